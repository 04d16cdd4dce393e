//! The conformance suite every kernel must pass: partition of unity, linear reproduction
//! of values and gradients, valid node indices, results independent of the location
//! cache, and a typed error outside the domain. Plus kernel-specific checks.

use std::sync::Arc;

use nalgebra::SVector;
use proptest::prelude::*;
use umls_kernels::testing::check_kernel;
use umls_kernels::{
    BSplineKernel, BSplineOrder, GradientKind, LinearFeKernel, Umls1, Umls2, Umls3,
};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mls::{CubicBSpline, SupportRadius, UmlsKernel};
use umls_transfer::{Kernel, Stencil};

/// Runs the public suite (`umls_kernels::testing`) on points given as fractions of the
/// box [lo, hi].
fn conformance<const D: usize, K: Kernel<D>>(
    kernel: &K,
    lo: SVector<f64, D>,
    hi: SVector<f64, D>,
    fractions: &[f64],
) -> Result<(), TestCaseError> {
    let points: Vec<SVector<f64, D>> = fractions
        .chunks_exact(D)
        .map(|c| lo + SVector::<f64, D>::from_fn(|k, _| c[k] * (hi[k] - lo[k])))
        .collect();
    let outside = hi + SVector::<f64, D>::repeat(10.0 * kernel.spacing() + 1.0);
    check_kernel(kernel, &points, outside).map_err(|v| TestCaseError::fail(v.to_string()))
}

/// The MLS settings of the CLI's `umls-eta4` and `umls-eta8`: weights η^p · d with the
/// incident-edge support `factor`.
fn powered<const D: usize>(mesh: &SimplexMesh<D>, exponent: u32, factor: f64) -> UmlsKernel<D> {
    UmlsKernel::with_weight(mesh, CubicBSpline, SupportRadius::IncidentEdge { factor })
        .and_then(|k| k.with_diminishing_exponent(exponent))
        .unwrap()
}

fn fractions(d: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.0f64..1.0, 12 * d)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn mesh_kernels_1d(f in fractions(1), seed in any::<u64>()) {
        let mesh = Arc::new(Lattice::new([0.0], [2.0], [16]).jitter(0.2, seed).segments().unwrap());
        let (lo, hi) = mesh.bounding_box();
        conformance(&Umls1::new(mesh.clone()), lo, hi, &f)?;
        conformance(&LinearFeKernel::new(mesh), lo, hi, &f)?;
    }

    #[test]
    fn mesh_kernels_2d(f in fractions(2), seed in any::<u64>(), angle in 0.0f64..6.3) {
        let mesh = Arc::new(Lattice::new([0.0, 0.0], [1.0, 1.0], [9, 7]).jitter(0.2, seed).triangles(Diagonal::Alternating).unwrap());
        // Fractions of the unrotated square, rotated with the mesh.
        let rotation = nalgebra::Rotation2::new(angle);
        let rotated = Arc::new(Lattice::new([0.0, 0.0], [1.0, 1.0], [9, 7]).jitter(0.2, seed).rotate_by(angle).triangles(Diagonal::Alternating).unwrap());
        let centre = SVector::<f64, 2>::new(0.5, 0.5);
        let (lo, hi) = (SVector::<f64, 2>::zeros(), SVector::<f64, 2>::repeat(1.0));
        conformance(&Umls2::new(mesh.clone()), lo, hi, &f)?;
        conformance(&Umls2::new(mesh.clone()).with_gradient(GradientKind::Full), lo, hi, &f)?;
        conformance(&Umls2::new(mesh.clone()).with_gradient(GradientKind::FrozenEta), lo, hi, &f)?;
        conformance(&Umls2::with_kernel(mesh.clone(), powered(&mesh, 4, 1.4)), lo, hi, &f)?;
        conformance(&Umls2::with_kernel(mesh.clone(), powered(&mesh, 8, 2.8)), lo, hi, &f)?;
        conformance(&LinearFeKernel::new(mesh), lo, hi, &f)?;
        // Same points mapped into the rotated square.
        let mapped: Vec<f64> = f.chunks_exact(2).flat_map(|c| {
            let p = centre + rotation * (SVector::<f64, 2>::new(c[0], c[1]) - centre);
            let (rlo, rhi) = rotated.bounding_box();
            [(p.x - rlo.x) / (rhi.x - rlo.x), (p.y - rlo.y) / (rhi.y - rlo.y)]
        }).collect();
        let (rlo, rhi) = rotated.bounding_box();
        conformance(&Umls2::new(rotated.clone()), rlo, rhi, &mapped)?;
    }

    #[test]
    fn mesh_kernels_3d(f in fractions(3), seed in any::<u64>()) {
        let mesh = Arc::new(Lattice::new([0.0; 3], [1.0; 3], [4, 4, 4]).jitter(0.2, seed).tetrahedra().unwrap());
        let (lo, hi) = mesh.bounding_box();
        conformance(&Umls3::new(mesh.clone()), lo, hi, &f)?;
        conformance(&Umls3::new(mesh.clone()).with_gradient(GradientKind::Full), lo, hi, &f)?;
        conformance(&Umls3::new(mesh.clone()).with_gradient(GradientKind::FrozenEta), lo, hi, &f)?;
        conformance(&Umls3::with_kernel(mesh.clone(), powered(&mesh, 4, 1.4)), lo, hi, &f)?;
        conformance(&Umls3::with_kernel(mesh.clone(), powered(&mesh, 8, 2.8)), lo, hi, &f)?;
        conformance(&LinearFeKernel::new(mesh), lo, hi, &f)?;
    }

    #[test]
    fn bspline_kernels(f1 in fractions(1), f2 in fractions(2), f3 in fractions(3)) {
        for order in [BSplineOrder::Quadratic, BSplineOrder::Cubic] {
            // Valid region: one (quadratic: half) cell inside the grid; test the inner box.
            let k1 = BSplineKernel::new(SVector::from([0.0]), 0.1, [20], order).unwrap();
            conformance(&k1, SVector::from([0.1]), SVector::from([1.9]), &f1)?;
            let k2 = BSplineKernel::new(SVector::from([-1.0, 0.0]), 0.25, [12, 8], order).unwrap();
            conformance(&k2, SVector::from([-0.75, 0.25]), SVector::from([1.75, 1.75]), &f2)?;
            let k3 = BSplineKernel::new(SVector::from([0.0, 0.0, 0.0]), 0.5, [6, 5, 4], order).unwrap();
            conformance(&k3, SVector::from([0.5, 0.5, 0.5]), SVector::from([2.5, 2.0, 1.5]), &f3)?;
        }
    }
}

