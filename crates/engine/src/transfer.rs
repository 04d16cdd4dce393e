//! Particle-grid transfer schemes behind a trait: each a type of its own, or any of them
//! as the run-time value [`AnyTransfer`], whose [`TransferShape`] the step reads (the
//! tensor-product row sums compiled per shape); and the stress-update variants.

use nalgebra::{SMatrix, SVector};
use umls_transfer::regular_inverse;

/// A velocity transfer scheme: how particle momentum reaches the grid and how grid
/// velocities come back to the particle.
/// What a transfer scheme reads and writes, which decides the work of P2G and G2P.
///
/// A value rather than associated constants, so that one simulation type can run any
/// scheme chosen at run time ([`AnyTransfer`]): the loops that would pay for a branch
/// on it (G2P's particle loop, P2G's stencil sums, the tensor-product row sums) are
/// still compiled per shape and chosen once per chunk or particle, while the rest of
/// the step, which does not depend on it, is compiled once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TransferShape {
    /// Whether the affine matrix C_p enters P2G: (mv)_i += N m_p (v_p + C_p (x_i − x_p)).
    pub affine: bool,
    /// Whether [`TransferScheme::affine`] reads B_p and D_p; G2P skips accumulating them
    /// otherwise.
    pub uses_moments: bool,
    /// Whether [`TransferScheme::velocity`] reads the FLIP increment; G2P skips reading
    /// the old grid velocities otherwise.
    pub uses_flip: bool,
    /// Whether P2G folds the internal force into the affine momentum (MLS-MPM, Hu et al.
    /// 2018): ∇N_i is taken as D_p⁻¹ N_i (x_i − x_p), so the stress impulse
    /// −Δt V τ ∇N_i joins the term P2G spreads anyway, N_i (m C − Δt V τ D_p⁻¹)(x_i − x_p),
    /// and gravity joins the momentum: no per-node gradient, force or stiffness, and G2P
    /// takes ∇v = C_p. Needs D_p⁻¹: B-splines' constant one, or each particle's own
    /// where the kernel's D_p stays regular (MLS fits; `Kernel::regular_second_moment`);
    /// the grid update then sees no separate force, so damping and selective mass
    /// scaling do not act, and MUSL's re-mapped gradient would be another scheme
    /// ([`crate::Simulation::new`] refuses those combinations).
    pub fused_force: bool,
    /// Whether the particles carry quadratic velocity modes besides C_p
    /// ([`crate::quadratic_modes`]): G2P fits their coefficients Q_p, and P2G spreads
    /// (mv)_i += N m_p (v_p + C_p r + Σ_k Q_pk q_k(r)).
    pub quadratic: bool,
}

impl TransferShape {
    /// No affine field, no FLIP increment: PIC.
    pub const PIC: Self = Self {
        affine: false,
        uses_moments: false,
        uses_flip: false,
        fused_force: false,
        quadratic: false,
    };
    /// FLIP: PIC's shape with the FLIP increment.
    pub const FLIP: Self = Self {
        uses_flip: true,
        ..Self::PIC
    };
    /// APIC: the affine field from the moments B_p and D_p.
    pub const APIC: Self = Self {
        affine: true,
        uses_moments: true,
        ..Self::PIC
    };
    /// APIC blended with FLIP.
    pub const APIC_FLIP: Self = Self {
        uses_flip: true,
        ..Self::APIC
    };
    /// MLS-MPM: APIC's shape with the force folded into the momentum.
    pub const MLS_MPM: Self = Self {
        fused_force: true,
        ..Self::APIC
    };
    /// The affine field from the velocity gradient, without the moments.
    pub const VELOCITY_GRADIENT: Self = Self {
        affine: true,
        ..Self::PIC
    };
    /// APIC with quadratic modes.
    pub const QUADRATIC_APIC: Self = Self {
        quadratic: true,
        ..Self::APIC
    };
    /// Quadratic APIC blended with FLIP.
    pub const QUADRATIC_APIC_FLIP: Self = Self {
        uses_flip: true,
        ..Self::QUADRATIC_APIC
    };
}

/// A velocity transfer scheme: how particle momentum reaches the grid and how grid
/// velocities come back to the particle.
pub trait TransferScheme: Copy + Send + Sync + std::fmt::Debug {
    /// What the scheme reads and writes. A scheme of fixed shape returns a constant.
    fn shape(&self) -> TransferShape;

