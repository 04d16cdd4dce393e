//! The centred quadratic velocity modes of [`crate::QuadraticApic`].
//!
//! APIC's particle field v_p + C_p r (r = x − x_p) is the weighted least-squares fit of an
//! affine field to the grid velocities, with the shape-function values N_i as weights:
//! the round trip G2P → P2G keeps affine fields and filters the rest, the more the wider
//! the stencil. Adding quadratic modes to the fit (after Fu et al. 2017's PolyPIC) keeps
//! quadratic fields too, so a smooth mode loses an order less per step.
//!
//! The modes are the monomials m_k(r) = r_a r_b (a ≤ b) made orthogonal, under the
//! weights N_i, to the constant and to r:
//!
//! q_k(r) = m_k(r) − M_k − w_k · r,  M_k = Σ N_i m_k(r_i),  w_k = D⁻¹ Σ N_i m_k(r_i) r_i,
//!
//! with D = Σ N_i r_i r_iᵀ. For a kernel with partition of unity and linear reproduction
//! (Σ N_i = 1, Σ N_i r_i = 0: B-splines, linear elements, MLS) this gives Σ N_i q_k = 0 and
//! Σ N_i q_k r_i = 0, so:
//! - the modes carry no momentum (P2G's momentum is still Σ m_p v_p);
//! - v_p and C_p are APIC's, bit for bit in exact arithmetic, and the modes' coefficients
//!   Q_p are the fit of what APIC leaves: Q_p = (Σ N_i ṽ_i q_iᵀ) G⁻¹, G = Σ N_i q_i q_iᵀ.
//!
//! G is singular where the weighted nodes do not determine a quadratic (a quadratic
//! B-spline at its knot has two nodes per axis with weight). The fit is therefore ridged,
//! G + λ s² I with s = tr D / dim and λ = [`QUADRATIC_RIDGE`]: the modes fade out
//! continuously where G degenerates instead of taking the noise of nearly weightless
//! nodes. Measured on the 1D bar, λ from 10⁻² to 10⁻¹ changes the error by a few per
//! cent; without it quadratic B-splines at one particle per cell went wrong from the
//! first step (an error of 8 % of the amplitude).
//!
//! Each G2P accumulates, besides APIC's sums, Σ N ṽ m_k, Σ N m_k r and Σ N m_k m_l in one
//! pass, and forms the orthogonal quantities from them algebraically.

use nalgebra::{SMatrix, SVector};

/// The most quadratic modes per velocity component: D (D + 1) / 2 for D ≤ 3.
pub const MAX_QUADRATIC_MODES: usize = 6;

/// A particle's quadratic-mode coefficients Q_p: entry k is the velocity per unit of
/// mode q_k, for the pairs (a, b), a ≤ b, in the order (0,0), (0,1), …, (1,1), …; the
/// entries beyond D (D + 1) / 2 stay zero.
pub type QuadraticModes<const D: usize> = [SVector<f64, D>; MAX_QUADRATIC_MODES];

/// The ridge λ of the modes' fit, relative to (tr D / dim)², the scale of a mode squared.
pub const QUADRATIC_RIDGE: f64 = 1e-2;

/// The number of quadratic modes in `D` dimensions.
pub(crate) const fn mode_count(d: usize) -> usize {
    d * (d + 1) / 2
}

/// The monomials r_a r_b (a ≤ b) of `r`, in [`QuadraticModes`]' order (zero beyond).
#[inline(always)]
pub(crate) fn monomials<const D: usize>(r: &SVector<f64, D>) -> [f64; MAX_QUADRATIC_MODES] {
    let mut m = [0.0; MAX_QUADRATIC_MODES];
    let mut k = 0;
    for a in 0..D {
        for b in a..D {
            m[k] = r[a] * r[b];
            k += 1;
        }
    }
    m
}

/// What turns the monomials at a particle into its orthogonal modes: q_k(r) =
/// m_k(r) − `mean`[k] − `shift`[k] · r.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ModeFrame<const D: usize> {
    mean: [f64; MAX_QUADRATIC_MODES],
    shift: [SVector<f64, D>; MAX_QUADRATIC_MODES],
}

