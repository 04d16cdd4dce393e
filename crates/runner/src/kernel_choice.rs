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

use umls_kernels::presets::{Preset, PresetFamily, UmlsPreset};
use umls_kernels::{BSplineKernel, BSplineOrder, LinearFeKernel, UmlsMeshKernel};
use umls_mesh::SimplexMesh;
use umls_mls::{
    DEFAULT_SHARPENING, MlsError, Profile, SharpenedBSpline, SupportRadius, UmlsKernel,
};
use umls_transfer::Kernel;
use umls_ugimp::{UgimpError, UgimpKernel};

use crate::error::Result;
use crate::scene::Scene;
use crate::schema::{KernelKind, SupportSpec, WeightSpec};
use crate::setup::Setup;

/// Builds a kernel for a scene's set-up: the door through which a kernel type enters
/// the runner. The built-in presets implement it ([`Preset`]), and so does any kernel
/// of a researcher's own; [`crate::run_with`] runs a scene with it.
pub trait KernelFactory<const D: usize> {
    /// The kernel type the runs step with.
    type Kernel: Kernel<D> + 'static;

    /// The kernel's name in the summary, the history's plot titles and the report.
    fn name(&self) -> String;

    /// Whether the kernel's nodes are the mesh's vertices. A mesh kernel needs the
    /// lattice split into simplices and writes its nodal fields onto `mesh.vtu`; a grid
    /// kernel (false) writes `grid.vtu`, and walls given as mesh groups reach it as
    /// signed-distance colliders.
    fn on_mesh(&self) -> bool;

    /// The kernel over the scene's background (`setup.background`: a mesh, or the box
    /// of a lattice that a grid kernel does not split); errors name the scene key.
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel>;

    /// What the user should hear about running this kernel on `setup` (a set-up the
    /// kernel is known to handle badly); the run's summary and plan repeat them. None by
    /// default.
    fn warnings(&self, setup: &Setup<D>) -> Vec<String> {
        let _ = setup;
        Vec::new()
    }
}

/// A built-in kernel of `[kernel] kind`, with the UMLS kernel type of its dimension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuiltIn<U> {
    kind: KernelKind,
    umls: std::marker::PhantomData<U>,
}

impl<U> BuiltIn<U> {
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

impl<const D: usize, const N: usize, B> KernelFactory<D>
    for BuiltIn<UmlsMeshKernel<D, N, B, Profile>>
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
        let mesh = mesh(scene, setup)?;
        let settings = umls_settings(scene, self.kind)?;
        let mls = mls_kernel(scene, &settings, &mesh)?;
        settings
            .mesh_kernel(mesh, mls)
            .map_err(|e| scene.value_error("kernel.integration_correction", e.to_string()))
    }
}

impl<const D: usize> KernelFactory<D> for BuiltIn<LinearFeKernel<D>>
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
    fn warnings(&self, setup: &Setup<D>) -> Vec<String> {
        one_particle_per_cell(setup).into_iter().collect()
    }
}

/// Below this many particles per simplex, linear elements are warned about.
const FEW_PARTICLES_PER_CELL: f64 = 1.5;

/// The warning for linear elements with about one particle per simplex: the particles
/// are the elements' only quadrature points, so once they move, some simplices hold none
/// (their nodes lose stiffness) and each crossing kicks the nodes it leaves; the energy
/// can grow with nothing stopping the run. Particles per simplex are the mesh's mean
/// simplex volume over the particles' mean volume.
fn one_particle_per_cell<const D: usize>(setup: &Setup<D>) -> Option<String> {
    let mesh = setup.background.mesh()?;
    let volumes = &setup.seeds.volume;
    if volumes.is_empty() || mesh.simplex_count() == 0 {
        return None;
    }
    let particle = volumes.iter().sum::<f64>() / volumes.len() as f64;
    let cell = mesh.total_volume() / mesh.simplex_count() as f64;
    let per_cell = cell / particle;
    (per_cell < FEW_PARTICLES_PER_CELL).then(|| {
        format!(
            "linear-fe with {per_cell:.2} particles per simplex: simplices that particles \
             leave have no stiffness and each crossing kicks their nodes, so the energy may \
             grow; seed two or more per simplex (e.g. `seeding = {{ mesh = \"gauss2\" }}`)"
        )
    })
}

