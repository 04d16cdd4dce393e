//! The conformance suite every kernel of the crate passes, public (feature `testing`) so
//! that a kernel written elsewhere can be held to the same properties before it joins
//! a comparison:
//!
//! - partition of unity Σ N_i = 1 and Σ ∇N_i = 0;
//! - linear reproduction of positions Σ N_i x_i = x and gradients Σ x_i ∇N_iᵀ = I;
//! - the second moment the kernel declares (`Kernel::constant_second_moment`), if any,
//!   and where it declares D_p regular (`Kernel::regular_second_moment`), a D_p that is
//!   positive definite, not near singular (det D_p > 10⁻⁶ (tr D_p / D)^D, the engine's
//!   test before it inverts it) and not vanishing (tr D_p > 10⁻³ h²) wherever the
//!   stencil's nodes surround the point (some node at least h/2 ahead along every
//!   direction: a fit at the domain's boundary is one-sided);
//! - no negative value where the kernel declares its values never negative
//!   (`Kernel::nonnegative_values`), with no -0.0 either (|N| m must be N m bit for bit);
//! - node indices below `node_count`;
//! - offsets x_i − x that match the node positions, and a `Kernel::node_range` equal
//!   to the stencil's smallest and largest node;
//! - the same stencil from a fresh location cache as from a warm one, also when
//!   `Kernel::domain_exit` (which an engine calls with a particle's new position) has
//!   first left in the warm cache what it found at the point, and no domain exit for a
//!   point inside the domain;
//! - `Kernel::visit_stencil` handing over the stencil's entries in order, bit for bit,
//!   and `Kernel::append_stencil` appending them after what its arrays held (and
//!   leaving the arrays as they were where it fails);
//! - factored stencils (`Kernel::factor_layout`) of the declared layout, rebuilt by
//!   `Kernel::visit_factored` into the stencil's entries, with its node range; and
//!   `KernelError::NotFactored` from a kernel without a layout;
//! - tensor-product stencils (`Kernel::tensor_width`, widths 1 to 6) whose per-axis
//!   factors give the stencil's nodes, values, gradients and offsets bit for bit (as
//!   products in axis order), and `KernelError::NotTensorProduct` for any other width;
//! - `Kernel::MAY_BE_TENSOR_PRODUCT` and `Kernel::MAY_CORRECT_FORCE_GRADIENTS` true
//!   wherever the kernel has a tensor width or a force-gradient correction;
//! - a typed `KernelError::OutsideDomain` far outside.
//!
//! ```
//! use nalgebra::SVector;
//! use umls_kernels::{BSplineKernel, BSplineOrder, testing::check_kernel};
//!
//! let grid = BSplineKernel::new(SVector::from([0.0, 0.0]), 0.25, [8, 8], BSplineOrder::Cubic).unwrap();
//! let points = [SVector::from([0.7, 1.1]), SVector::from([1.3, 0.4])];
//! check_kernel(&grid, &points, SVector::from([5.0, 5.0])).expect("a conforming kernel");
//! ```

use nalgebra::{SMatrix, SVector};
use umls_transfer::{Kernel, KernelError, Stencil, TensorStencil};

/// Tolerances of the suite, relative to the kernel's spacing where lengths enter.
const UNITY: f64 = 1e-12;
const REPRODUCTION: f64 = 1e-9;

/// Which property failed, where, and by how much.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The point (empty for the outside check).
    pub point: Vec<f64>,
    /// What failed, with the values.
    pub message: String,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "at {:?}: {}", self.point, self.message)
    }
}

impl std::error::Error for Violation {}

/// Whether the stencil's nodes surround the point, as away from the domain's boundary:
/// along every direction of a fine set (the integer vectors of [−4, 4]^D, normalised)
/// some node lies at least h/2 ahead.
fn surrounded<const D: usize>(offsets: &[SVector<f64, D>], h: f64) -> bool {
    let k = 4i32;
    let count = (2 * k + 1).pow(D as u32);
    (0..count).all(|code| {
        let mut u = SVector::<f64, D>::zeros();
        let mut rest = code;
        for c in u.iter_mut() {
            *c = f64::from(rest % (2 * k + 1) - k);
            rest /= 2 * k + 1;
        }
        let norm = u.norm();
        norm == 0.0 || offsets.iter().any(|r| r.dot(&u) >= 0.5 * h * norm)
    })
}

