//! The UMLS kernels' integration correction ξ_i = ∫(∂N_i − ∇N_i) / ∫N_i against an
//! independent computation: the full derivative integrated over the simplices (not
//! the kernel's boundary integral) with a subdivided degree-2 rule (not its
//! Gauss–Jacobi rules), through the public stencils of the kernel and of its
//! full-gradient twin.

use std::sync::Arc;

use nalgebra::{SVector, Vector2};
use umls_kernels::{GradientKind, Umls2, Umls3};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::{Kernel, Stencil};

/// ∫(∂N_i − ∇N_i), ∫N_i per vertex: every triangle cut into k² sub-triangles, each with
/// the 3-point degree-2 rule.
fn reference(mesh: &SimplexMesh<2>, kernel: &Umls2, k: usize) -> (Vec<SVector<f64, 2>>, Vec<f64>) {
    let full = kernel.clone().with_gradient(GradientKind::Full);
    let n = mesh.vertex_count();
    let (mut defect, mut weight) = (vec![SVector::zeros(); n], vec![0.0; n]);
    let (mut a, mut b) = (Stencil::new(), Stencil::new());
    let kf = k as f64;
    for s in 0..mesh.simplex_count() {
        let c = mesh.corners(s);
        let at = |l1: f64, l2: f64| c[0] + (c[1] - c[0]) * l1 + (c[2] - c[0]) * l2;
        let area = mesh.volume(s) / (kf * kf);
        let mut sub = Vec::new();
        for i in 0..k {
            for j in 0..k - i {
                let (i, j) = (i as f64, j as f64);
                sub.push([(i, j), (i + 1.0, j), (i, j + 1.0)]);
                if i + j + 2.0 <= kf {
                    sub.push([(i + 1.0, j), (i, j + 1.0), (i + 1.0, j + 1.0)]);
                }
            }
        }
        for corners in sub {
            for p in 0..3 {
                let w = |q: usize| if q == p { 2.0 / 3.0 } else { 1.0 / 6.0 };
                let l1 = (0..3).map(|q| w(q) * corners[q].0).sum::<f64>() / kf;
                let l2 = (0..3).map(|q| w(q) * corners[q].1).sum::<f64>() / kf;
                let x: Vector2<f64> = at(l1, l2);
                kernel.stencil(&x, &mut Default::default(), &mut a).unwrap();
                full.stencil(&x, &mut Default::default(), &mut b).unwrap();
                assert_eq!(a.nodes(), b.nodes());
                for e in 0..a.len() {
                    let v = a.nodes()[e] as usize;
                    defect[v] += (b.gradients()[e] - a.gradients()[e]) * (area / 3.0);
                    weight[v] += a.values()[e] * area / 3.0;
                }
            }
        }
    }
    (defect, weight)
}

fn jittered_triangles(seed: u64) -> Arc<SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [6, 5])
            .jitter(0.2, seed)
            .triangles(Diagonal::Alternating)
            .unwrap(),
    )
}

/// The kernel's ξ (boundary integral for ∫∂N_i, Gauss–Jacobi rules) matches the
/// independent volume integral of the full derivative. The reference converges as its
/// sub-triangles shrink (the two references differ by about 10⁻³ of the largest ξ; the
/// kernel's rule is within that of the finer one).
#[test]
fn the_correction_is_the_derivatives_integral_defect_over_the_weight() {
    for seed in [3, 17] {
        let mesh = jittered_triangles(seed);
        let kernel = Umls2::new(mesh.clone())
            .with_integration_correction()
            .unwrap();
        let xi = kernel.force_gradient_correction().unwrap();
        let (coarse, _) = reference(&mesh, &kernel, 4);
        let (fine, weight) = reference(&mesh, &kernel, 8);
        let scale = (0..xi.len())
            .map(|i| (fine[i] / weight[i]).norm())
            .fold(0.0, f64::max);
        // The correction is not small: the test could not pass on zeros.
        assert!(scale > 0.5, "{scale}");
        let (mut refinement, mut error) = (0.0f64, 0.0f64);
        for i in 0..xi.len() {
            refinement = refinement.max(((fine[i] - coarse[i]) / weight[i]).norm());
            error = error.max((xi[i] - fine[i] / weight[i]).norm());
        }
        assert!(refinement < 5e-3 * scale, "{refinement} of {scale}");
        assert!(error < 5e-3 * scale, "seed {seed}: {error} of {scale}");
        // Σ_i ξ_i ∫N_i = Σ_i ∫(∂N_i − ∇N_i) = 0: both gradients sum to zero.
        let sum: SVector<f64, 2> = (0..xi.len()).map(|i| xi[i] * weight[i]).sum();
        assert!(sum.norm() < 1e-3 * scale, "{sum}");
    }
}

/// The correction leaves the stencils alone (the conformance suite's reproduction holds
/// for them as for the plain kernel), is none for the full derivative, and is the same,
/// bit for bit, on any number of threads.
#[test]
fn the_correction_changes_no_stencil_and_no_bit_with_the_threads() {
    let mesh = Arc::new(
        Lattice::new([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [4, 4, 3])
            .jitter(0.2, 5)
            .tetrahedra()
            .unwrap(),
    );
    let pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    };
    let plain = Umls3::new(mesh.clone());
    let one = pool(1).install(|| plain.clone().with_integration_correction().unwrap());
    let three = pool(3).install(|| plain.clone().with_integration_correction().unwrap());
    let (a, b) = (
        one.force_gradient_correction().unwrap(),
        three.force_gradient_correction().unwrap(),
    );
    assert!(a.iter().zip(b).all(|(x, y)| {
        x.iter()
            .zip(y.iter())
            .all(|(p, q)| p.to_bits() == q.to_bits())
    }));
    assert!(a.iter().any(|x| x.norm() > 0.1));
    assert_eq!(plain.force_gradient_correction(), None);
    let x = SVector::<f64, 3>::new(0.41, 0.37, 0.52);
    let (mut s, mut t) = (Stencil::new(), Stencil::new());
    plain.stencil(&x, &mut Default::default(), &mut s).unwrap();
    one.stencil(&x, &mut Default::default(), &mut t).unwrap();
    assert_eq!(s, t);
    let full = Umls3::new(mesh)
        .with_gradient(GradientKind::Full)
        .with_integration_correction()
        .unwrap();
    assert!(full.force_gradient_correction().is_none());
}
