//! Cross-crate check of the project's central claim on a mesh made by `umls-mesh` and a
//! kernel from `umls-mls`: along a path that crosses many facets, the gradient of an
//! interpolated smooth field is continuous with UMLS and jumps at every facet with
//! linear FE shape functions.

use nalgebra::Vector2;
use umls::mesh::generate::{Diagonal, Lattice};
use umls::mls::{GradientKind, Linear, Stencil, UmlsKernel};

fn field(x: &Vector2<f64>) -> f64 {
    (2.3 * x.x).sin() * (1.7 * x.y).cos() + x.x * x.y
}

/// Largest change of ∂f/∂x between consecutive samples spaced δ along the path, and the
/// number of host changes on the way.
fn largest_step(use_umls: bool, delta: f64) -> (f64, usize) {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [24, 24])
        .jitter(0.2, 5)
        .rotate_by(0.4)
        .triangles(Diagonal::Crossed)
        .unwrap();
    let kernel = UmlsKernel::new(&mesh);
    let nodal: Vec<f64> = mesh.vertices().iter().map(field).collect();
    let mut st = Stencil::new();
    let (mut previous, mut host, mut crossings, mut largest) =
        (None::<f64>, None::<u32>, 0, 0.0f64);
    let steps = (0.6 / delta) as usize;
    for i in 0..=steps {
        let t = 0.2 + i as f64 * delta;
        let x = Vector2::new(t, 0.5 + 0.3 * (t - 0.5));
        let found = match host {
            Some(h) => mesh.locate_from(&x, h),
            None => mesh.locate(&x),
        }
        .unwrap();
        if host.is_some_and(|h| h != found.simplex) {
            crossings += 1;
        }
        host = Some(found.simplex);
        let dfdx = if use_umls {
            kernel
                .evaluate::<3, Linear>(
                    &mesh,
                    found.simplex,
                    &x,
                    GradientKind::Reconstructed,
                    &mut st,
                )
                .unwrap();
            st.interpolate(&nodal).unwrap().1.x
        } else {
            let grads = mesh.barycentric_gradients(found.simplex as usize);
            mesh.simplex(found.simplex as usize)
                .iter()
                .zip(grads.as_slice())
                .map(|(&v, g)| nodal[v as usize] * g.x)
                .sum()
        };
        if let Some(p) = previous {
            largest = largest.max((dfdx - p).abs());
        }
        previous = Some(dfdx);
    }
    (largest, crossings)
}

#[test]
fn umls_gradient_steps_vanish_with_the_sample_spacing_linear_fe_steps_do_not() {
    let (umls_coarse, crossings) = largest_step(true, 1e-4);
    let (umls_fine, _) = largest_step(true, 5e-5);
    let (fe_coarse, _) = largest_step(false, 1e-4);
    let (fe_fine, _) = largest_step(false, 5e-5);
    assert!(crossings > 40, "path crosses {crossings} facets");
    // Continuous: the largest step halves with the spacing.
    assert!(
        (umls_coarse / umls_fine - 2.0).abs() < 0.2,
        "UMLS steps {umls_coarse} → {umls_fine}"
    );
    // Discontinuous: the largest step is a facet jump, independent of the spacing.
    assert!(
        (fe_coarse / fe_fine - 1.0).abs() < 0.05,
        "FE steps {fe_coarse} → {fe_fine}"
    );
    assert!(
        fe_fine > 100.0 * umls_fine,
        "FE {fe_fine} vs UMLS {umls_fine}"
    );
}