    /// Short name for reports.
    fn name(&self) -> &'static str;

    /// New particle velocity from its old value, the PIC value Σ N ṽ_i and the FLIP
    /// increment Σ N (ṽ_i − v_i). Default: the PIC value.
    fn velocity<const D: usize>(
        &self,
        old: &SVector<f64, D>,
        pic: &SVector<f64, D>,
        flip_increment: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        let _ = (old, flip_increment);
        *pic
    }

    /// New affine matrix from B_p = Σ N ṽ_i (x_i − x_p)ᵀ, D_p = Σ N (x_i − x_p)(x_i − x_p)ᵀ
    /// and the velocity gradient ∇v_p = Σ ṽ_i ∇N_iᵀ. Default (non-affine schemes): zero.
    fn affine<const D: usize>(
        &self,
        b: &SMatrix<f64, D, D>,
        d: &SMatrix<f64, D, D>,
        grad_v: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        let _ = (b, d, grad_v);
        SMatrix::zeros()
    }

    /// [`Self::affine`] for a kernel whose second moment D_p is s·I everywhere
    /// (`Kernel::constant_second_moment`); a scheme may skip inverting D_p.
    fn affine_with_constant_moment<const D: usize>(
        &self,
        b: &SMatrix<f64, D, D>,
        s: f64,
        grad_v: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        self.affine(b, &(SMatrix::identity() * s), grad_v)
    }
}

/// Particle-in-cell: v_p = Σ N ṽ_i (dissipative, stable).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Pic;

/// FLIP blended with PIC: v_p = α (v_p + Σ N (ṽ_i − v_i)) + (1 − α) Σ N ṽ_i.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flip {
    /// FLIP fraction α ∈ [0, 1] (1 = pure FLIP).
    pub alpha: f64,
}

/// Affine PIC (Jiang et al. 2015): C_p = B_p D_p⁻¹, with B_p and D_p summed over the
/// stencil so the scheme holds for any kernel (D_p is not the B-spline closed form).
///
/// For hat functions D_p vanishes as a particle approaches a vertex (all weight on one
/// node), and B_p D_p⁻¹ would explode; where D_p is not positive definite (Cholesky
/// fails: MLS values can be negative, so D_p can have negative eigenvalues with a
/// positive determinant) or is ill-conditioned (det D_p < 10⁻⁶ (tr D_p / D)^D) the scheme
/// uses the velocity gradient, which B_p D_p⁻¹ equals for linear shape functions
/// (N_i D_p⁻¹ (x_i − x_p) = ∇N_i on a simplex).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Apic;

/// MLS-MPM (Hu et al. 2018, Taichi's `mpm88`/`mpm3d`): APIC's transfers with the
/// internal force folded into the affine momentum ([`TransferShape::fused_force`]) and
/// ∇v = C_p. For quadratic B-splines D_p⁻¹ N_i (x_i − x_p) is an O(h) approximation of
/// ∇N_i (exact for linear velocity fields), so results differ from APIC's at that order
/// for about half the per-node arithmetic. With an MLS kernel (UMLS) D_p is each
/// particle's own, summed with its stencil: the gradient D_p⁻¹ N_i (x_i − x_p) is then
/// as continuous as N_i and D_p (across facets too) and still exact for linear fields
/// (Σ N_i r_i = 0 and Σ N_i r_i r_iᵀ = D_p), but it is not the kernel's reconstructed
/// gradient, so the kernel's integration correction does not enter either.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MlsMpm;

/// FLIP blended with APIC (the AFLIP of Fei et al. 2021): P2G spreads the particle's
/// affine field as APIC does, (mv)_i += N m_p (v_p + C_p (x_i − x_p)), and G2P updates the
/// velocity as [`Flip`] does, v_p = α (v_p + Σ N (ṽ_i − v_i)) + (1 − α) Σ N ṽ_i, with
/// C_p = B_p D_p⁻¹ as [`Apic`] makes it. The PIC part then only filters what the affine
/// field does not carry, so less kinetic energy is lost at the same α than with FLIP.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApicFlip {
    /// FLIP fraction α ∈ [0, 1] (0 = APIC).
    pub alpha: f64,
}

