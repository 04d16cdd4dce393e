//! The built-in kernels by name: `umls` and its variants, `linear-fe`, `bspline2` and
//! `bspline3`, each with its settings ([`Preset::family`]) and, per dimension, the
//! kernel type it is ([`PresetKernels`]). The scene runner and the command line select
//! kernels through these names; a study that wants the same kernel in its own code
//! builds it here.
//!
//! ```
//! use std::sync::Arc;
//! use umls_kernels::presets::{Dim, Preset, PresetFamily, PresetKernels};
//! use umls_mesh::generate::{Diagonal, Lattice};
//! use umls_transfer::Kernel;
//!
//! let mesh = Arc::new(Lattice::new([0.0, 0.0], [1.0, 1.0], [8, 8]).triangles(Diagonal::Right)?);
//! let preset = Preset::from_name("umls-eta4").expect("a preset");
//! let PresetFamily::Umls(settings) = preset.family() else { unreachable!() };
//! let kernel: <Dim<2> as PresetKernels<2>>::Umls = settings.kernel(mesh)?;
//! assert_eq!(kernel.node_count(), 81);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::sync::Arc;

use umls_mesh::SimplexMesh;
use umls_mls::{
    DEFAULT_SHARPENING, DEFAULT_SUPPORT_FACTOR, GradientKind, Linear, MlsError, PolynomialBasis,
    Profile, Quadratic, SharpenedBSpline, SupportRadius, UmlsKernel,
};
use umls_transfer::{Kernel, KernelError};

use crate::{BSplineOrder, UmlsMeshKernel};

/// A built-in kernel, by the name scene files and the command line use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// The C¹ UMLS kernel: linear basis, cubic B-spline weights with the incident-edge
    /// support radius, and the integration correction of its force gradients. The
    /// other UMLS names but `umls-eta4`, `umls-eta8` and `umls-element-size` (which vary
    /// `umls` itself) change one part of `umls-uncorrected`, the kernel their studies
    /// measured against (docs/umls-kernel.md).
    Umls,
    /// UMLS with the quadratic basis on the 1-ring (a ridge on the quadratic terms).
    UmlsQuadratic,
    /// UMLS with Wendland C² distance weights.
    UmlsWendland,
    /// UMLS with sharpened distance weights (the cubic B-spline over 1 + (r/ε)²).
    UmlsSharp,
    /// UMLS with the wide per-vertex support radius.
    UmlsWide,
    /// UMLS with the paper's one global radius, the mesh's longest edge.
    UmlsPaper,
    /// UMLS with the full derivative of the fit as the shape-function gradient.
    UmlsFullGradient,
    /// UMLS with the fit's derivative at frozen diminishing factors as the gradient.
    UmlsFrozenEta,
    /// `umls` without the integration correction.
    UmlsUncorrected,
    /// `umls` with weights η⁴ · d and the incident-edge support factor 1.4.
    UmlsEta4,
    /// `umls` with weights η⁸ · d and the incident-edge support factor 2.8.
    UmlsEta8,
    /// `umls` with the element-size support radius (factor 1.0).
    UmlsElementSize,
    /// Linear finite-element shape functions on the mesh.
    LinearFe,
    /// Quadratic B-splines on a Cartesian grid.
    Bspline2,
    /// Cubic B-splines on a Cartesian grid.
    Bspline3,
}

/// What a preset is: a UMLS kernel with its settings, linear FE, or a B-spline grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PresetFamily {
    /// UMLS with the linear basis ([`PresetKernels::Umls`]).
    Umls(UmlsPreset),
    /// UMLS with the quadratic basis ([`PresetKernels::UmlsQuadratic`]).
    UmlsQuadratic(UmlsPreset),
    /// [`crate::LinearFeKernel`].
    LinearFe,
    /// [`crate::BSplineKernel`] of this order.
    BSpline(BSplineOrder),
}

impl Preset {
    /// Every preset, in the order the command line lists them.
    pub const ALL: [Preset; 15] = [
        Preset::Umls,
        Preset::UmlsQuadratic,
        Preset::UmlsWendland,
        Preset::UmlsSharp,
        Preset::UmlsWide,
        Preset::UmlsPaper,
        Preset::UmlsFullGradient,
        Preset::UmlsFrozenEta,
        Preset::UmlsUncorrected,
        Preset::UmlsEta4,
        Preset::UmlsEta8,
        Preset::UmlsElementSize,
        Preset::LinearFe,
        Preset::Bspline2,
        Preset::Bspline3,
    ];