/// Whether a second moment is what `Kernel::regular_second_moment` promises: one the
/// engine inverts ([`umls_transfer::regular_inverse`]) and tr D > 10⁻³ h².
fn regular<const D: usize>(moment: &SMatrix<f64, D, D>, h: f64) -> bool {
    umls_transfer::regular_inverse(moment).is_some() && moment.trace() > 1e-3 * h * h
}

/// Checks `kernel` at each of `points` (which must lie in its domain) and that
/// `outside` is reported as outside the domain.
pub fn check_kernel<const D: usize, K: Kernel<D>>(
    kernel: &K,
    points: &[SVector<f64, D>],
    outside: SVector<f64, D>,
) -> Result<(), Violation> {
    if kernel.force_gradient_correction().is_some() && !K::MAY_CORRECT_FORCE_GRADIENTS {
        return Err(Violation {
            point: Vec::new(),
            message: "a force-gradient correction, though the type declares \
                      MAY_CORRECT_FORCE_GRADIENTS = false (the engine would drop it)"
                .into(),
        });
    }
    let mut cache = K::Cache::default();
    let (mut st, mut fresh) = (Stencil::new(), Stencil::new());
    let h = kernel.spacing();
    for x in points {
        let fail = |message: String| Violation {
            point: x.iter().copied().collect(),
            message,
        };
        // As in G2P: the particle moves to x, the kernel looks for a domain exit there
        // (and may keep what it found for the next stencil), then the stencil at x.
        if let Some(exit) = kernel.domain_exit(x, &mut cache) {
            return Err(fail(format!(
                "a domain exit through facet {:?} for a point inside the domain",
                exit.facet.iter().take(exit.facet_len).collect::<Vec<_>>()
            )));
        }
        kernel
            .stencil(x, &mut cache, &mut st)
            .map_err(|e| fail(format!("no stencil inside the domain: {e}")))?;
        let (mut sum, mut grad_sum) = (0.0, SVector::<f64, D>::zeros());
        let mut position = SVector::<f64, D>::zeros();
        let mut jacobian = SMatrix::<f64, D, D>::zeros();
        let mut moment = SMatrix::<f64, D, D>::zeros();
        for (e, (node, n, g)) in st.iter().enumerate() {
            if node as usize >= kernel.node_count() {
                return Err(fail(format!(
                    "node {node} beyond the {} nodes",
                    kernel.node_count()
                )));
            }
            if kernel.nonnegative_values() && n.is_sign_negative() {
                return Err(fail(format!(
                    "N = {n} at node {node}, though the kernel declares no negative values"
                )));
            }
            let xi = kernel.node_position(node as usize);
            let offset = st.offsets()[e];
            if (offset - (xi - x)).norm() >= UNITY * h {
                return Err(fail(format!(
                    "offset of node {node} is {offset:?}, not x_i − x = {:?}",
                    xi - x
                )));
            }
            sum += n;
            grad_sum += g;
            position += xi * n;
            jacobian += xi * g.transpose();
            moment += (xi - x) * (xi - x).transpose() * n;
        }
        if (sum - 1.0).abs() >= UNITY {
            return Err(fail(format!("Σ N = {sum}, not 1")));
        }
        if grad_sum.norm() * h >= 100.0 * UNITY {
            return Err(fail(format!("Σ ∇N = {grad_sum:?}, not 0")));
        }
        if (position - x).norm() >= UNITY * (1.0 + x.norm()) {
            return Err(fail(format!("Σ N x_i = {position:?}, not x")));
        }
        if (jacobian - SMatrix::<f64, D, D>::identity()).norm() >= REPRODUCTION {
            return Err(fail(format!("Σ x_i ∇N_iᵀ = {jacobian}, not I")));
        }
        if let Some(s) = kernel.constant_second_moment() {
            if (moment - SMatrix::<f64, D, D>::identity() * s).norm() >= REPRODUCTION * s {
                return Err(fail(format!("Σ N r rᵀ = {moment}, not the declared {s} I")));
            }
        }
        if kernel.regular_second_moment() && surrounded(st.offsets(), h) && !regular(&moment, h) {
            return Err(fail(format!(
                "Σ N r rᵀ = {moment} is declared regular but is not positive definite, \
                 is near singular or vanishes"
            )));
        }
        let range = kernel
            .node_range(x, &mut K::Cache::default(), &mut fresh)
            .map_err(|e| fail(format!("no node range inside the domain: {e}")))?;
        if Some(range) != st.node_range() {
            return Err(fail(format!(
                "node_range gives {range:?}, the stencil spans {:?}",
                st.node_range()
            )));
        }
        kernel
            .stencil(x, &mut K::Cache::default(), &mut fresh)
            .map_err(|e| fail(format!("no stencil from a fresh cache: {e}")))?;
        if st != fresh {
            return Err(fail("a fresh cache gives another stencil".into()));
        }
        let mut visited = Stencil::new();
        kernel
            .visit_stencil(x, &mut K::Cache::default(), &mut fresh, |node, n, g, r| {
                visited.push(node, n, *g, *r)
            })
            .map_err(|e| fail(format!("visit_stencil fails inside the domain: {e}")))?;
        if st != visited {
            return Err(fail(
                "visit_stencil hands over other entries than stencil gives".into(),
            ));
        }
        check_appended(kernel, x, &st).map_err(fail)?;
        check_factors(kernel, x, &st).map_err(fail)?;
        check_tensor(kernel, x, &st).map_err(fail)?;
    }
    let outside_error = |what: &str, got: String| Violation {
        point: outside.iter().copied().collect(),
        message: format!("expected an outside-the-domain error from {what}, got {got}"),
    };
    match kernel.stencil(&outside, &mut K::Cache::default(), &mut st) {
        Err(KernelError::OutsideDomain { .. }) => {}
        other => return Err(outside_error("stencil", format!("{other:?}"))),
    }
    match kernel.node_range(&outside, &mut K::Cache::default(), &mut st) {
        Err(KernelError::OutsideDomain { .. }) => {}
        other => return Err(outside_error("node_range", format!("{other:?}"))),
    }
    match kernel.visit_stencil(&outside, &mut K::Cache::default(), &mut st, |_, _, _, _| {}) {
        Err(KernelError::OutsideDomain { .. }) => {}
        other => return Err(outside_error("visit_stencil", format!("{other:?}"))),
    }
    // A failed append leaves what the arrays held.
    let (mut nodes, mut values, mut gradients) = held::<D>();
    match kernel.append_stencil(
        &outside,
        &mut K::Cache::default(),
        &mut st,
        &mut nodes,
        &mut values,
        &mut gradients,
    ) {
        Err(KernelError::OutsideDomain { .. }) => {}
        other => return Err(outside_error("append_stencil", format!("{other:?}"))),
    }
    if (nodes, values, gradients) != held::<D>() {
        return Err(outside_error(
            "append_stencil",
            "an error that left entries in the arrays".into(),
        ));
    }
    Ok(())
}

