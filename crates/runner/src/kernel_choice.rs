//! Which kernel a run steps with: the [`KernelFactory`] port through which any kernel
//! (a built-in preset or a researcher's own type) is built from a scene's set-up, and
//! the built-in presets behind the scene key `[kernel] kind` and `umls run --kernel`.
//!
//! A preset names a kernel type and its settings: the UMLS variants differ in profile,
//! support radius, gradient, exponent of η and integration correction (`umls_preset`);
//! `linear-fe` and the B-spline grids have one setting each. A kernel from outside the
//! workspace implements [`KernelFactory`] and goes through the same run loop
//! ([`crate::run_with`]), with the same outputs, metrics and summary.

use std::sync::Arc;

use umls_kernels::{BSplineKernel, BSplineOrder, GradientKind, LinearFeKernel, UmlsMeshKernel};
use umls_mesh::SimplexMesh;
use umls_mls::{
    DEFAULT_SHARPENING, DEFAULT_SUPPORT_FACTOR, Linear, Profile, Quadratic, SharpenedBSpline,
    SupportRadius, UmlsKernel,
};
use umls_transfer::Kernel;
use umls_ugimp::{UgimpError, UgimpKernel};

use crate::error::Result;
use crate::scene::Scene;
use crate::schema::{GradientSpec, KernelKind, SupportSpec, WeightSpec};
use crate::setup::Setup;

/// Builds a kernel for a scene's set-up: the door through which a kernel type enters
/// the runner. The built-in presets implement it ([`Preset`]), and so does any kernel
/// of a researcher's own; [`crate::run_with`] runs a scene with it.
pub trait KernelFactory<const D: usize> {
    /// The kernel type the runs step with.
    type Kernel: Kernel<D>;

    /// The kernel's name in the summary, the history's plot titles and the report.
    fn name(&self) -> String;

    /// Whether the kernel's nodes are the mesh's vertices. A mesh kernel needs the
    /// lattice split into simplices and writes its nodal fields onto `mesh.vtu`; a grid
    /// kernel (false) writes `grid.vtu`, and walls given as mesh groups reach it as the
    /// staircase of its nodes outside the mesh.
    fn on_mesh(&self) -> bool;

    /// The kernel over the scene's background (`setup.background`: a mesh, or the box
    /// of a lattice that a grid kernel does not split); errors name the scene key.
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel>;
}

/// A built-in kernel of `[kernel] kind`, with the UMLS kernel type of its dimension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Preset<U> {
    kind: KernelKind,
    umls: std::marker::PhantomData<U>,
}

impl<U> Preset<U> {
    /// The preset of `kind`.
    pub fn new(kind: KernelKind) -> Self {
        Self {
            kind,
            umls: std::marker::PhantomData,
        }
    }
}

/// The mesh a mesh kernel is built on.
fn mesh<const D: usize>(scene: &Scene, setup: &Setup<D>) -> Result<Arc<SimplexMesh<D>>> {
    setup.background.mesh().cloned().ok_or_else(|| {
        scene.value_error(
            "kernel.kind",
            "a mesh kernel needs the mesh (none was built)",
        )
    })
}

/// The UMLS kernel of `kind` on the scene's mesh, as type `U`.
fn umls<const D: usize, U: FromMls<D>>(
    scene: &Scene,
    setup: &Setup<D>,
    kind: KernelKind,
) -> Result<U> {
    let mesh = mesh(scene, setup)?;
    let mls = umls_settings(scene, kind, &mesh)?;
    corrected(scene, kind, U::from_mls(mesh, mls))
}

/// The UMLS presets with the linear basis.
pub type LinearUmls<const D: usize, const N: usize> = UmlsMeshKernel<D, N, Linear, Profile>;
/// `umls-quadratic`.
pub type QuadraticUmls<const D: usize, const N: usize> = UmlsMeshKernel<D, N, Quadratic, Profile>;