impl<const D: usize> KernelFactory<D> for BuiltIn<UgimpKernel<D>> {
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

impl<const D: usize> KernelFactory<D> for BuiltIn<BSplineKernel<D>> {
    type Kernel = BSplineKernel<D>;
    fn name(&self) -> String {
        self.kind.name().to_string()
    }
    fn on_mesh(&self) -> bool {
        false
    }
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Self::Kernel> {
        let order = match self.kind.preset().map(Preset::family) {
            Some(PresetFamily::BSpline(order)) => order,
            _ => return Err(scene.value_error("kernel.kind", "is not a B-spline kernel")),
        };
        bspline(scene, setup, order)
    }
}

/// The settings of the UMLS preset `kind` (`umls_kernels::presets`) with `[kernel]`'s
/// `weight`, `sharpening`, `support`, `support_factor`, `gradient`,
/// `diminishing_exponent` and `integration_correction` overriding them.
fn umls_settings(scene: &Scene, kind: KernelKind) -> Result<UmlsPreset> {
    let spec = &scene.spec.kernel;
    let mut settings = match kind.preset().map(Preset::family) {
        Some(PresetFamily::Umls(s) | PresetFamily::UmlsQuadratic(s)) => s,
        _ => return Err(scene.value_error("kernel.kind", "is not a UMLS kernel")),
    };
    let sharpened = |epsilon: f64| {
        SharpenedBSpline::new(epsilon)
            .map(Profile::Sharpened)
            .map_err(|e| scene.value_error("kernel.sharpening", e.to_string()))
    };
    settings.profile = match (spec.weight, settings.profile) {
        (Some(WeightSpec::CubicBspline), _) => Profile::CubicBSpline,
        (Some(WeightSpec::Wendland), _) => Profile::WendlandC2,
        (Some(WeightSpec::Sharpened), _) => {
            sharpened(spec.sharpening.unwrap_or(DEFAULT_SHARPENING))?
        }
        (None, Profile::Sharpened(_)) if spec.sharpening.is_some() => {
            sharpened(spec.sharpening.unwrap_or(DEFAULT_SHARPENING))?
        }
        (None, profile) => profile,
    };
    let (rule, factor) = match settings.support {
        SupportRadius::PerVertex { factor } => (SupportSpec::PerVertex, factor),
        SupportRadius::IncidentEdge { factor } => (SupportSpec::IncidentEdge, factor),
        SupportRadius::ElementSize { factor } => (SupportSpec::ElementSize, factor),
        SupportRadius::Global { factor } => (SupportSpec::Global, factor),
    };
    let factor = spec.support_factor.unwrap_or(factor);
    settings.support = match spec.support.unwrap_or(rule) {
        SupportSpec::PerVertex => SupportRadius::PerVertex { factor },
        SupportSpec::IncidentEdge => SupportRadius::IncidentEdge { factor },
        SupportSpec::ElementSize => SupportRadius::ElementSize { factor },
        SupportSpec::Global => SupportRadius::Global { factor },
    };
    if let Some(gradient) = spec.gradient {
        settings.gradient = gradient.kind();
    }
    if let Some(p) = spec.diminishing_exponent {
        settings.diminishing_exponent = p;
    }
    if let Some(corrected) = spec.integration_correction {
        settings.integration_correction = corrected;
    }
    Ok(settings)
}

/// The MLS kernel of `settings` on `mesh`; an error names the scene key it comes from.
fn mls_kernel<const D: usize>(
    scene: &Scene,
    settings: &UmlsPreset,
    mesh: &SimplexMesh<D>,
) -> Result<UmlsKernel<D, Profile>> {
    settings.mls_kernel(mesh).map_err(|e| {
        let key = match e {
            MlsError::InvalidParameter {
                parameter: "diminishing exponent",
                ..
            } => "kernel.diminishing_exponent",
            _ => "kernel.support_factor",
        };
        scene.value_error(key, e.to_string())
    })
}

/// Most nodes a grid may have (a typo in the spacing should be an error).
const MAX_GRID_NODES: f64 = 1e8;

/// The grid spacing of a grid kernel: `[kernel] grid_spacing`, else the lattice's cell
/// size, else the mesh's mean element size (`SimplexMesh::mean_element_size`, the cell
/// size of a lattice however it is split or jittered; the longest edge grew with the
/// jitter and coarsened the grid with it).
fn grid_spacing<const D: usize>(scene: &Scene, setup: &Setup<D>) -> Result<f64> {
    let h = scene
        .spec
        .kernel
        .grid_spacing
        .or(setup.lattice_spacing)
        .or_else(|| setup.background.mesh().map(|mesh| mesh.mean_element_size()))
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
