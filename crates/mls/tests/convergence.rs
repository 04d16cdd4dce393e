//! Interpolation of a smooth field on refined jittered meshes: the UMLS value error
//! converges at second order and the reconstructed gradient at first order or better.

use nalgebra::{SVector, Vector2, Vector3};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mls::{GradientKind, Linear, PolynomialBasis, Stencil, UmlsKernel};

fn field2(x: &Vector2<f64>) -> (f64, Vector2<f64>) {
    let (a, b) = (1.3, 0.9);
    let value = (a * x.x).sin() * (b * x.y).cos() + 0.5 * x.x * x.y;
    let grad = Vector2::new(
        a * (a * x.x).cos() * (b * x.y).cos() + 0.5 * x.y,
        -b * (a * x.x).sin() * (b * x.y).sin() + 0.5 * x.x,
    );
    (value, grad)
}

fn field3(x: &Vector3<f64>) -> (f64, Vector3<f64>) {
    let value = (x.x + 0.5 * x.y).sin() * (0.7 * x.z).exp();
    let c = (x.x + 0.5 * x.y).cos() * (0.7 * x.z).exp();
    (value, Vector3::new(c, 0.5 * c, 0.7 * value))
}

/// RMS errors of value and gradient over sample points at fixed barycentric positions in
/// every simplex.
fn errors<const D: usize, const N: usize>(
    mesh: &SimplexMesh<D>,
    field: impl Fn(&SVector<f64, D>) -> (f64, SVector<f64, D>),
) -> (f64, f64)
where
    Linear: PolynomialBasis<D, N>,
{
    let kernel = UmlsKernel::new(mesh);
    let nodal: Vec<f64> = mesh.vertices().iter().map(|v| field(v).0).collect();
    let mut st = Stencil::new();
    let (mut ev, mut eg, mut count) = (0.0, 0.0, 0.0);
    let samples: [[f64; 4]; 3] = [[0.25; 4], [0.6, 0.2, 0.1, 0.1], [0.1, 0.15, 0.7, 0.05]];
    for s in 0..mesh.simplex_count() {
        for raw in &samples {
            let total: f64 = raw[..=D].iter().sum();
            let x = mesh
                .simplex(s)
                .iter()
                .zip(raw)
                .fold(SVector::<f64, D>::zeros(), |acc, (&v, &w)| {
                    acc + mesh.vertex(v as usize) * (w / total)
                });
            kernel
                .evaluate::<N, Linear>(mesh, s as u32, &x, GradientKind::Reconstructed, &mut st)
                .unwrap();
            let (value, grad) = st.interpolate(&nodal).unwrap();
            let (exact, exact_grad) = field(&x);
            ev += (value - exact).powi(2);
            eg += (grad - exact_grad).norm_squared();
            count += 1.0;
        }
    }
    ((ev / count).sqrt(), (eg / count).sqrt())
}

/// Observed value orders between successive refinements by a factor of 2, and the
/// gradient order as the least-squares slope of log₂ e against refinement level. Each level
/// is a fresh random jitter, so the O(h) gradient constant varies from level to level and
/// pairwise gradient orders scatter around the asymptotic one; the fitted slope does not.
fn orders(errors: &[(f64, f64)]) -> (Vec<f64>, f64) {
    let value = errors
        .windows(2)
        .map(|w| (w[0].0 / w[1].0).log2())
        .collect();
    let n = errors.len() as f64;
    let mean_level = (n - 1.0) / 2.0;
    let logs: Vec<f64> = errors.iter().map(|e| e.1.log2()).collect();
    let mean_log = logs.iter().sum::<f64>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for (level, log) in logs.iter().enumerate() {
        num += (level as f64 - mean_level) * (log - mean_log);
        den += (level as f64 - mean_level).powi(2);
    }
    (value, -num / den)
}

#[test]
fn second_order_values_first_order_gradients_1d() {
    let errs: Vec<(f64, f64)> = [8, 16, 32, 64, 128, 256, 512]
        .iter()
        .map(|&n| {
            let mesh = Lattice::new([0.0], [2.0], [n])
                .jitter(0.2, 4)
                .segments()
                .unwrap();
            errors::<1, 2>(&mesh, |x| {
                (
                    (1.5 * x[0]).sin(),
                    SVector::from([1.5 * (1.5 * x[0]).cos()]),
                )
            })
        })
        .collect();
    let (value, gradient) = orders(&errs);
    eprintln!("1D errors {errs:?}\n   value orders {value:?}\n   fitted gradient order {gradient}");
    assert!(value.iter().all(|&p| p > 1.8), "value orders {value:?}");
    assert!(gradient > 0.9, "fitted gradient order {gradient}");
}

#[test]
fn second_order_values_first_order_gradients_2d() {
    let errs: Vec<(f64, f64)> = [8, 16, 32]
        .iter()
        .map(|&n| {
            let mesh = Lattice::new([0.0, 0.0], [2.0, 2.0], [n, n])
                .jitter(0.2, 4)
                .rotate_by(0.3)
                .triangles(Diagonal::Alternating)
                .unwrap();
            errors::<2, 3>(&mesh, field2)
        })
        .collect();
    let (value, gradient) = orders(&errs);
    eprintln!("2D errors {errs:?}\n   value orders {value:?}\n   fitted gradient order {gradient}");
    assert!(value.iter().all(|&p| p > 1.8), "value orders {value:?}");
    assert!(gradient > 0.9, "fitted gradient order {gradient}");
}

#[test]
fn second_order_values_first_order_gradients_3d() {
    let errs: Vec<(f64, f64)> = [4, 8, 16]
        .iter()
        .map(|&n| {
            let mesh = Lattice::new([0.0; 3], [1.0; 3], [n, n, n])
                .jitter(0.2, 4)
                .tetrahedra()
                .unwrap();
            errors::<3, 4>(&mesh, field3)
        })
        .collect();
    let (value, gradient) = orders(&errs);
    eprintln!("3D errors {errs:?}\n   value orders {value:?}\n   fitted gradient order {gradient}");
    assert!(value.iter().all(|&p| p > 1.8), "value orders {value:?}");
    assert!(gradient > 0.9, "fitted gradient order {gradient}");
}
