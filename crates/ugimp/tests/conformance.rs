//! uGIMP against the public conformance suite of the kernels, and the continuity that
//! makes it the grid's remedy for the cell-crossing error.

use nalgebra::SVector;
use proptest::prelude::*;
use umls_kernels::testing::check_kernel;
use umls_transfer::{Kernel, Stencil};
use umls_ugimp::{UgimpError, UgimpKernel};

/// Points spread over the box [0, 1]^D, off the nodes and on them.
fn points<const D: usize>(count: usize) -> Vec<SVector<f64, D>> {
    (0..count)
        .map(|i| SVector::from_fn(|k, _| ((i * (7 + 3 * k) + k) % 97) as f64 / 96.0))
        .collect()
}

fn grid<const D: usize>(h: f64, l: f64) -> UgimpKernel<D> {
    UgimpKernel::covering(SVector::zeros(), SVector::repeat(1.0), h, l).expect("valid grid")
}

#[test]
fn passes_the_conformance_suite_in_every_dimension() {
    for (h, l) in [(0.1, 0.025), (0.1, 0.05), (0.125, 0.01)] {
        check_kernel(&grid::<1>(h, l), &points::<1>(60), SVector::repeat(9.0)).unwrap();
        check_kernel(&grid::<2>(h, l), &points::<2>(60), SVector::repeat(9.0)).unwrap();
        check_kernel(&grid::<3>(h, l), &points::<3>(40), SVector::repeat(9.0)).unwrap();
    }
}

/// ∇ of the interpolant of a fixed nodal field at x.
fn gradient<const D: usize>(k: &UgimpKernel<D>, x: SVector<f64, D>) -> SVector<f64, D> {
    let mut st = Stencil::new();
    k.stencil(&x, &mut (), &mut st).unwrap();
    st.iter()
        .map(|(n, _, g)| g * (((n as f64) * 0.618).fract() - 0.5))
        .sum()
}

proptest! {
    /// Across a cell face (where the stencil's nodes change) and across the box's
    /// breakpoints, the interpolated field's gradient changes by O(ε): uGIMP is C¹.
    #[test]
    fn the_gradient_is_continuous_across_cell_faces(
        cell in 3usize..7, y in 0.2f64..0.8, l in 0.01f64..0.05
    ) {
        let h = 0.1;
        let k = grid::<2>(h, l);
        // Half a cell from a node is where the nearest node, and so the stencil, changes.
        let face = (cell as f64 + 0.5) * h;
        let eps = 1e-9;
        let below = gradient(&k, SVector::from([face - eps, y]));
        let above = gradient(&k, SVector::from([face + eps, y]));
        prop_assert!((below - above).norm() < 1e-5, "{below} vs {above}");
        // Where the hat's kink meets the box (a node ± l), as well.
        let kink = cell as f64 * h + l;
        let below = gradient(&k, SVector::from([kink - eps, y]));
        let above = gradient(&k, SVector::from([kink + eps, y]));
        prop_assert!((below - above).norm() < 1e-5, "{below} vs {above}");
    }
}

#[test]
fn a_box_wider_than_half_a_cell_is_refused_naming_it() {
    let e =
        UgimpKernel::<2>::covering(SVector::zeros(), SVector::repeat(1.0), 0.1, 0.06).unwrap_err();
    assert_eq!(
        e,
        UgimpError::HalfWidth {
            half_width: 0.06,
            h: 0.1
        }
    );
    assert!(e.to_string().contains("l = 0.06"), "{e}");
    assert!(matches!(
        UgimpKernel::<1>::covering(SVector::zeros(), SVector::repeat(1.0), 0.0, 0.01),
        Err(UgimpError::Spacing(_))
    ));
    assert!(matches!(
        UgimpKernel::<1>::covering(SVector::zeros(), SVector::from([f64::NAN]), 0.1, 0.01),
        Err(UgimpError::Box)
    ));
}

#[test]
fn one_particle_per_cell_is_the_widest_box() {
    // l = h/2 with round-off above it is accepted and held at h/2.
    let k = UgimpKernel::<1>::covering(
        SVector::zeros(),
        SVector::repeat(1.0),
        0.1,
        0.05 * (1.0 + 1e-15),
    )
    .unwrap();
    assert_eq!(k.half_width(), 0.05);
}

#[test]
fn with_boxes_of_a_whole_cell_it_is_the_quadratic_b_spline() {
    // The hat averaged over a box as wide as a cell is the quadratic B-spline: an
    // independent closed form for the widest boxes (one particle per cell).
    use umls_kernels::{BSplineKernel, BSplineOrder};
    let (lower, upper) = (SVector::<f64, 2>::zeros(), SVector::repeat(1.0));
    let gimp = UgimpKernel::covering(lower, upper, 0.1, 0.05).unwrap();
    let spline = BSplineKernel::covering(lower, upper, 0.1, BSplineOrder::Quadratic).unwrap();
    let (mut a, mut b) = (Stencil::new(), Stencil::new());
    for x in points::<2>(50) {
        gimp.stencil(&x, &mut (), &mut a).unwrap();
        spline.stencil(&x, &mut (), &mut b).unwrap();
        // Where x is half a cell from a node, the two may pick stencils one node apart;
        // the node only one of them holds has weight zero there.
        let entry = |st: &Stencil<2>, node: u32| {
            st.iter()
                .find(|(n, _, _)| *n == node)
                .map_or((0.0, SVector::zeros()), |(_, v, g)| (v, *g))
        };
        for node in a.nodes().iter().chain(b.nodes()) {
            let ((va, ga), (vb, gb)) = (entry(&a, *node), entry(&b, *node));
            assert!((va - vb).abs() < 1e-14, "N_{node} at {x}: {va} vs {vb}");
            assert!((ga - gb).norm() < 1e-12, "∇N_{node} at {x}: {ga} vs {gb}");
        }
    }
}