impl<const D: usize> ModeFrame<D> {
    /// The frame of a stencil with second moment `d` and third moments `third`[k] =
    /// Σ N m_k r, or `None` where D is not positive definite (no fit: the modes are off).
    pub(crate) fn new(
        d: &SMatrix<f64, D, D>,
        third: &[SVector<f64, D>; MAX_QUADRATIC_MODES],
    ) -> Option<Self> {
        let cholesky = d.cholesky()?;
        let mut frame = Self {
            mean: monomials_of_matrix(d),
            shift: [SVector::zeros(); MAX_QUADRATIC_MODES],
        };
        for (shift, t) in frame.shift.iter_mut().zip(third).take(mode_count(D)) {
            *shift = cholesky.solve(t);
        }
        frame
            .shift
            .iter()
            .all(|w| w.iter().all(|c| c.is_finite()))
            .then_some(frame)
    }

    /// The frame of a whole stencil of (N_i, r_i) pairs, with the stencil's second
    /// moment D = Σ N r rᵀ it was built from (summed in entry order, the bits of
    /// `stencils::second_moment`, so a caller needs no second pass for it).
    pub(crate) fn of_stencil(
        entries: impl Iterator<Item = (f64, SVector<f64, D>)>,
    ) -> Option<(Self, SMatrix<f64, D, D>)> {
        let mut d = SMatrix::<f64, D, D>::zeros();
        let mut third = [SVector::<f64, D>::zeros(); MAX_QUADRATIC_MODES];
        for (n, r) in entries {
            d += r * r.transpose() * n;
            let m = monomials(&r);
            for k in 0..mode_count(D) {
                third[k] += r * (m[k] * n);
            }
        }
        Self::new(&d, &third).map(|frame| (frame, d))
    }

    /// The modes' kinetic energy per unit mass on a stencil of (N_i, r_i) pairs,
    /// Σ_i N_i |Σ_k Q_k q_k(r_i)|² = tr(Q G Qᵀ): what P2G's limiter compares with the
    /// energy the modes had where G2P fitted them.
    pub(crate) fn energy(
        &self,
        modes: &QuadraticModes<D>,
        entries: impl Iterator<Item = (f64, SVector<f64, D>)>,
    ) -> f64 {
        entries
            .map(|(n, r)| n * self.velocity(modes, &r).norm_squared())
            .sum()
    }

    /// The modes' velocity at offset `r`: Σ_k Q_k q_k(r).
    #[inline(always)]
    pub(crate) fn velocity(
        &self,
        modes: &QuadraticModes<D>,
        r: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        let m = monomials(r);
        let mut v = SVector::zeros();
        for k in 0..mode_count(D) {
            v += modes[k] * (m[k] - self.mean[k] - self.shift[k].dot(r));
        }
        v
    }
}

/// D_ab for a ≤ b, in [`QuadraticModes`]' order: the monomials' weighted means M_k.
fn monomials_of_matrix<const D: usize>(d: &SMatrix<f64, D, D>) -> [f64; MAX_QUADRATIC_MODES] {
    let mut m = [0.0; MAX_QUADRATIC_MODES];
    let mut k = 0;
    for a in 0..D {
        for b in a..D {
            m[k] = d[(a, b)];
            k += 1;
        }
    }
    m
}

/// The sums one pass over a stencil gathers for the modes' fit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ModeSums<const D: usize> {
    /// Σ N ṽ m_k.
    velocity: [SVector<f64, D>; MAX_QUADRATIC_MODES],
    /// Σ N m_k r.
    third: [SVector<f64, D>; MAX_QUADRATIC_MODES],
    /// Σ N m_k m_l.
    fourth: SMatrix<f64, MAX_QUADRATIC_MODES, MAX_QUADRATIC_MODES>,
}

impl<const D: usize> Default for ModeSums<D> {
    fn default() -> Self {
        Self {
            velocity: [SVector::zeros(); MAX_QUADRATIC_MODES],
            third: [SVector::zeros(); MAX_QUADRATIC_MODES],
            fourth: SMatrix::zeros(),
        }
    }
}

impl<const D: usize> ModeSums<D> {
    /// Adds a stencil entry: value `n`, grid velocity `v`, offset `r`.
    #[inline(always)]
    pub(crate) fn add(&mut self, n: f64, v: &SVector<f64, D>, r: &SVector<f64, D>) {
        let m = monomials(r);
        let q = mode_count(D);
        for k in 0..q {
            let nm = n * m[k];
            self.velocity[k] += v * nm;
            self.third[k] += r * nm;
            for (l, &ml) in m.iter().enumerate().take(q).skip(k) {
                self.fourth[(k, l)] += nm * ml;
            }
        }
    }