    /// The preset named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Its name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Umls => "umls",
            Preset::UmlsQuadratic => "umls-quadratic",
            Preset::UmlsWendland => "umls-wendland",
            Preset::UmlsSharp => "umls-sharp",
            Preset::UmlsWide => "umls-wide",
            Preset::UmlsPaper => "umls-paper",
            Preset::UmlsFullGradient => "umls-full-gradient",
            Preset::UmlsFrozenEta => "umls-frozen-eta",
            Preset::UmlsUncorrected => "umls-uncorrected",
            Preset::UmlsEta4 => "umls-eta4",
            Preset::UmlsEta8 => "umls-eta8",
            Preset::UmlsElementSize => "umls-element-size",
            Preset::LinearFe => "linear-fe",
            Preset::Bspline2 => "bspline2",
            Preset::Bspline3 => "bspline3",
        }
    }

    /// What the preset is, with its settings.
    pub fn family(self) -> PresetFamily {
        let umls = UmlsPreset::UMLS;
        let uncorrected = UmlsPreset {
            integration_correction: false,
            ..umls
        };
        let incident = |factor| SupportRadius::IncidentEdge { factor };
        match self {
            Preset::Umls => PresetFamily::Umls(umls),
            Preset::UmlsQuadratic => PresetFamily::UmlsQuadratic(UmlsPreset {
                higher_order_ridge: QUADRATIC_RIDGE,
                ..uncorrected
            }),
            Preset::UmlsWendland => PresetFamily::Umls(UmlsPreset {
                profile: Profile::WendlandC2,
                ..uncorrected
            }),
            Preset::UmlsSharp => PresetFamily::Umls(UmlsPreset {
                profile: sharpened(DEFAULT_SHARPENING),
                ..uncorrected
            }),
            Preset::UmlsWide => PresetFamily::Umls(UmlsPreset {
                support: SupportRadius::PerVertex { factor: 1.0 },
                ..uncorrected
            }),
            Preset::UmlsPaper => PresetFamily::Umls(UmlsPreset {
                support: SupportRadius::Global { factor: 1.0 },
                ..uncorrected
            }),
            Preset::UmlsFullGradient => PresetFamily::Umls(UmlsPreset {
                gradient: GradientKind::Full,
                ..uncorrected
            }),
            Preset::UmlsFrozenEta => PresetFamily::Umls(UmlsPreset {
                gradient: GradientKind::FrozenEta,
                ..uncorrected
            }),
            Preset::UmlsUncorrected => PresetFamily::Umls(uncorrected),
            Preset::UmlsEta4 => PresetFamily::Umls(UmlsPreset {
                support: incident(ETA4_SUPPORT_FACTOR),
                diminishing_exponent: ETA4_EXPONENT,
                ..umls
            }),
            Preset::UmlsEta8 => PresetFamily::Umls(UmlsPreset {
                support: incident(ETA8_SUPPORT_FACTOR),
                diminishing_exponent: ETA8_EXPONENT,
                ..umls
            }),
            Preset::UmlsElementSize => PresetFamily::Umls(UmlsPreset {
                support: SupportRadius::ElementSize {
                    factor: ELEMENT_SIZE_SUPPORT_FACTOR,
                },
                ..umls
            }),
            Preset::LinearFe => PresetFamily::LinearFe,
            Preset::Bspline2 => PresetFamily::BSpline(BSplineOrder::Quadratic),
            Preset::Bspline3 => PresetFamily::BSpline(BSplineOrder::Cubic),
        }
    }
}

/// The sharpened profile of ε (the presets' ε are valid).
fn sharpened(epsilon: f64) -> Profile {
    Profile::Sharpened(SharpenedBSpline::new(epsilon).expect("a valid ε"))
}

/// p of `umls-eta4`'s weights η^p · d, and its support factor: the pair of the study in
/// docs/umls-kernel.md (*Powered diminishing factor*) that keeps the vortex within 4 % of
/// `umls` and cuts the bar scene's stall to a third.
const ETA4_EXPONENT: u32 = 4;
/// See [`ETA4_EXPONENT`].
const ETA4_SUPPORT_FACTOR: f64 = 1.4;
/// p of `umls-eta8`'s weights, and its support factor: the pair of the same study that
/// brings the disks within 5 points of bspline2 at 20 and 40 cells, with FLIP 0.99 and
/// with APIC.
const ETA8_EXPONENT: u32 = 8;
/// See [`ETA8_EXPONENT`].
const ETA8_SUPPORT_FACTOR: f64 = 2.8;
/// The element-size support factor of `umls-element-size`: the radius of the cells' own
/// size, the narrowest of the sweep in docs/umls-kernel.md (*Element-size radii*) whose
/// vortex completes at four particles per cell (0.9 loses a particle at 60 cells) and
/// the widest that brings the disks within 5 points of bspline2 under both transfers.
const ELEMENT_SIZE_SUPPORT_FACTOR: f64 = 1.0;
/// Relative ridge on the quadratic monomials of `umls-quadratic`: the quadratic basis
/// needs six (2D) or ten (3D) weighted samples, more than a vertex on a wall or in a
/// corner has.
const QUADRATIC_RIDGE: f64 = 1e-3;