/// Central differences (step 10⁻⁶) of `kernel`'s values at `x`, per stencil entry, in
/// the stencil's node order (which must not change within the step).
fn differenced_gradients<const D: usize, K: Kernel<D>>(
    kernel: &K,
    x: &SVector<f64, D>,
) -> Vec<SVector<f64, D>> {
    let d = 1e-6;
    let (mut st, mut plus, mut minus) = (Stencil::new(), Stencil::new(), Stencil::new());
    kernel
        .stencil(x, &mut K::Cache::default(), &mut st)
        .unwrap();
    let mut gradients = vec![SVector::<f64, D>::zeros(); st.len()];
    for axis in 0..D {
        let e = SVector::<f64, D>::from_fn(|i, _| if i == axis { d } else { 0.0 });
        kernel
            .stencil(&(x + e), &mut K::Cache::default(), &mut plus)
            .unwrap();
        kernel
            .stencil(&(x - e), &mut K::Cache::default(), &mut minus)
            .unwrap();
        assert_eq!(
            plus.nodes(),
            st.nodes(),
            "the stencil's nodes must not change"
        );
        assert_eq!(
            minus.nodes(),
            st.nodes(),
            "the stencil's nodes must not change"
        );
        for (i, g) in gradients.iter_mut().enumerate() {
            g[axis] = (plus.values()[i] - minus.values()[i]) / (2.0 * d);
        }
    }
    gradients
}

/// The largest difference between `kernel`'s gradients at `x` and `expected`.
fn gradient_gap<const D: usize, K: Kernel<D>>(
    kernel: &K,
    x: &SVector<f64, D>,
    expected: &[SVector<f64, D>],
) -> f64 {
    let mut st = Stencil::new();
    kernel
        .stencil(x, &mut K::Cache::default(), &mut st)
        .unwrap();
    assert_eq!(st.len(), expected.len());
    st.gradients()
        .iter()
        .zip(expected)
        .map(|(g, e)| (g - e).amax())
        .fold(0.0, f64::max)
}