/// APIC with quadratic modes (after Fu et al. 2017's PolyPIC): each particle also carries
/// the coefficients Q_p of the centred quadratic modes q_k(x − x_p), which G2P fits to the
/// grid velocities with APIC's weights and P2G spreads with v_p and C_p
/// ([`crate::quadratic_modes`]). v_p and C_p are APIC's; the round trip keeps quadratic
/// velocity fields as APIC keeps affine ones, so a smooth mode loses an order less per
/// step. Momentum is conserved as with APIC (the modes have zero weighted mean). The
/// fit costs D (D + 1) / 2 more sums per component and entry, and P2G evaluates the
/// modes' frame from the stencil before its entries: the B-spline fast paths (row sums)
/// do not apply.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct QuadraticApic;

/// FLIP blended with quadratic APIC: P2G spreads the particle's affine field and quadratic
/// modes as [`QuadraticApic`] does, G2P updates the velocity as [`Flip`] does (the
/// quadratic analogue of [`ApicFlip`]). With α = 0 its results are [`QuadraticApic`]'s
/// bit for bit, at the cost of reading the old grid velocities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraticApicFlip {
    /// FLIP fraction α ∈ [0, 1] (0 = quadratic APIC).
    pub alpha: f64,
}

/// Affine transfer with the grid velocity gradient, C_p = Σ ṽ_i ∇N_iᵀ (the MLS-MPM form,
/// natural for MLS kernels whose reconstructed gradient is the fit's slope).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VelocityGradientAffine;

impl TransferScheme for Pic {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::PIC
    }
    fn name(&self) -> &'static str {
        "PIC"
    }
}

impl TransferScheme for Flip {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::FLIP
    }
    fn name(&self) -> &'static str {
        "FLIP"
    }
    fn velocity<const D: usize>(
        &self,
        old: &SVector<f64, D>,
        pic: &SVector<f64, D>,
        flip_increment: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        (old + flip_increment) * self.alpha + pic * (1.0 - self.alpha)
    }
}

impl TransferScheme for Apic {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::APIC
    }
    fn name(&self) -> &'static str {
        "APIC"
    }
    // Inlined: called with G2P's sums, which a call would keep in memory through the
    // stencil's loop.
    #[inline]
    fn affine<const D: usize>(
        &self,
        b: &SMatrix<f64, D, D>,
        d: &SMatrix<f64, D, D>,
        grad_v: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        match regular_inverse(d) {
            Some(inverse) => b * inverse,
            None => *grad_v,
        }
    }

    #[inline]
    fn affine_with_constant_moment<const D: usize>(
        &self,
        b: &SMatrix<f64, D, D>,
        s: f64,
        _: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        // D_p = s I with s > 0 (a B-spline's variance): C_p = B_p / s, the closed form.
        b / s
    }
}

/// A particle's second moment D_p that MLS-MPM cannot invert ([`regular_inverse`]),
/// reported as the cause of a [`umls_transfer::KernelError::Evaluation`] with the
/// particle and step ([`crate::EngineError::Kernel`]).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "the particle's second moment D_p (determinant {determinant:e}, trace {trace:e}) is not \
     positive definite or is near singular, and MLS-MPM's gradient D_p⁻¹ N_i (x_i − x_p) \
     needs its inverse"
)]
pub struct SingularSecondMoment {
    /// det D_p.
    pub determinant: f64,
    /// tr D_p.
    pub trace: f64,
}

impl SingularSecondMoment {
    /// The error for `d`, as the kernel `K`'s evaluation error.
    #[cold]
    pub(crate) fn of<const D: usize, K>(d: &SMatrix<f64, D, D>) -> umls_transfer::KernelError {
        umls_transfer::KernelError::evaluation(
            std::any::type_name::<K>(),
            Self {
                determinant: umls_constitutive::determinant(d),
                trace: d.trace(),
            },
        )
    }
}

/// APIC's C_p = B_p D_p⁻¹ (and its closed form for a constant D_p) in the impl of a
/// scheme that shares APIC's affine field.
macro_rules! apic_affine {
    () => {
        #[inline]
        fn affine<const D: usize>(
            &self,
            b: &SMatrix<f64, D, D>,
            d: &SMatrix<f64, D, D>,
            grad_v: &SMatrix<f64, D, D>,
        ) -> SMatrix<f64, D, D> {
            Apic.affine(b, d, grad_v)
        }
        #[inline]
        fn affine_with_constant_moment<const D: usize>(
            &self,
            b: &SMatrix<f64, D, D>,
            s: f64,
            grad_v: &SMatrix<f64, D, D>,
        ) -> SMatrix<f64, D, D> {
            Apic.affine_with_constant_moment(b, s, grad_v)
        }
    };
}