/// What the arrays hold before `Kernel::append_stencil` is called on them: one entry
/// that an append must keep in front of its own, and that a failed append must leave.
fn held<const D: usize>() -> (Vec<u32>, Vec<f64>, Vec<SVector<f64, D>>) {
    (vec![7], vec![0.5], vec![SVector::repeat(2.0)])
}

/// `Kernel::append_stencil` at `x`, whose stencil is `st`: the stencil's nodes, values
/// and gradients, bit for bit, after what the arrays held.
fn check_appended<const D: usize, K: Kernel<D>>(
    kernel: &K,
    x: &SVector<f64, D>,
    st: &Stencil<D>,
) -> Result<(), String> {
    let (mut nodes, mut values, mut gradients) = held::<D>();
    kernel
        .append_stencil(
            x,
            &mut K::Cache::default(),
            &mut Stencil::new(),
            &mut nodes,
            &mut values,
            &mut gradients,
        )
        .map_err(|e| format!("append_stencil fails inside the domain: {e}"))?;
    let (held_nodes, held_values, held_gradients) = held::<D>();
    let same = nodes[..1] == held_nodes
        && values[..1] == held_values
        && gradients[..1] == held_gradients
        && nodes[1..] == *st.nodes()
        && values[1..]
            .iter()
            .map(|v| v.to_bits())
            .eq(st.values().iter().map(|v| v.to_bits()))
        && gradients[1..] == *st.gradients();
    if same {
        Ok(())
    } else {
        Err("append_stencil appends other entries than stencil gives".into())
    }
}