/// B-spline gradients are the derivatives of the values (central differences), and the
/// stencil sizes are 3^D and 4^D.
#[test]
fn bspline_gradients_and_sizes() {
    for order in [BSplineOrder::Quadratic, BSplineOrder::Cubic] {
        let k = BSplineKernel::new(SVector::from([0.0, 0.0]), 0.2, [10, 10], order).unwrap();
        let x = SVector::<f64, 2>::new(0.913, 1.071);
        let mut st = Stencil::new();
        k.stencil(&x, &mut (), &mut st).unwrap();
        assert_eq!(st.len(), order.width().pow(2));
        let gap = gradient_gap(&k, &x, &differenced_gradients(&k, &x));
        assert!(gap < 1e-6, "{order:?}: gradients off by {gap}");
    }
    assert!(BSplineKernel::new(SVector::from([0.0]), -1.0, [10], BSplineOrder::Cubic).is_none());
    assert!(BSplineKernel::new(SVector::from([0.0]), 1.0, [2], BSplineOrder::Cubic).is_none());
}

/// With `GradientKind::Full` the UMLS stencil's gradients are the derivatives of its
/// values (central differences inside one host, where the fit is smooth); the default
/// reconstructed gradient is not, by a margin well above the differencing error; both
/// carry the same values.
#[test]
fn umls_full_gradient_is_the_derivative_of_the_values() {
    let mesh = Arc::new(
        Lattice::new([0.0; 3], [1.0; 3], [4, 4, 4])
            .jitter(0.2, 5)
            .tetrahedra()
            .unwrap(),
    );
    let full = Umls3::new(mesh.clone()).with_gradient(GradientKind::Full);
    let reconstructed = Umls3::new(mesh);
    assert_eq!(reconstructed.gradient(), GradientKind::Reconstructed);
    let mut largest_gap = 0.0f64;
    for x in [
        SVector::<f64, 3>::new(0.41, 0.37, 0.52),
        SVector::<f64, 3>::new(0.63, 0.28, 0.71),
    ] {
        let (mut st, mut rec) = (Stencil::new(), Stencil::new());
        full.stencil(&x, &mut Default::default(), &mut st).unwrap();
        reconstructed
            .stencil(&x, &mut Default::default(), &mut rec)
            .unwrap();
        assert_eq!(st.nodes(), rec.nodes());
        assert_eq!(st.values(), rec.values());
        let differenced = differenced_gradients(&full, &x);
        let gap = gradient_gap(&full, &x, &differenced);
        assert!(gap < 1e-6, "full gradient off by {gap}");
        largest_gap = largest_gap.max(gradient_gap(&reconstructed, &x, &differenced));
    }
    assert!(
        largest_gap > 1e-2,
        "the reconstructed gradient differs from the derivative: {largest_gap}"
    );
}