/// [`Flip`]'s velocity update with the scheme's `alpha`, in the impl of an affine scheme
/// blended with FLIP.
macro_rules! flip_velocity {
    () => {
        fn velocity<const D: usize>(
            &self,
            old: &SVector<f64, D>,
            pic: &SVector<f64, D>,
            flip_increment: &SVector<f64, D>,
        ) -> SVector<f64, D> {
            Flip { alpha: self.alpha }.velocity(old, pic, flip_increment)
        }
    };
}

impl TransferScheme for MlsMpm {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::MLS_MPM
    }
    fn name(&self) -> &'static str {
        "MLS-MPM"
    }
    apic_affine!();
}

impl TransferScheme for ApicFlip {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::APIC_FLIP
    }
    fn name(&self) -> &'static str {
        "APIC-FLIP"
    }
    flip_velocity!();
    apic_affine!();
}

impl TransferScheme for QuadraticApic {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::QUADRATIC_APIC
    }
    fn name(&self) -> &'static str {
        "quadratic APIC"
    }
    apic_affine!();
}

impl TransferScheme for QuadraticApicFlip {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::QUADRATIC_APIC_FLIP
    }
    fn name(&self) -> &'static str {
        "quadratic APIC-FLIP"
    }
    flip_velocity!();
    apic_affine!();
}

impl TransferScheme for VelocityGradientAffine {
    #[inline]
    fn shape(&self) -> TransferShape {
        TransferShape::VELOCITY_GRADIENT
    }
    fn name(&self) -> &'static str {
        "affine (velocity gradient)"
    }
    fn affine<const D: usize>(
        &self,
        _: &SMatrix<f64, D, D>,
        _: &SMatrix<f64, D, D>,
        grad_v: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        *grad_v
    }
}

/// Where in the step the deformation gradient (and so the stress) is updated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StressUpdate {
    /// Update stress last, with the velocity gradient of the updated grid velocities.
    #[default]
    Usl,
    /// Modified USL: after G2P, map the new particle momenta back to the grid and use
    /// that grid velocity for the deformation update (Sulsky et al. 1995).
    Musl,
}

#[cfg(test)]
mod tests {
    use nalgebra::Matrix2;

    use super::*;

    #[test]
    fn apic_recovers_affine_fields_and_falls_back_on_singular_d() {
        // Nodes around a particle at 0 with N = 1/4 each: D = Σ N r rᵀ, B = Σ N (A r) rᵀ.
        let a = Matrix2::new(0.3, -1.2, 0.7, 0.1);
        let offsets = [(-1.0, -0.5), (1.0, -0.5), (0.5, 1.0), (-0.5, 1.0)];
        let (mut b, mut d) = (Matrix2::zeros(), Matrix2::zeros());
        for (x, y) in offsets {
            let r = nalgebra::Vector2::new(x, y);
            b += a * r * r.transpose() * 0.25;
            d += r * r.transpose() * 0.25;
        }
        let grad_v = Matrix2::new(9.0, 9.0, 9.0, 9.0);
        assert!((Apic.affine(&b, &d, &grad_v) - a).norm() < 1e-12);
        // All weight on one node: D = 0 → the velocity gradient, not an explosion.
        assert_eq!(Apic.affine(&b, &Matrix2::zeros(), &grad_v), grad_v);
        // Positive determinant, two negative eigenvalues (possible with negative MLS
        // values): not a moment matrix, so the velocity gradient.
        let negative = nalgebra::Matrix3::new(-1.0, 0.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0, 3.0);
        assert!(umls_constitutive::determinant(&negative) > 0.0);
        let g3 = nalgebra::Matrix3::from_element(7.0);
        assert_eq!(
            Apic.affine(&nalgebra::Matrix3::identity(), &negative, &g3),
            g3
        );
        assert_eq!(Pic.affine(&b, &d, &grad_v), Matrix2::zeros());
        // A constant moment s I: the closed form equals the general inverse.
        let s = 0.3;
        let closed = Apic.affine_with_constant_moment(&b, s, &grad_v);
        assert!((closed - Apic.affine(&b, &(Matrix2::identity() * s), &grad_v)).norm() < 1e-12);
        assert_eq!(
            VelocityGradientAffine.affine_with_constant_moment(&b, s, &grad_v),
            grad_v
        );
        assert_eq!(VelocityGradientAffine.affine(&b, &d, &grad_v), grad_v);
        let v = Flip { alpha: 0.75 }.velocity(
            &nalgebra::Vector2::new(1.0, 0.0),
            &nalgebra::Vector2::new(0.0, 2.0),
            &nalgebra::Vector2::new(0.5, 0.5),
        );
        assert!((v - nalgebra::Vector2::new(1.125, 0.875)).norm() < 1e-15);
        // APIC-FLIP: FLIP's velocity, APIC's affine matrix (closed form included).
        let both = ApicFlip { alpha: 0.75 };
        let (old, pic, inc) = (
            nalgebra::Vector2::new(1.0, 0.0),
            nalgebra::Vector2::new(0.0, 2.0),
            nalgebra::Vector2::new(0.5, 0.5),
        );
        assert_eq!(both.velocity(&old, &pic, &inc), v);
        assert_eq!(both.affine(&b, &d, &grad_v), Apic.affine(&b, &d, &grad_v));
        assert_eq!(
            both.affine_with_constant_moment(&b, s, &grad_v),
            Apic.affine_with_constant_moment(&b, s, &grad_v)
        );
        assert_eq!(
            ApicFlip { alpha: 0.0 }.velocity(&old, &pic, &inc),
            pic,
            "α = 0 is APIC's velocity"
        );
    }
}