impl<const D: usize, const N: usize, B> KernelFactory<D>
    for Preset<UmlsMeshKernel<D, N, B, Profile>>
where
    B: umls_mls::PolynomialBasis<D, N>,
    UmlsMeshKernel<D, N, B, Profile>: Kernel<D>,
{
    type Kernel = UmlsMeshKernel<D, N, B, Profile>;
    fn name(&self) -> String {
        self.kind.name().to_string()
    }
    fn on_mesh(&self) -> bool {
        true
    }
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel> {
        umls(scene, setup, self.kind)
    }
}

impl<const D: usize> KernelFactory<D> for Preset<LinearFeKernel<D>>
where
    LinearFeKernel<D>: Kernel<D>,
{
    type Kernel = LinearFeKernel<D>;
    fn name(&self) -> String {
        self.kind.name().to_string()
    }
    fn on_mesh(&self) -> bool {
        true
    }
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel> {
        Ok(LinearFeKernel::new(mesh(scene, setup)?))
    }
}

impl<const D: usize> KernelFactory<D> for Preset<UgimpKernel<D>> {
    type Kernel = UgimpKernel<D>;
    fn name(&self) -> String {
        self.kind.name().to_string()
    }
    fn on_mesh(&self) -> bool {
        false
    }
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel> {
        ugimp(scene, setup)
    }
}

impl<const D: usize> KernelFactory<D> for Preset<BSplineKernel<D>> {
    type Kernel = BSplineKernel<D>;
    fn name(&self) -> String {
        self.kind.name().to_string()
    }
    fn on_mesh(&self) -> bool {
        false
    }
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel> {
        let order = if self.kind == KernelKind::Bspline3 {
            BSplineOrder::Cubic
        } else {
            BSplineOrder::Quadratic
        };
        bspline(scene, setup, order)
    }
}

/// A UMLS kernel type built from a mesh, MLS settings and the gradient kind: what
/// differs per dimension is only the basis size, the construction is the same for all.
pub trait FromMls<const D: usize>: Sized {
    /// The kernel on `mesh` with these MLS settings and gradient.
    fn from_mls(
        mesh: Arc<SimplexMesh<D>>,
        settings: (UmlsKernel<D, Profile>, GradientKind),
    ) -> Self;

    /// The kernel with its force's integration correction.
    fn with_integration_correction(self) -> std::result::Result<Self, umls_transfer::KernelError>;
}

impl<const D: usize, const N: usize, B: umls_mls::PolynomialBasis<D, N>> FromMls<D>
    for UmlsMeshKernel<D, N, B, Profile>
{
    fn from_mls(
        mesh: Arc<SimplexMesh<D>>,
        (mls, gradient): (UmlsKernel<D, Profile>, GradientKind),
    ) -> Self {
        Self::with_kernel(mesh, mls).with_gradient(gradient)
    }

    fn with_integration_correction(self) -> std::result::Result<Self, umls_transfer::KernelError> {
        UmlsMeshKernel::with_integration_correction(self)
    }
}

/// The UMLS kernel with its force's integration correction where `[kernel]
/// integration_correction` (or the kernel name's preset, [`umls_preset`]) asks for it.
fn corrected<const D: usize, K: FromMls<D>>(
    scene: &Scene,
    kind: KernelKind,
    kernel: K,
) -> Result<K> {
    let spec = &scene.spec.kernel;
    if !spec
        .integration_correction
        .unwrap_or(umls_preset(kind).corrected)
    {
        return Ok(kernel);
    }
    kernel
        .with_integration_correction()
        .map_err(|e| scene.value_error("kernel.integration_correction", e.to_string()))
}