/// The suite catches what it checks: hat functions on [0, 1] pass it; scaled values, a
/// wrong declared second moment, negative values of a kernel declared nonnegative, a
/// node beyond the count, and no error outside each fail it with the property named, as
/// do wrong offsets, a wrong node range and a visitor that hands the entries over in
/// another order.
#[test]
fn the_public_suite_catches_broken_kernels() {
    #[derive(Clone, Copy)]
    struct Hat {
        scale: f64,
        moment: Option<f64>,
        node_count: usize,
        rejects_outside: bool,
        offset_scale: f64,
        claimed_range: Option<(u32, u32)>,
        visits_reversed: bool,
        nonnegative: bool,
    }
    impl Kernel<1> for Hat {
        type Cache = ();
        fn node_count(&self) -> usize {
            self.node_count
        }
        fn node_position(&self, node: usize) -> SVector<f64, 1> {
            SVector::from([node as f64])
        }
        fn spacing(&self) -> f64 {
            1.0
        }
        fn constant_second_moment(&self) -> Option<f64> {
            self.moment
        }
        fn nonnegative_values(&self) -> bool {
            self.nonnegative
        }
        fn node_range(
            &self,
            x: &SVector<f64, 1>,
            cache: &mut (),
            scratch: &mut Stencil<1>,
        ) -> Result<(u32, u32), umls_transfer::KernelError> {
            self.stencil(x, cache, scratch)?;
            Ok(self.claimed_range.unwrap_or((0, 1)))
        }
        fn visit_stencil<F>(
            &self,
            x: &SVector<f64, 1>,
            cache: &mut (),
            scratch: &mut Stencil<1>,
            mut visit: F,
        ) -> Result<(), umls_transfer::KernelError>
        where
            F: FnMut(u32, f64, &SVector<f64, 1>, &SVector<f64, 1>),
        {
            self.stencil(x, cache, scratch)?;
            let mut entries: Vec<usize> = (0..scratch.len()).collect();
            if self.visits_reversed {
                entries.reverse();
            }
            for e in entries {
                let (node, n, g) = scratch.iter().nth(e).unwrap();
                visit(node, n, g, &scratch.offsets()[e]);
            }
            Ok(())
        }
        fn stencil(
            &self,
            x: &SVector<f64, 1>,
            _: &mut (),
            out: &mut Stencil<1>,
        ) -> Result<(), umls_transfer::KernelError> {
            if self.rejects_outside && !(0.0..=1.0).contains(&x[0]) {
                return Err(umls_transfer::KernelError::OutsideDomain { point: vec![x[0]] });
            }
            out.clear();
            out.push(
                0,
                self.scale * (1.0 - x[0]),
                SVector::from([-1.0]),
                SVector::from([-x[0]]),
            );
            out.push(
                1,
                self.scale * x[0],
                SVector::from([1.0]),
                SVector::from([self.offset_scale * (1.0 - x[0])]),
            );
            Ok(())
        }
    }
    let good = Hat {
        scale: 1.0,
        moment: None,
        node_count: 2,
        rejects_outside: true,
        offset_scale: 1.0,
        claimed_range: None,
        visits_reversed: false,
        nonnegative: false,
    };
    let points = [SVector::from([0.25]), SVector::from([0.6])];
    let outside = SVector::from([3.0]);
    check_kernel(&good, &points, outside).unwrap();
    // Hats are never negative on [0, 1], and may say so; extended linearly beyond it
    // they are (N_0 = −0.25 at 1.25), and then the declaration is caught.
    let nonnegative = Hat {
        nonnegative: true,
        ..good
    };
    check_kernel(&nonnegative, &points, outside).unwrap();
    let extended = Hat {
        rejects_outside: false,
        ..nonnegative
    };
    let negative = check_kernel(&extended, &[SVector::from([1.25])], outside)
        .unwrap_err()
        .message;
    assert!(
        negative.contains("declares no negative values"),
        "{negative}"
    );
    let failure = |k: Hat| check_kernel(&k, &points, outside).unwrap_err().message;
    assert!(failure(Hat { scale: 1.1, ..good }).contains("Σ N"));
    // x(1 − x) ≠ 0.3 at x = 0.25: a hat's second moment is not constant.
    assert!(
        failure(Hat {
            moment: Some(0.3),
            ..good
        })
        .contains("declared")
    );
    assert!(
        failure(Hat {
            node_count: 1,
            ..good
        })
        .contains("beyond")
    );
    assert!(
        failure(Hat {
            rejects_outside: false,
            ..good
        })
        .contains("outside")
    );
    assert!(
        failure(Hat {
            offset_scale: 2.0,
            ..good
        })
        .contains("offset of node 1")
    );
    assert!(
        failure(Hat {
            claimed_range: Some((0, 2)),
            ..good
        })
        .contains("node_range")
    );
    assert!(
        failure(Hat {
            visits_reversed: true,
            ..good
        })
        .contains("visit_stencil")
    );
}

/// A kernel type that declares it never corrects its force gradients, yet has a
/// correction, fails the suite: the engine would leave the correction out.
#[test]
fn the_public_suite_catches_a_false_declaration() {
    struct Liar {
        correction: [SVector<f64, 1>; 2],
    }
    impl Kernel<1> for Liar {
        type Cache = ();
        const MAY_CORRECT_FORCE_GRADIENTS: bool = false;
        fn node_count(&self) -> usize {
            2
        }
        fn node_position(&self, node: usize) -> SVector<f64, 1> {
            SVector::from([node as f64])
        }
        fn spacing(&self) -> f64 {
            1.0
        }
        fn force_gradient_correction(&self) -> Option<&[SVector<f64, 1>]> {
            Some(&self.correction)
        }
        fn stencil(
            &self,
            x: &SVector<f64, 1>,
            _: &mut (),
            out: &mut Stencil<1>,
        ) -> Result<(), umls_transfer::KernelError> {
            if !(0.0..=1.0).contains(&x[0]) {
                return Err(umls_transfer::KernelError::OutsideDomain { point: vec![x[0]] });
            }
            out.clear();
            out.push(0, 1.0 - x[0], SVector::from([-1.0]), SVector::from([-x[0]]));
            out.push(1, x[0], SVector::from([1.0]), SVector::from([1.0 - x[0]]));
            Ok(())
        }
    }
    let liar = Liar {
        correction: [SVector::from([0.1]), SVector::from([-0.1])],
    };
    let err = check_kernel(&liar, &[SVector::from([0.3])], SVector::from([5.0])).unwrap_err();
    assert!(
        err.message.contains("MAY_CORRECT_FORCE_GRADIENTS = false"),
        "{}",
        err.message
    );
}