/// Any of the schemes above, chosen at run time: one simulation type for every scheme,
/// so that a program offering all of them (the scene runner) compiles the step once per
/// kernel and material rather than once per scheme as well ([`TransferShape`] says
/// which loops are still compiled per shape).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyTransfer {
    /// [`Pic`].
    Pic,
    /// [`Flip`] with its α.
    Flip(Flip),
    /// [`Apic`].
    Apic,
    /// [`ApicFlip`] with its α.
    ApicFlip(ApicFlip),
    /// [`MlsMpm`].
    MlsMpm,
    /// [`VelocityGradientAffine`].
    VelocityGradient,
    /// [`QuadraticApic`].
    QuadraticApic,
    /// [`QuadraticApicFlip`] with its α.
    QuadraticApicFlip(QuadraticApicFlip),
}

/// Calls `$call` on the scheme inside an [`AnyTransfer`].
macro_rules! each_scheme {
    ($self:expr, $t:ident => $call:expr) => {
        match $self {
            AnyTransfer::Pic => {
                let $t = Pic;
                $call
            }
            AnyTransfer::Flip($t) => $call,
            AnyTransfer::Apic => {
                let $t = Apic;
                $call
            }
            AnyTransfer::ApicFlip($t) => $call,
            AnyTransfer::MlsMpm => {
                let $t = MlsMpm;
                $call
            }
            AnyTransfer::VelocityGradient => {
                let $t = VelocityGradientAffine;
                $call
            }
            AnyTransfer::QuadraticApic => {
                let $t = QuadraticApic;
                $call
            }
            AnyTransfer::QuadraticApicFlip($t) => $call,
        }
    };
}

impl TransferScheme for AnyTransfer {
    #[inline]
    fn shape(&self) -> TransferShape {
        each_scheme!(self, t => t.shape())
    }

    fn name(&self) -> &'static str {
        each_scheme!(self, t => t.name())
    }

    #[inline]
    fn velocity<const D: usize>(
        &self,
        old: &SVector<f64, D>,
        pic: &SVector<f64, D>,
        flip_increment: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        each_scheme!(self, t => t.velocity(old, pic, flip_increment))
    }

    #[inline]
    fn affine<const D: usize>(
        &self,
        b: &SMatrix<f64, D, D>,
        d: &SMatrix<f64, D, D>,
        grad_v: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        each_scheme!(self, t => t.affine(b, d, grad_v))
    }

    #[inline]
    fn affine_with_constant_moment<const D: usize>(
        &self,
        b: &SMatrix<f64, D, D>,
        s: f64,
        grad_v: &SMatrix<f64, D, D>,
    ) -> SMatrix<f64, D, D> {
        each_scheme!(self, t => t.affine_with_constant_moment(b, s, grad_v))
    }
}
