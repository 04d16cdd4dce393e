//! Seeding: regions select sample points; volumes and masses add up.

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{SVector, Vector2};
use umls_engine::{Particles, Region, lattice_samples};
use umls_mesh::SampleRule;
use umls_mesh::generate::{Diagonal, Lattice};

type P2 = Particles<2, (), ()>;

#[test]
fn disk_from_mesh_samples_converges_to_its_area() {
    let disk = Region::Ball {
        centre: Vector2::new(0.5, 0.5),
        radius: 0.3,
    };
    let errors: Vec<f64> = [16usize, 32, 64]
        .iter()
        .map(|&n| {
            let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [n, n])
                .jitter(0.2, 4)
                .triangles(Diagonal::Alternating)
                .unwrap();
            let p = P2::seed(
                &mesh.sample_points(SampleRule::Gauss2),
                &disk,
                2.0,
                (),
                |_| Vector2::zeros(),
            );
            let area: f64 = p.volume.iter().sum();
            assert!((p.mass.iter().sum::<f64>() - 2.0 * area).abs() < 1e-12);
            (area - PI * 0.09).abs()
        })
        .collect();
    eprintln!("disk area errors {errors:?}");
    // The boundary layer of partially covered simplices shrinks with h.
    assert!(
        errors[2] < errors[0] / 2.0 && errors[2] < 0.01,
        "{errors:?}"
    );
}

#[test]
fn regions_and_velocity_fields() {
    let samples = lattice_samples(SVector::from([0.0, 0.0]), SVector::from([1.0, 1.0]), 0.1);
    assert_eq!(samples.len(), 100);
    assert!((samples.iter().map(|s| s.1).sum::<f64>() - 1.0).abs() < 1e-12);
    // Centres ((i + ½)/10, (j + ½)/10) with x + y ≤ 1.05 are those with i + j ≤ 9: 55.
    // (The plane sits between sample rows so round-off cannot decide membership.)
    let below = Region::HalfSpace {
        normal: Vector2::new(1.0, 1.0),
        offset: 1.05,
    };
    assert_eq!(
        P2::seed(&samples, &below, 1.0, (), |_| Vector2::zeros()).len(),
        55
    );
    let boxed = Region::Box {
        lower: Vector2::new(0.2, 0.2),
        upper: Vector2::new(0.6, 0.4),
    };
    assert_eq!(
        P2::seed(&samples, &boxed, 1.0, (), |_| Vector2::zeros()).len(),
        8
    );
    let both = Region::Intersection(vec![
        boxed,
        Region::Predicate(Arc::new(|x: &Vector2<f64>| x.x < 0.4)),
    ]);
    let p = P2::seed(&samples, &both, 1.0, (), |x| Vector2::new(-x.y, x.x));
    assert_eq!(p.len(), 4);
    for (v, x) in p.velocity.iter().zip(&p.position) {
        assert_eq!(*v, Vector2::new(-x.y, x.x));
    }
    let mut all = P2::seed(&samples, &Region::Everywhere, 1.0, (), |_| Vector2::zeros());
    let n = all.len();
    all.append(p);
    assert_eq!(all.len(), n + 4);
    assert_eq!(all.cache.len(), n + 4);
    assert!(format!("{both:?}").contains("Predicate"));
}