    /// The modes' frame on the stencil these sums were gathered from, given its second
    /// moment `d` (the bits of [`ModeFrame::of_stencil`] when `d` was summed in the same
    /// pass).
    pub(crate) fn frame(&self, d: &SMatrix<f64, D, D>) -> Option<ModeFrame<D>> {
        ModeFrame::new(d, &self.third)
    }

    /// The modes' coefficients Q_p and their energy tr(Q G Qᵀ) (with the unridged G),
    /// given the same pass's PIC value `pic` = Σ N ṽ, APIC's B = Σ N ṽ rᵀ and the second
    /// moment `d` = Σ N r rᵀ (no modes where D is not positive definite, where APIC
    /// falls back too).
    pub(crate) fn fit(
        &self,
        pic: &SVector<f64, D>,
        b: &SMatrix<f64, D, D>,
        d: &SMatrix<f64, D, D>,
    ) -> (QuadraticModes<D>, f64) {
        let mut modes = [SVector::zeros(); MAX_QUADRATIC_MODES];
        let Some(frame) = ModeFrame::new(d, &self.third) else {
            return (modes, 0.0);
        };
        let q = mode_count(D);
        let scale = d.trace() / D as f64;
        // G_kl = Σ N q_k q_l = Σ N m_k m_l − M_k M_l − T_k · w_l (q_k ⊥ 1, r); the unused
        // modes' rows are the identity's.
        let mut gram = SMatrix::<f64, MAX_QUADRATIC_MODES, MAX_QUADRATIC_MODES>::identity();
        for k in 0..q {
            for l in k..q {
                let g = self.fourth[(k, l)]
                    - frame.mean[k] * frame.mean[l]
                    - self.third[k].dot(&frame.shift[l]);
                gram[(k, l)] = g;
                gram[(l, k)] = g;
            }
        }
        let mut ridged = gram;
        for k in 0..q {
            ridged[(k, k)] += QUADRATIC_RIDGE * scale * scale;
        }
        let Some(cholesky) = ridged.cholesky() else {
            return (modes, 0.0);
        };
        // Right-hand sides Σ N ṽ q_k = Σ N ṽ m_k − M_k Σ N ṽ − B w_k, one per component.
        let mut rhs = SMatrix::<f64, MAX_QUADRATIC_MODES, D>::zeros();
        for k in 0..q {
            let row = self.velocity[k] - pic * frame.mean[k] - b * frame.shift[k];
            rhs.set_row(k, &row.transpose());
        }
        let solved = cholesky.solve(&rhs);
        for (k, mode) in modes.iter_mut().enumerate().take(q) {
            *mode = solved.row(k).transpose();
        }
        let energy: f64 = (0..q)
            .map(|k| {
                (0..q)
                    .map(|l| modes[k].dot(&modes[l]) * gram[(k, l)])
                    .sum::<f64>()
            })
            .sum();
        if energy.is_finite() && modes.iter().all(|m| m.iter().all(|c| c.is_finite())) {
            (modes, energy)
        } else {
            ([SVector::zeros(); MAX_QUADRATIC_MODES], 0.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Vector2, Vector3};

    use super::*;

    /// Shape-function-like weights on scattered offsets with Σ N = 1 and Σ N r = 0 (the
    /// nodes' mean moved onto the particle).
    fn weighted_offsets() -> Vec<(f64, Vector2<f64>)> {
        let raw = [
            (0.1, Vector2::new(-1.0, -0.7)),
            (0.2, Vector2::new(0.4, -1.1)),
            (0.15, Vector2::new(1.2, 0.1)),
            (0.25, Vector2::new(-0.3, 0.9)),
            (0.1, Vector2::new(0.8, 1.3)),
            (0.12, Vector2::new(-1.4, 0.4)),
            (0.08, Vector2::new(0.2, 0.2)),
        ];
        let total: f64 = raw.iter().map(|(n, _)| n).sum();
        let mean: Vector2<f64> = raw.iter().map(|(n, r)| r * *n).sum::<Vector2<f64>>() / total;
        raw.iter().map(|(n, r)| (n / total, r - mean)).collect()
    }

    #[test]
    fn the_modes_are_orthogonal_to_the_constant_and_the_offset() {
        let stencil = weighted_offsets();
        let (frame, _) = ModeFrame::of_stencil(stencil.iter().copied()).unwrap();
        for k in 0..3 {
            let mut unit = [SVector::zeros(); MAX_QUADRATIC_MODES];
            unit[k] = Vector2::new(1.0, 0.0);
            let (mut sum, mut first) = (0.0, Vector2::zeros());
            for (n, r) in &stencil {
                let q = frame.velocity(&unit, r)[0];
                sum += n * q;
                first += r * (n * q);
            }
            assert!(sum.abs() < 1e-14, "mode {k}: Σ N q = {sum}");
            assert!(first.norm() < 1e-14, "mode {k}: Σ N q r = {first}");
        }
    }

    #[test]
    fn a_quadratic_field_is_recovered_up_to_the_ridge() {
        // v(r) = v0 + A r + quadratic part; the fit with a vanishing ridge returns it.
        let stencil = weighted_offsets();
        let field = |r: &Vector2<f64>| {
            Vector2::new(
                0.5 + 0.3 * r[0] - 0.2 * r[1] + 0.7 * r[0] * r[0] - 0.4 * r[0] * r[1],
                -0.1 + 0.6 * r[1] + 0.25 * r[1] * r[1] + 0.9 * r[0] * r[1],
            )
        };
        let mut sums = ModeSums::<2>::default();
        let (mut pic, mut b, mut d) = (Vector2::zeros(), SMatrix::zeros(), SMatrix::zeros());
        for (n, r) in &stencil {
            let v = field(r);
            sums.add(*n, &v, r);
            pic += v * *n;
            b += v * r.transpose() * *n;
            d += r * r.transpose() * *n;
        }
        let (modes, energy) = sums.fit(&pic, &b, &d);
        let (frame, _) = ModeFrame::of_stencil(stencil.iter().copied()).unwrap();
        // The fit's energy is the modes' field's Σ N |Σ Q q|² on the same stencil.
        let direct = frame.energy(&modes, stencil.iter().copied());
        assert!(
            (energy - direct).abs() < 1e-12 * direct,
            "{energy} against {direct}"
        );
        let c = b * d.try_inverse().unwrap();
        // The fitted field v_p + C r + Σ Q q against the field at every node; the ridge
        // (10⁻² of the modes' scale) shrinks the quadratic part by about as much.
        let mut worst: f64 = 0.0;
        let mut apic_worst: f64 = 0.0;
        for (_, r) in &stencil {
            let fitted = pic + c * r + frame.velocity(&modes, r);
            worst = worst.max((fitted - field(r)).norm());
            apic_worst = apic_worst.max((pic + c * r - field(r)).norm());
        }
        assert!(worst < 0.05 * apic_worst, "fit {worst}, APIC {apic_worst}");
        assert_eq!(modes[3], Vector2::zeros(), "beyond the 2D modes");
    }

    #[test]
    fn a_degenerate_stencil_gives_no_modes_but_finite_ones_under_the_ridge() {
        // Two nodes on a line (a B-spline at its knot in 1D): q vanishes on both, G = 0,
        // and the ridge gives zero modes instead of a division by zero.
        let stencil = [
            (0.5, Vector3::new(-0.5, 0.0, 0.0)),
            (0.5, Vector3::new(0.5, 0.0, 0.0)),
        ];
        let mut sums = ModeSums::<3>::default();
        for (n, r) in &stencil {
            sums.add(*n, &Vector3::new(1.0, 2.0, 3.0), r);
        }
        let d = stencil
            .iter()
            .map(|(n, r)| r * r.transpose() * *n)
            .sum::<SMatrix<f64, 3, 3>>();
        // D is singular here (no spread in y, z): no frame, no modes.
        let (modes, energy) = sums.fit(&Vector3::new(1.0, 2.0, 3.0), &SMatrix::zeros(), &d);
        assert!(modes.iter().all(|m| *m == Vector3::zeros()) && energy == 0.0);
        assert_eq!(mode_count(3), 6);
        assert_eq!(
            monomials(&Vector3::new(1.0, 2.0, 3.0)),
            [1.0, 2.0, 3.0, 4.0, 6.0, 9.0]
        );
    }
}