/// The MLS settings of a UMLS kernel and its gradient kind: the kernel name's preset
/// (profile, radius rule, factor, gradient, exponent of η), with `[kernel]`'s `weight`,
/// `support`, `support_factor`, `gradient` and `diminishing_exponent` overriding it. The
/// quadratic basis needs six (2D) or ten (3D) weighted samples, more than a vertex on a
/// wall or in a corner has, so its quadratic terms carry a small ridge.
fn umls_settings<const D: usize>(
    scene: &Scene,
    kind: KernelKind,
    mesh: &SimplexMesh<D>,
) -> Result<(UmlsKernel<D, Profile>, GradientKind)> {
    let spec = &scene.spec.kernel;
    let preset = umls_preset(kind);
    let weight = match spec.weight.unwrap_or(preset.weight) {
        WeightSpec::CubicBspline => Profile::CubicBSpline,
        WeightSpec::Wendland => Profile::WendlandC2,
        WeightSpec::Sharpened => Profile::Sharpened(
            SharpenedBSpline::new(spec.sharpening.unwrap_or(DEFAULT_SHARPENING))
                .map_err(|e| scene.value_error("kernel.sharpening", e.to_string()))?,
        ),
    };
    let factor = spec.support_factor.unwrap_or(preset.factor);
    let support = match spec.support.unwrap_or(preset.support) {
        SupportSpec::PerVertex => SupportRadius::PerVertex { factor },
        SupportSpec::IncidentEdge => SupportRadius::IncidentEdge { factor },
        SupportSpec::ElementSize => SupportRadius::ElementSize { factor },
        SupportSpec::Global => SupportRadius::Global { factor },
    };
    let mut mls = UmlsKernel::with_weight(mesh, weight, support)
        .map_err(|e| scene.value_error("kernel.support_factor", e.to_string()))?
        .with_diminishing_exponent(spec.diminishing_exponent.unwrap_or(preset.exponent))
        .map_err(|e| scene.value_error("kernel.diminishing_exponent", e.to_string()))?;
    if kind == KernelKind::UmlsQuadratic {
        mls.conditioning.higher_order_ridge = QUADRATIC_RIDGE;
    }
    Ok((mls, spec.gradient.unwrap_or(preset.gradient).kind()))
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

/// Relative ridge on the quadratic monomials of `umls-quadratic`.
const QUADRATIC_RIDGE: f64 = 1e-3;

/// What a UMLS kernel name stands for; `[kernel]`'s keys override each part.
struct UmlsPreset {
    weight: WeightSpec,
    support: SupportSpec,
    factor: f64,
    gradient: GradientSpec,
    /// p of the weights η^p · d.
    exponent: u32,
    /// Whether the force's gradients carry the integration correction ([`corrected`]).
    corrected: bool,
}

/// Profile, radius rule, factor, gradient, exponent of η and integration correction of
/// each UMLS kernel name. `umls-eta4`, `umls-eta8` and `umls-element-size` change one
/// part of `umls`; the other names change one part of `umls-uncorrected`, the kernel
/// their studies measured against.
fn umls_preset(kind: KernelKind) -> UmlsPreset {
    let umls = UmlsPreset {
        weight: WeightSpec::CubicBspline,
        support: SupportSpec::IncidentEdge,
        factor: DEFAULT_SUPPORT_FACTOR,
        gradient: GradientSpec::Reconstructed,
        exponent: 1,
        corrected: true,
    };
    let uncorrected = UmlsPreset {
        corrected: false,
        ..umls
    };
    match kind {
        KernelKind::Umls => umls,
        KernelKind::UmlsWide => UmlsPreset {
            support: SupportSpec::PerVertex,
            factor: 1.0,
            ..uncorrected
        },
        KernelKind::UmlsPaper => UmlsPreset {
            support: SupportSpec::Global,
            factor: 1.0,
            ..uncorrected
        },
        KernelKind::UmlsWendland => UmlsPreset {
            weight: WeightSpec::Wendland,
            ..uncorrected
        },
        KernelKind::UmlsSharp => UmlsPreset {
            weight: WeightSpec::Sharpened,
            ..uncorrected
        },
        KernelKind::UmlsFullGradient => UmlsPreset {
            gradient: GradientSpec::Full,
            ..uncorrected
        },
        KernelKind::UmlsFrozenEta => UmlsPreset {
            gradient: GradientSpec::FrozenEta,
            ..uncorrected
        },
        KernelKind::UmlsEta4 => UmlsPreset {
            factor: ETA4_SUPPORT_FACTOR,
            exponent: ETA4_EXPONENT,
            ..umls
        },
        KernelKind::UmlsEta8 => UmlsPreset {
            factor: ETA8_SUPPORT_FACTOR,
            exponent: ETA8_EXPONENT,
            ..umls
        },
        KernelKind::UmlsElementSize => UmlsPreset {
            support: SupportSpec::ElementSize,
            factor: ELEMENT_SIZE_SUPPORT_FACTOR,
            ..umls
        },
        _ => uncorrected,
    }
}

/// Most nodes a grid may have (a typo in the spacing should be an error).
const MAX_GRID_NODES: f64 = 1e8;

/// The grid spacing of a grid kernel: `[kernel] grid_spacing`, else the lattice's cell
/// size, else the mesh's longest edge / √D.
fn grid_spacing<const D: usize>(scene: &Scene, setup: &Setup<D>) -> Result<f64> {
    let h = scene
        .spec
        .kernel
        .grid_spacing
        .or(setup.lattice_spacing)
        .or_else(|| {
            setup
                .background
                .mesh()
                .map(|mesh| mesh.max_edge_length() / (D as f64).sqrt())
        })
        .unwrap_or(f64::NAN);
    if !(h.is_finite() && h > 0.0) {
        return Err(scene.value_error("kernel.grid_spacing", "must be positive"));
    }
    Ok(h)
}

/// Refuses a grid of more than [`MAX_GRID_NODES`] nodes.
fn check_grid_size(scene: &Scene, h: f64, cells: &[usize]) -> Result<()> {
    let nodes: f64 = cells.iter().map(|&n| n as f64 + 1.0).product();
    if nodes > MAX_GRID_NODES {
        return Err(scene.value_error(
            "kernel.grid_spacing",
            format!("{h} gives a grid of {nodes:.3e} nodes (limit {MAX_GRID_NODES:.0e})"),
        ));
    }
    Ok(())
}

/// A B-spline grid covering the mesh's bounding box with two cells of margin (the
/// widest, cubic, stencil needs one).
fn bspline<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    order: BSplineOrder,
) -> Result<BSplineKernel<D>> {
    let h = grid_spacing(scene, setup)?;
    let (lower, upper) = setup.background.bounding_box();
    let kernel = BSplineKernel::covering(lower, upper, h, order).ok_or_else(|| {
        scene.value_error(
            "kernel.grid_spacing",
            "too coarse for one B-spline stencil, or so fine that the grid has more than 2^32 nodes",
        )
    })?;
    check_grid_size(scene, h, &kernel.cells())?;
    Ok(kernel)
}

/// The uGIMP grid covering the background as the B-spline grids do, for particle boxes
/// of half the particles' initial spacing: l = V̄^(1/D) / 2 with V̄ the mean initial
/// particle volume (uGIMP keeps one box size; a scene whose bodies are seeded at
/// different spacings gets their mean).
fn ugimp<const D: usize>(scene: &Scene, setup: &Setup<D>) -> Result<UgimpKernel<D>> {
    let h = grid_spacing(scene, setup)?;
    let volumes = &setup.seeds.volume;
    let mean = volumes.iter().sum::<f64>() / volumes.len().max(1) as f64;
    let half_width = 0.5 * mean.powf(1.0 / D as f64);
    let (lower, upper) = setup.background.bounding_box();
    let kernel = UgimpKernel::covering(lower, upper, h, half_width).map_err(|e| {
        let key = match e {
            UgimpError::HalfWidth { .. } => "bodies.seeding",
            _ => "kernel.grid_spacing",
        };
        scene.value_error(key, format!("ugimp: {e}"))
    })?;
    check_grid_size(scene, h, &kernel.cells())?;
    Ok(kernel)
}