/// The settings of a UMLS preset; a study changes any of them before building.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UmlsPreset {
    /// The distance weight's profile.
    pub profile: Profile,
    /// The support radius rule and its factor.
    pub support: SupportRadius,
    /// The shape-function gradient.
    pub gradient: GradientKind,
    /// p of the weights η^p · d.
    pub diminishing_exponent: u32,
    /// Whether the force's gradients carry the integration correction
    /// ([`UmlsMeshKernel::with_integration_correction`]).
    pub integration_correction: bool,
    /// Relative ridge on the basis's higher-order terms (0: none).
    pub higher_order_ridge: f64,
}

impl UmlsPreset {
    /// `umls`'s settings.
    pub const UMLS: UmlsPreset = UmlsPreset {
        profile: Profile::CubicBSpline,
        support: SupportRadius::IncidentEdge {
            factor: DEFAULT_SUPPORT_FACTOR,
        },
        gradient: GradientKind::Reconstructed,
        diminishing_exponent: 1,
        integration_correction: true,
        higher_order_ridge: 0.0,
    };

    /// The MLS kernel of these settings on `mesh` (refuses a factor or an exponent out
    /// of range).
    pub fn mls_kernel<const D: usize>(
        &self,
        mesh: &SimplexMesh<D>,
    ) -> Result<UmlsKernel<D, Profile>, MlsError> {
        let mut mls = UmlsKernel::with_weight(mesh, self.profile, self.support)?
            .with_diminishing_exponent(self.diminishing_exponent)?;
        mls.conditioning.higher_order_ridge = self.higher_order_ridge;
        Ok(mls)
    }

    /// The mesh kernel of these settings on `mesh`, with the basis `B`.
    pub fn kernel<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: Arc<SimplexMesh<D>>,
    ) -> Result<UmlsMeshKernel<D, N, B, Profile>, KernelError>
    where
        UmlsMeshKernel<D, N, B, Profile>: Kernel<D>,
    {
        let mls = self
            .mls_kernel(&mesh)
            .map_err(|e| KernelError::evaluation("UMLS", e))?;
        self.mesh_kernel(mesh, mls)
    }

    /// The mesh kernel over `mls` (built by [`Self::mls_kernel`]) with these settings'
    /// gradient and, where they ask for it, the integration correction (whose fits may
    /// fail).
    pub fn mesh_kernel<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: Arc<SimplexMesh<D>>,
        mls: UmlsKernel<D, Profile>,
    ) -> Result<UmlsMeshKernel<D, N, B, Profile>, KernelError>
    where
        UmlsMeshKernel<D, N, B, Profile>: Kernel<D>,
    {
        let kernel = UmlsMeshKernel::with_kernel(mesh, mls).with_gradient(self.gradient);
        if self.integration_correction {
            kernel.with_integration_correction()
        } else {
            Ok(kernel)
        }
    }
}

/// UMLS with the linear basis and a run-time profile: the presets' `umls` kernels.
pub type LinearUmls<const D: usize, const N: usize> = UmlsMeshKernel<D, N, Linear, Profile>;
/// UMLS with the quadratic basis and a run-time profile: `umls-quadratic`.
pub type QuadraticUmls<const D: usize, const N: usize> = UmlsMeshKernel<D, N, Quadratic, Profile>;

/// The kernel types of the UMLS presets in dimension `D` (the basis size differs per
/// dimension); [`Dim`]`<1>`, `<2>` and `<3>` implement it.
pub trait PresetKernels<const D: usize> {
    /// `umls` and its linear-basis variants.
    type Umls: Kernel<D>;
    /// `umls-quadratic`.
    type UmlsQuadratic: Kernel<D>;
}

/// The dimension `D` as a type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dim<const D: usize>;

impl PresetKernels<1> for Dim<1> {
    type Umls = LinearUmls<1, 2>;
    type UmlsQuadratic = QuadraticUmls<1, 3>;
}

impl PresetKernels<2> for Dim<2> {
    type Umls = LinearUmls<2, 3>;
    type UmlsQuadratic = QuadraticUmls<2, 6>;
}

impl PresetKernels<3> for Dim<3> {
    type Umls = LinearUmls<3, 4>;
    type UmlsQuadratic = QuadraticUmls<3, 10>;
}