/// The factored-stencil checks at `x`, whose stencil is `st`.
fn check_factors<const D: usize, K: Kernel<D>>(
    kernel: &K,
    x: &SVector<f64, D>,
    st: &Stencil<D>,
) -> Result<(), String> {
    let mut cache = K::Cache::default();
    let mut scratch = Stencil::new();
    let Some(layout) = kernel.factor_layout() else {
        let mut entries = Vec::new();
        return match kernel.factor_stencil(x, &mut cache, &mut scratch, &mut [], &mut entries) {
            Err(KernelError::NotFactored { .. }) => Ok(()),
            other => Err(format!(
                "factor_stencil without a factor layout gives {other:?}, not NotFactored"
            )),
        };
    };
    let mut particle = vec![0.0; layout.per_particle];
    // Appended after what is there, as an engine's chunk appends particle after particle.
    let mut entries = vec![f64::NAN; 3];
    let range = kernel
        .factor_stencil(x, &mut cache, &mut scratch, &mut particle, &mut entries)
        .map_err(|e| format!("factor_stencil fails inside the domain: {e}"))?;
    if Some(range) != st.node_range() {
        return Err(format!(
            "factor_stencil gives the node range {range:?}, the stencil spans {:?}",
            st.node_range()
        ));
    }
    if entries.len() - 3 != layout.per_entry * st.len() {
        return Err(format!(
            "factor_stencil appended {} numbers for {} entries of {} each",
            entries.len() - 3,
            st.len(),
            layout.per_entry
        ));
    }
    let mut rebuilt = Stencil::new();
    kernel
        .visit_factored(x, &cache, &particle, &entries[3..], |node, n, g, r| {
            rebuilt.push(node, n, *g, *r)
        })
        .map_err(|e| format!("visit_factored fails inside the domain: {e}"))?;
    if &rebuilt != st {
        return Err("visit_factored rebuilds other entries than stencil gives".into());
    }
    Ok(())
}

/// The tensor-product checks at `x`, whose stencil is `st`: the factors of the declared
/// width rebuild it, every other width (1 to 6) is refused.
fn check_tensor<const D: usize, K: Kernel<D>>(
    kernel: &K,
    x: &SVector<f64, D>,
    st: &Stencil<D>,
) -> Result<(), String> {
    let declared = kernel.tensor_width();
    if declared.is_some() && !K::MAY_BE_TENSOR_PRODUCT {
        return Err(
            "a tensor width, though the type declares MAY_BE_TENSOR_PRODUCT = false (the \
             engine would never take its row sums)"
                .into(),
        );
    }
    let mut outcomes = [
        tensor_of_width::<D, K, 1>(kernel, x, st, declared),
        tensor_of_width::<D, K, 2>(kernel, x, st, declared),
        tensor_of_width::<D, K, 3>(kernel, x, st, declared),
        tensor_of_width::<D, K, 4>(kernel, x, st, declared),
        tensor_of_width::<D, K, 5>(kernel, x, st, declared),
        tensor_of_width::<D, K, 6>(kernel, x, st, declared),
    ]
    .into_iter();
    if let Some(w) = declared.filter(|w| !(1..=6).contains(w)) {
        return Err(format!("tensor width {w}: the suite checks widths 1 to 6"));
    }
    outcomes.try_for_each(|outcome| outcome)
}

/// A tensor stencil's `corner` names its `first` node; where the kernel declares its
/// node lattice, the strides are the lattice's, the stencil lies inside it and the
/// lattice holds every node.
fn check_lattice<const D: usize, K: Kernel<D>, const W: usize>(
    kernel: &K,
    t: &TensorStencil<D, W>,
) -> Result<(), String> {
    let first: usize = (0..D).map(|k| t.corner[k] * t.strides[k]).sum();
    if first != t.first {
        return Err(format!(
            "tensor_stencil's corner {:?} with strides {:?} names node {first}, not its \
             first node {}",
            t.corner, t.strides, t.first
        ));
    }
    let Some(counts) = kernel.node_lattice() else {
        return Ok(());
    };
    let strides: [usize; D] = std::array::from_fn(|k| counts[..k].iter().product());
    if strides != t.strides {
        return Err(format!(
            "node_lattice {counts:?} has strides {strides:?}, tensor_stencil {:?}",
            t.strides
        ));
    }
    if (0..D).any(|k| t.corner[k] + W > counts[k]) {
        return Err(format!(
            "tensor_stencil's corner {:?} of width {W} leaves node_lattice {counts:?}",
            t.corner
        ));
    }
    if counts.iter().product::<usize>() != kernel.node_count() {
        return Err(format!(
            "node_lattice {counts:?} does not hold node_count {} nodes",
            kernel.node_count()
        ));
    }
    Ok(())
}

/// [`check_tensor`] for the width `W`.
// The axis index runs over several per-axis arrays at once.
#[allow(clippy::needless_range_loop)]
fn tensor_of_width<const D: usize, K: Kernel<D>, const W: usize>(
    kernel: &K,
    x: &SVector<f64, D>,
    st: &Stencil<D>,
    declared: Option<usize>,
) -> Result<(), String> {
    let result = kernel.tensor_stencil::<W>(x);
    if declared != Some(W) {
        return match result {
            Err(KernelError::NotTensorProduct { width, .. }) if width == W => Ok(()),
            other => Err(format!(
                "tensor_stencil of width {W} (declared {declared:?}) gives {other:?}, not \
                 NotTensorProduct"
            )),
        };
    }
    let t: TensorStencil<D, W> =
        result.map_err(|e| format!("tensor_stencil fails inside the domain: {e}"))?;
    check_lattice(kernel, &t)?;
    let mut rebuilt = Stencil::new();
    let mut digits = [0usize; D];
    'entries: loop {
        let node = t.first + (0..D).map(|k| digits[k] * t.strides[k]).sum::<usize>();
        let mut value = t.values[0][digits[0]];
        for k in 1..D {
            value *= t.values[k][digits[k]];
        }
        let gradient = SVector::<f64, D>::from_fn(|j, _| {
            let mut g = if j == 0 {
                t.derivatives[0][digits[0]]
            } else {
                t.values[0][digits[0]]
            };
            for k in 1..D {
                g *= if k == j {
                    t.derivatives[k][digits[k]]
                } else {
                    t.values[k][digits[k]]
                };
            }
            g
        });
        let offset = SVector::<f64, D>::from_fn(|k, _| t.offsets[k][digits[k]]);
        let Ok(node) = u32::try_from(node) else {
            return Err(format!("tensor_stencil gives node {node}, beyond u32"));
        };
        rebuilt.push(node, value, gradient, offset);
        // Axis 0 fastest, as the stencil's node numbering runs.
        for digit in digits.iter_mut() {
            *digit += 1;
            if *digit < W {
                continue 'entries;
            }
            *digit = 0;
        }
        break;
    }
    if &rebuilt != st {
        return Err(format!(
            "tensor_stencil's factors of width {W} rebuild other entries than stencil gives"
        ));
    }
    Ok(())
}
