//! `umls run`: build the scene for its dimension, pick the kernel, material table and
//! transfer types, step to the end time and write the output.
//!
//! Each (dimension, kernel, transfer, plasticity) combination is its own monomorphized
//! simulation, so a run steps with exactly the code its scene needs. The run loop around
//! it (time step, boundaries, output, history, summary) sees the simulation through the
//! object-safe `Run` trait and is compiled once per dimension.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use nalgebra::{SMatrix, SVector};
use serde_json::json;
use umls_engine::{
    Apic, ApicFlip, Boundary, Diagnostics, EngineError, FaceClamp, Flip, MlsMpm, Particles,
    QuadraticApicFlip, Simulation, StageTimes, StepSettings, TimeStepControl, TransferScheme,
    VelocityGradientAffine, Wall,
};
use umls_io::csv::HistoryWriter;
use umls_io::vtk::Encoding;
use umls_kernels::{BSplineKernel, BSplineOrder, GradientKind, LinearFeKernel, UmlsMeshKernel};
use umls_mesh::SimplexMesh;
use umls_mls::{
    DEFAULT_SHARPENING, DEFAULT_SUPPORT_FACTOR, Linear, Profile, Quadratic, SharpenedBSpline,
    SupportRadius, UmlsKernel,
};
use umls_transfer::Kernel;

use crate::error::{CliError, Result};
use crate::output::OutputDir;
use crate::plot::EnergyRecord;
use crate::pressure::WallPressure;
use crate::probes::Probes;
use crate::progress::Progress;
use crate::reference;
use crate::scene::Scene;
use crate::schema::{
    EncodingSpec, ForcePosition, GradientSpec, KernelKind, SupportSpec, TransferKind, WeightSpec,
};
use crate::setup::{self, Setup, Split};
use crate::{conditions, end_metrics};
use umls_constitutive::Constitutive;
use umls_constitutive::table::{
    MaterialTable, Model, NoPlasticity, PlasticModel, PlasticPart, TableState,
};

/// Command-line overrides and output settings of a run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Kernel instead of the scene's.
    pub kernel: Option<KernelKind>,
    /// Output directory.
    pub out: PathBuf,
    /// End time instead of the scene's.
    pub end_time: Option<f64>,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Show a progress bar.
    pub progress: bool,
    /// Set (by a Ctrl-C handler) to stop the run after the current step; the output up to
    /// then is written and the summary says "interrupted".
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// What a finished run reports.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// The contents of `summary.json`.
    pub summary: serde_json::Value,
    /// Where the files are.
    pub out: PathBuf,
}

/// What differs between dimensions: the UMLS kernel type, the lattice split, and
/// whether plastic models exist.
trait Dimension<const D: usize> {
    type Umls: Kernel<D> + FromMls<D>;
    type UmlsQuadratic: Kernel<D> + FromMls<D>;
    const SPLIT: Split<D>;
    fn run_plastic<K: Kernel<D>>(ctx: &Context<'_, D>, kernel: K) -> Result<RunReport>;
}

struct D1;
struct D2;
struct D3;

impl Dimension<1> for D1 {
    type Umls = UmlsMeshKernel<1, 2, Linear, Profile>;
    type UmlsQuadratic = UmlsMeshKernel<1, 3, Quadratic, Profile>;
    const SPLIT: Split<1> = setup::segments;
    fn run_plastic<K: Kernel<1>>(ctx: &Context<'_, 1>, _: K) -> Result<RunReport> {
        Err(setup::plastic_in_1d(ctx.scene))
    }
}

impl Dimension<2> for D2 {
    type Umls = UmlsMeshKernel<2, 3, Linear, Profile>;
    type UmlsQuadratic = UmlsMeshKernel<2, 6, Quadratic, Profile>;
    const SPLIT: Split<2> = setup::triangles;
    fn run_plastic<K: Kernel<2>>(ctx: &Context<'_, 2>, kernel: K) -> Result<RunReport> {
        with_material(
            ctx,
            kernel,
            MaterialTable::<PlasticModel> {
                models: ctx.setup.models.clone(),
            },
        )
    }
}

impl Dimension<3> for D3 {
    type Umls = UmlsMeshKernel<3, 4, Linear, Profile>;
    type UmlsQuadratic = UmlsMeshKernel<3, 10, Quadratic, Profile>;
    const SPLIT: Split<3> = setup::tetrahedra;
    fn run_plastic<K: Kernel<3>>(ctx: &Context<'_, 3>, kernel: K) -> Result<RunReport> {
        with_material(
            ctx,
            kernel,
            MaterialTable::<PlasticModel> {
                models: ctx.setup.models.clone(),
            },
        )
    }
}

/// A UMLS kernel type built from a mesh, MLS settings and the gradient kind: what
/// `Dimension` names per dimension is only the basis size, the construction is the same
/// for all.
trait FromMls<const D: usize> {
    fn from_mls(
        mesh: Arc<SimplexMesh<D>>,
        settings: (UmlsKernel<D, Profile>, GradientKind),
    ) -> Self;

    /// The kernel with its force's integration correction.
    fn with_integration_correction(self) -> std::result::Result<Self, umls_transfer::KernelError>
    where
        Self: Sized;
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

/// Everything the typed part of a run reads.
pub(crate) struct Context<'a, const D: usize> {
    pub(crate) scene: &'a Scene,
    pub(crate) setup: Setup<D>,
    pub(crate) options: &'a RunOptions,
    pub(crate) kernel: KernelKind,
    pub(crate) end_time: f64,
    pub(crate) encoding: Encoding,
}

/// Runs `scene` with `options`.
pub fn run(scene: &Scene, options: &RunOptions) -> Result<RunReport> {
    setup::check_header(scene)?;
    if let Some(t) = options.end_time {
        if !(t.is_finite() && t > 0.0) {
            return Err(scene.value_error("--end-time", "must be finite and positive"));
        }
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = options.threads {
        if n == 0 {
            return Err(scene.value_error("--threads", "must be at least 1"));
        }
        // Each thread is an OS thread with its own stack; far more threads than cores only
        // costs time (100000 made a 50-step run never finish).
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let limit = (16 * cores).max(64);
        if n > limit {
            return Err(scene.value_error(
                "--threads",
                format!("{n} is more than {limit} (16 per core on this machine, at least 64)"),
            ));
        }
        pool = pool.num_threads(n);
    }
    let pool = pool
        .build()
        .map_err(|e| scene.value_error("--threads", e.to_string()))?;
    pool.install(|| match scene.spec.scene.dimension {
        1 => run_dim::<1, D1>(scene, options),
        2 => run_dim::<2, D2>(scene, options),
        _ => run_dim::<3, D3>(scene, options),
    })
}

fn run_dim<const D: usize, X: Dimension<D>>(
    scene: &Scene,
    options: &RunOptions,
) -> Result<RunReport> {
    let kernel = options.kernel.unwrap_or(scene.spec.kernel.kind);
    let grid_kernel = matches!(kernel, KernelKind::Bspline2 | KernelKind::Bspline3);
    let setup = setup::build_for::<D>(scene, X::SPLIT, grid_kernel)?;
    let encoding = match scene.spec.output.encoding {
        EncodingSpec::Binary => Encoding::Binary,
        EncodingSpec::Ascii => Encoding::Ascii,
    };
    let ctx = Context {
        scene,
        kernel,
        end_time: options.end_time.unwrap_or(scene.spec.scene.end_time),
        setup,
        options,
        encoding,
    };
    let mesh = || {
        ctx.setup.background.mesh().cloned().ok_or_else(|| {
            scene.value_error(
                "kernel.kind",
                "a mesh kernel needs the mesh (none was built)",
            )
        })
    };
    match ctx.kernel {
        KernelKind::Umls
        | KernelKind::UmlsWendland
        | KernelKind::UmlsSharp
        | KernelKind::UmlsWide
        | KernelKind::UmlsPaper
        | KernelKind::UmlsFullGradient
        | KernelKind::UmlsFrozenEta
        | KernelKind::UmlsUncorrected
        | KernelKind::UmlsEta4
        | KernelKind::UmlsEta8
        | KernelKind::UmlsElementSize => {
            let mesh = mesh()?;
            let mls = umls_settings(&ctx, &mesh)?;
            let kernel = corrected(&ctx, X::Umls::from_mls(mesh, mls))?;
            with_kernel::<D, X, _>(&ctx, kernel)
        }
        KernelKind::UmlsQuadratic => {
            let mesh = mesh()?;
            let mls = umls_settings(&ctx, &mesh)?;
            let kernel = corrected(&ctx, X::UmlsQuadratic::from_mls(mesh, mls))?;
            with_kernel::<D, X, _>(&ctx, kernel)
        }
        KernelKind::LinearFe => with_kernel::<D, X, _>(&ctx, LinearFeKernel::new(mesh()?)),
        KernelKind::Bspline2 => {
            with_kernel::<D, X, _>(&ctx, bspline(&ctx, BSplineOrder::Quadratic)?)
        }
        KernelKind::Bspline3 => with_kernel::<D, X, _>(&ctx, bspline(&ctx, BSplineOrder::Cubic)?),
    }
}

/// The UMLS kernel with its force's integration correction where `[kernel]
/// integration_correction` (or the kernel name's preset, [`umls_preset`]) asks for it.
fn corrected<const D: usize, K: FromMls<D>>(ctx: &Context<'_, D>, kernel: K) -> Result<K> {
    let spec = &ctx.scene.spec.kernel;
    if !spec
        .integration_correction
        .unwrap_or(umls_preset(ctx.kernel).corrected)
    {
        return Ok(kernel);
    }
    kernel.with_integration_correction().map_err(|e| {
        ctx.scene
            .value_error("kernel.integration_correction", e.to_string())
    })
}

/// The MLS settings of a UMLS kernel and its gradient kind: the kernel name's preset
/// (profile, radius rule, factor, gradient, exponent of η), with `[kernel]`'s `weight`,
/// `support`, `support_factor`, `gradient` and `diminishing_exponent` overriding it. The
/// quadratic basis needs six (2D) or ten (3D) weighted samples, more than a vertex on a
/// wall or in a corner has, so its quadratic terms carry a small ridge.
fn umls_settings<const D: usize>(
    ctx: &Context<'_, D>,
    mesh: &SimplexMesh<D>,
) -> Result<(UmlsKernel<D, Profile>, GradientKind)> {
    let spec = &ctx.scene.spec.kernel;
    let preset = umls_preset(ctx.kernel);
    let weight = match spec.weight.unwrap_or(preset.weight) {
        WeightSpec::CubicBspline => Profile::CubicBSpline,
        WeightSpec::Wendland => Profile::WendlandC2,
        WeightSpec::Sharpened => Profile::Sharpened(
            SharpenedBSpline::new(spec.sharpening.unwrap_or(DEFAULT_SHARPENING))
                .map_err(|e| ctx.scene.value_error("kernel.sharpening", e.to_string()))?,
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
        .map_err(|e| {
            ctx.scene
                .value_error("kernel.support_factor", e.to_string())
        })?
        .with_diminishing_exponent(spec.diminishing_exponent.unwrap_or(preset.exponent))
        .map_err(|e| {
            ctx.scene
                .value_error("kernel.diminishing_exponent", e.to_string())
        })?;
    if ctx.kernel == KernelKind::UmlsQuadratic {
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

/// Most nodes a B-spline grid may have (a typo in the spacing should be an error).
const MAX_GRID_NODES: f64 = 1e8;

/// A B-spline grid covering the mesh's bounding box with two cells of margin (the
/// widest, cubic, stencil needs one).
fn bspline<const D: usize>(ctx: &Context<'_, D>, order: BSplineOrder) -> Result<BSplineKernel<D>> {
    let background = &ctx.setup.background;
    let h = ctx
        .scene
        .spec
        .kernel
        .grid_spacing
        .or(ctx.setup.lattice_spacing)
        .or_else(|| {
            background
                .mesh()
                .map(|mesh| mesh.max_edge_length() / (D as f64).sqrt())
        })
        .unwrap_or(f64::NAN);
    if !(h.is_finite() && h > 0.0) {
        return Err(ctx
            .scene
            .value_error("kernel.grid_spacing", "must be positive"));
    }
    let (lower, upper) = background.bounding_box();
    let kernel = BSplineKernel::covering(lower, upper, h, order).ok_or_else(|| {
        ctx.scene
            .value_error(
                "kernel.grid_spacing",
                "too coarse for one B-spline stencil, or so fine that the grid has more than 2^32 nodes",
            )
    })?;
    let nodes: f64 = kernel.cells().iter().map(|&n| n as f64 + 1.0).product();
    if nodes > MAX_GRID_NODES {
        return Err(ctx.scene.value_error(
            "kernel.grid_spacing",
            format!("{h} gives a grid of {nodes:.3e} nodes (limit {MAX_GRID_NODES:.0e})"),
        ));
    }
    Ok(kernel)
}

fn with_kernel<const D: usize, X: Dimension<D>, K: Kernel<D>>(
    ctx: &Context<'_, D>,
    kernel: K,
) -> Result<RunReport> {
    if ctx.setup.has_plasticity() {
        return X::run_plastic(ctx, kernel);
    }
    let models = ctx
        .setup
        .models
        .iter()
        .filter_map(|m| match m {
            Model::Elastic(e) => Some(Model::<NoPlasticity>::Elastic(e.clone())),
            Model::Plastic(_) => None,
        })
        .collect();
    with_material(ctx, kernel, MaterialTable::<NoPlasticity> { models })
}

fn with_material<const D: usize, K: Kernel<D>, P: PlasticPart<D>>(
    ctx: &Context<'_, D>,
    kernel: K,
    table: MaterialTable<P>,
) -> Result<RunReport> {
    // Five transfer types for the eight kinds keep down the simulations this crate
    // compiles: PIC is FLIP with α = 0 (v = 0·(v + Δv) + 1·v_PIC, the same numbers), the
    // two affine schemes share one type, and quadratic APIC is its FLIP blend at α = 0
    // (the same bits, tested in the engine). APIC-FLIP has its own type, so that APIC
    // does not read the old grid velocities it has no use for; MLS-MPM has its own, as
    // its force is folded into the momentum.
    let t = &ctx.scene.spec.transfer;
    if !(0.0..=1.0).contains(&t.alpha) {
        return Err(ctx
            .scene
            .value_error("transfer.alpha", format!("{} is not in [0, 1]", t.alpha)));
    }
    match t.kind {
        TransferKind::Pic => start(ctx, kernel, table, Flip { alpha: 0.0 }),
        TransferKind::Flip => start(ctx, kernel, table, Flip { alpha: t.alpha }),
        TransferKind::ApicFlip => start(ctx, kernel, table, ApicFlip { alpha: t.alpha }),
        TransferKind::Apic => start(ctx, kernel, table, AffineTransfer::Apic),
        TransferKind::QuadraticApic => start(ctx, kernel, table, QuadraticApicFlip { alpha: 0.0 }),
        TransferKind::QuadraticApicFlip => {
            start(ctx, kernel, table, QuadraticApicFlip { alpha: t.alpha })
        }
        TransferKind::VelocityGradient => {
            start(ctx, kernel, table, AffineTransfer::VelocityGradient)
        }
        TransferKind::MlsMpm => {
            if !kernel.regular_second_moment() {
                return Err(ctx.scene.value_error(
                    "transfer.kind",
                    "mls-mpm takes D_p⁻¹ N_i (x_i − x_p) as the force's gradient, and linear \
                     elements' D_p vanishes at the vertices: it needs a B-spline or UMLS kernel",
                ));
            }
            start(ctx, kernel, table, MlsMpm)
        }
    }
}

/// APIC or the velocity-gradient affine transfer, chosen at run time. Both carry C_p; the
/// moments B_p and D_p are accumulated for both although only APIC reads them (a few
/// flops per node, against a second copy of every simulation type in the binary).
#[derive(Debug, Clone, Copy)]
enum AffineTransfer {
    Apic,
    VelocityGradient,
}

impl TransferScheme for AffineTransfer {
    const AFFINE: bool = true;
    const USES_MOMENTS: bool = true;

    fn name(&self) -> &'static str {
        match self {
            Self::Apic => Apic.name(),
            Self::VelocityGradient => VelocityGradientAffine.name(),
        }
    }

    fn affine<const D: usize>(
        &self,
        b: &nalgebra::SMatrix<f64, D, D>,
        d: &nalgebra::SMatrix<f64, D, D>,
        grad_v: &nalgebra::SMatrix<f64, D, D>,
    ) -> nalgebra::SMatrix<f64, D, D> {
        match self {
            Self::Apic => Apic.affine(b, d, grad_v),
            Self::VelocityGradient => VelocityGradientAffine.affine(b, d, grad_v),
        }
    }

    fn affine_with_constant_moment<const D: usize>(
        &self,
        b: &nalgebra::SMatrix<f64, D, D>,
        s: f64,
        grad_v: &nalgebra::SMatrix<f64, D, D>,
    ) -> nalgebra::SMatrix<f64, D, D> {
        // Each scheme's own closed form (APIC: B_p / s, no Cholesky factorisation).
        match self {
            Self::Apic => Apic.affine_with_constant_moment(b, s, grad_v),
            Self::VelocityGradient => {
                VelocityGradientAffine.affine_with_constant_moment(b, s, grad_v)
            }
        }
    }
}

/// The typed part of a run: particles of the table's state and the kernel's cache, and
/// the simulation, handed to the run loop as a [`Run`].
fn start<const D: usize, K: Kernel<D>, P: PlasticPart<D>, T: TransferScheme>(
    ctx: &Context<'_, D>,
    kernel: K,
    table: MaterialTable<P>,
    transfer: T,
) -> Result<RunReport> {
    let seeds = &ctx.setup.seeds;
    let mut particles = Particles::<D, TableState<P::State>, K::Cache>::at_rest(
        seeds.position.clone(),
        seeds.volume.clone(),
        1.0,
        TableState::default(),
    );
    particles.mass.clone_from(&seeds.mass);
    particles.velocity.clone_from(&seeds.velocity);
    particles.affine.clone_from(&seeds.affine);
    for (state, &m) in particles.state.iter_mut().zip(&seeds.material) {
        state.material = m;
    }
    let mut settings = StepSettings::new(1.0);
    settings.gravity = ctx.setup.gravity;
    settings.gravity_ramp = ctx.setup.gravity_ramp;
    settings.stress_update = ctx.setup.stress_update;
    settings.stencil_storage = ctx.scene.spec.kernel.stencils.storage();
    settings.particle_sort_interval = ctx.scene.spec.kernel.particle_sort_interval;
    settings.mass_matrix = crate::schema::MassSpec::matrix(ctx.scene.spec.transfer.mass);
    settings.damping = ctx.setup.damping;
    let mut sim = Simulation::new(kernel, table, transfer, particles, settings)?;
    if let Some((field, position)) = &ctx.setup.body_force {
        let (field, frame) = (field.clone(), ctx.setup.frame);
        // The seeds are where the particles start, in the particles' order.
        let reference: Option<Vec<SVector<f64, D>>> =
            (*position == ForcePosition::Reference).then(|| {
                seeds
                    .position
                    .iter()
                    .map(|x| frame.point_to_scene(x))
                    .collect()
            });
        // An evaluation error (none is expected: the field was evaluated at every
        // particle before the run) gives NaN, which the engine stops at.
        sim.body_force = Some(Arc::new(move |p: usize, x: &SVector<f64, D>, t: f64| {
            let at = match &reference {
                Some(start) => start[p],
                None => frame.point_to_scene(x),
            };
            field
                .eval(&at, t)
                .map(|b| frame.vector_to_world(&b))
                .unwrap_or_else(|_| SVector::from_element(f64::NAN))
        }));
    }
    drive(ctx, &mut sim)
}

/// What the run loop needs of a simulation. Object-safe, so [`drive`] is compiled once
/// per dimension; only [`Run::step`] and the output of particle fields are compiled for
/// each kernel, material table and transfer, which is where the time goes.
pub(crate) trait Run<const D: usize> {
    fn step(&mut self) -> std::result::Result<(), EngineError>;
    fn time(&self) -> f64;
    fn step_count(&self) -> usize;
    fn diagnostics(&self) -> std::result::Result<Diagnostics<D>, EngineError>;
    fn settings(&self) -> &StepSettings<D>;
    fn settings_mut(&mut self) -> &mut StepSettings<D>;
    fn stable_time_step(&self, cfl: f64) -> f64;
    fn set_geostatic_stress(&mut self, k0: f64) -> std::result::Result<(), EngineError>;
    fn spacing(&self) -> f64;
    /// Adds a wall; the nodes it constrains.
    fn add_wall(&mut self, wall: Wall<D>, tolerance: f64) -> Vec<u32>;
    /// Adds a clamp held on its face, the region's `nodes` and the face `points`, with
    /// the face points' residuals weighted by `penalty` (else the default); the nodes its
    /// constraint moves (or the face point the kernel cannot evaluate).
    fn add_face_clamp(
        &mut self,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
        penalty: Option<f64>,
    ) -> std::result::Result<Vec<u32>, EngineError>;
    /// The particles' reference volumes.
    fn volumes(&self) -> &[f64];
    /// The constraint forces of the boundary's reaction sets in the last step.
    fn reactions(&self) -> &[umls_engine::Reaction<D>];
    /// Each reaction-set node's reaction, the sets one after the other.
    fn node_reactions(&self) -> &[SVector<f64, D>];
    /// The node sets whose reactions are summed.
    fn reaction_sets(&mut self) -> Vec<Vec<u32>>;
    /// Each material state scalar's name and its largest value over the particles.
    fn state_scalar_maxima(&self) -> Vec<(&'static str, f64)>;
    fn boundary(&mut self) -> &mut Boundary<D>;
    fn positions(&self) -> &[SVector<f64, D>];
    fn velocities(&self) -> &[SVector<f64, D>];
    fn masses(&self) -> &[f64];
    /// The scene's index of the particle stored in `slot` (sorting moves particles).
    fn particle_id(&self, slot: usize) -> usize;
    /// How many times the particles have been sorted.
    fn particle_sorts(&self) -> usize;
    fn write_particles(&self, out: &mut OutputDir, reference: &[SVector<f64, D>]) -> Result<()>;
    fn grid(&self) -> (&[f64], &[SVector<f64, D>]);
    fn node_positions(&self) -> Vec<SVector<f64, D>>;
    fn node_count(&self) -> usize;
    fn last_dt(&self) -> f64;
    fn stage_times(&self) -> StageTimes;
    fn memory_use(&self) -> umls_engine::MemoryUse;
    /// Cauchy stresses σ = τ / det F.
    fn cauchy_stresses(&self) -> std::result::Result<Vec<SMatrix<f64, D, D>>, EngineError>;
}

impl<const D: usize, K: Kernel<D>, P: PlasticPart<D>, T: TransferScheme> Run<D>
    for Simulation<D, K, MaterialTable<P>, T>
{
    fn step(&mut self) -> std::result::Result<(), EngineError> {
        Simulation::step(self)
    }
    fn time(&self) -> f64 {
        Simulation::time(self)
    }
    fn step_count(&self) -> usize {
        Simulation::step_count(self)
    }
    fn diagnostics(&self) -> std::result::Result<Diagnostics<D>, EngineError> {
        Simulation::diagnostics(self)
    }
    fn settings(&self) -> &StepSettings<D> {
        &self.settings
    }
    fn settings_mut(&mut self) -> &mut StepSettings<D> {
        &mut self.settings
    }
    fn stable_time_step(&self, cfl: f64) -> f64 {
        Simulation::stable_time_step(self, cfl)
    }
    fn set_geostatic_stress(&mut self, k0: f64) -> std::result::Result<(), EngineError> {
        Simulation::set_geostatic_stress(self, k0)
    }
    fn spacing(&self) -> f64 {
        self.kernel.spacing()
    }
    fn reactions(&self) -> &[umls_engine::Reaction<D>] {
        Simulation::reactions(self)
    }
    fn node_reactions(&self) -> &[SVector<f64, D>] {
        Simulation::node_reactions(self)
    }
    fn reaction_sets(&mut self) -> Vec<Vec<u32>> {
        self.boundary.reaction_sets.clone()
    }
    fn state_scalar_maxima(&self) -> Vec<(&'static str, f64)> {
        let names = self.material().state_scalar_names();
        let mut maxima = vec![f64::NEG_INFINITY; names.len()];
        let mut values = Vec::with_capacity(names.len());
        for s in &self.particles().state {
            values.clear();
            self.material().state_scalars(s, &mut values);
            for (m, v) in maxima.iter_mut().zip(&values) {
                *m = m.max(*v);
            }
        }
        names.iter().copied().zip(maxima).collect()
    }
    fn add_wall(&mut self, wall: Wall<D>, tolerance: f64) -> Vec<u32> {
        self.boundary.add_wall(&self.kernel, wall, tolerance)
    }
    fn add_face_clamp(
        &mut self,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
        penalty: Option<f64>,
    ) -> std::result::Result<Vec<u32>, EngineError> {
        let mut clamp = FaceClamp::new(&self.kernel, nodes, points)?;
        if let Some(w) = penalty {
            clamp.penalty = w;
        }
        Ok(self.boundary.add_face_clamp(clamp))
    }
    fn volumes(&self) -> &[f64] {
        &self.particles().volume
    }
    fn boundary(&mut self) -> &mut Boundary<D> {
        &mut self.boundary
    }
    fn positions(&self) -> &[SVector<f64, D>] {
        &self.particles().position
    }
    fn velocities(&self) -> &[SVector<f64, D>] {
        &self.particles().velocity
    }
    fn masses(&self) -> &[f64] {
        &self.particles().mass
    }
    fn particle_id(&self, slot: usize) -> usize {
        Simulation::particle_id(self, slot)
    }
    fn particle_sorts(&self) -> usize {
        Simulation::particle_sorts(self)
    }
    fn write_particles(&self, out: &mut OutputDir, reference: &[SVector<f64, D>]) -> Result<()> {
        out.write_particles(self, reference)
    }
    fn grid(&self) -> (&[f64], &[SVector<f64, D>]) {
        Simulation::grid(self)
    }
    fn node_positions(&self) -> Vec<SVector<f64, D>> {
        (0..self.kernel.node_count())
            .map(|n| self.kernel.node_position(n))
            .collect()
    }
    fn node_count(&self) -> usize {
        self.kernel.node_count()
    }
    fn last_dt(&self) -> f64 {
        Simulation::last_dt(self)
    }
    fn stage_times(&self) -> StageTimes {
        *Simulation::stage_times(self)
    }
    fn memory_use(&self) -> umls_engine::MemoryUse {
        Simulation::memory_use(self)
    }
    fn cauchy_stresses(&self) -> std::result::Result<Vec<SMatrix<f64, D, D>>, EngineError> {
        let mut stresses = self.stresses()?;
        for (tau, f) in stresses.iter_mut().zip(&self.particles().deformation) {
            *tau /= umls_constitutive::determinant(f);
        }
        Ok(stresses)
    }
}

fn transfer_name(spec: &crate::schema::TransferSpec) -> String {
    let name = transfer_kind_name(spec);
    match spec.mass {
        None => name,
        Some(m) => format!(
            "{name}, consistent mass ({} iterations{})",
            m.iterations,
            match m.forces.share() {
                0.0 => String::new(),
                1.0 => ", forces too".into(),
                beta => format!(", forces with share {beta}"),
            }
        ),
    }
}

fn transfer_kind_name(spec: &crate::schema::TransferSpec) -> String {
    match spec.kind {
        TransferKind::Pic => "pic".into(),
        TransferKind::Flip => format!("flip (alpha {})", spec.alpha),
        TransferKind::ApicFlip => format!("apic-flip (alpha {})", spec.alpha),
        TransferKind::Apic => "apic".into(),
        TransferKind::QuadraticApic => "quadratic-apic".into(),
        TransferKind::QuadraticApicFlip => format!("quadratic-apic-flip (alpha {})", spec.alpha),
        TransferKind::VelocityGradient => "velocity-gradient".into(),
        TransferKind::MlsMpm => "mls-mpm".into(),
    }
}

/// Energy with the potential of gravity and body forces (minus their work since the
/// start), so that scenes under gravity conserve it too.
fn total_energy<const D: usize>(d: &Diagnostics<D>) -> (f64, f64) {
    (-d.external_work, d.energy_balance())
}

/// After a particle sort: the seeds' positions in the new storage order, and the probes'
/// particles where they are stored now.
fn follow_sorted<const D: usize>(
    sim: &dyn Run<D>,
    seeds: &[SVector<f64, D>],
    reference_positions: &mut [SVector<f64, D>],
    probes: &mut Probes,
) {
    let mut slot_of = vec![0; seeds.len()];
    for (slot, x) in reference_positions.iter_mut().enumerate() {
        let id = sim.particle_id(slot);
        *x = seeds[id];
        slot_of[id] = slot;
    }
    probes.follow(&slot_of);
}

/// The run loop: time step, boundaries, output, history, summary.
fn drive<const D: usize>(ctx: &Context<'_, D>, sim: &mut dyn Run<D>) -> Result<RunReport> {
    let (scene, setup, spec) = (ctx.scene, &ctx.setup, &ctx.scene.spec);
    let seeds = &setup.seeds;
    if let Some(k0) = setup.geostatic_k0 {
        sim.set_geostatic_stress(k0)?;
    }

    let mut warnings = setup.warnings.clone();
    let stable_dt = sim.stable_time_step(1.0);
    let (steps, dt_cap) = plan_time_step(ctx, sim, stable_dt, &mut warnings)?;
    let mesh_kernel = ctx.kernel.on_mesh();
    conditions::apply_boundaries(ctx, sim)?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }

    let mut out = OutputDir::create(&ctx.options.out, ctx.encoding)?;
    let mut probes = Probes::new(scene, &setup.frame, &seeds.position)?;
    // The measured wall: its nodes' positions, and where its reactions start among all
    // reaction-set nodes.
    let mut wall_pressure = setup.pressure.map(|(boundary, centre, area)| {
        let sets = sim.reaction_sets();
        let offset: usize = sets[..boundary].iter().map(Vec::len).sum();
        let positions = sim.node_positions();
        let nodes: Vec<SVector<f64, D>> = sets[boundary]
            .iter()
            .map(|&n| positions[n as usize])
            .collect();
        (WallPressure::new(boundary, centre, area), offset, nodes)
    });
    let mut header = history_header(D, setup.reference.is_some(), setup.displacement.is_some());
    header.extend(probes.columns(D));
    for k in 0..setup.boundaries.len() {
        header.extend(
            ["x", "y", "z"][..D]
                .iter()
                .map(|a| format!("reaction{k}_{a}")),
        );
        header.push(format!("reaction{k}_magnitude"));
    }
    let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut history = HistoryWriter::create(out.path("history.csv"), &header_refs)?;

    // Where each stored particle started: the seeds, in the simulation's storage order
    // (which a particle sort changes; `follow_sorted`).
    let mut reference_positions = seeds.position.clone();
    let mut sorts = sim.particle_sorts();
    let frames = setup::frame_count(scene, ctx.end_time);
    let frame_time = |k: usize| ctx.end_time * k as f64 / (frames - 1) as f64;
    let mut next_frame = 1;
    // A history row; the displacement and probe errors are sampled here, at the rows.
    let mut displacement_errors: Vec<f64> = Vec::new();
    let mut probe_error = 0.0f64;
    let mut record = |sim: &dyn Run<D>,
                      history: &mut HistoryWriter,
                      error: Option<f64>,
                      (reference_positions, probes): (&[SVector<f64, D>], &Probes)|
     -> Result<(f64, Diagnostics<D>, EnergyRecord)> {
        let d = sim.diagnostics()?;
        let (potential, total) = total_energy(&d);
        let displacement = reference::displacement_error(
            scene,
            setup,
            reference_positions,
            sim.positions(),
            sim.time(),
        )?;
        displacement_errors.extend(displacement);
        let mut row = history_row(&d, potential, total, error);
        row.extend(displacement);
        for k in 0..probes.len() {
            let u = probes.displacement(k, &setup.frame, reference_positions, sim.positions());
            row.extend(u.iter());
            if let Some(reference) = setup.probe_reference.as_ref().filter(|r| r.probe == k) {
                if let Some(exact) = reference.at(sim.time()) {
                    probe_error = probe_error.max((u - exact).norm() / reference.scale());
                }
            }
        }
        if let Some((wall, offset, nodes)) = wall_pressure.as_mut() {
            let all = sim.node_reactions();
            if all.len() >= *offset + nodes.len() {
                wall.record(nodes, &all[*offset..*offset + nodes.len()]);
            }
        }
        // Reactions after the probes, as the header has them.
        let reactions = sim.reactions();
        for k in 0..setup.boundaries.len() {
            let r = reactions.get(k).copied().unwrap_or_default();
            row.extend(r.force.iter());
            row.push(r.magnitude);
        }
        history.row(&row)?;
        let record = EnergyRecord {
            time: d.time,
            kinetic: d.kinetic,
            elastic: d.elastic,
            potential,
            total,
        };
        Ok((total, d, record))
    };

    let reference_error = |sim: &dyn Run<D>, reference_positions: &[SVector<f64, D>]| {
        reference::velocity_error(
            scene,
            setup,
            reference_positions,
            sim.velocities(),
            sim.time(),
            if sim.step_count() > 0 {
                sim.last_dt()
            } else {
                0.0
            },
        )
    };

    sim.write_particles(&mut out, &reference_positions)?;
    let (e0, d0, r0) = record(
        &*sim,
        &mut history,
        reference_error(&*sim, &reference_positions)?,
        (&reference_positions, &probes),
    )?;
    let mut energies = vec![r0];
    // Energy error: the largest |E(t) − E(0)| over the largest mechanical energy
    // (kinetic + elastic) of the run, which stays meaningful when E(0) is 0 (a body
    // released from rest under gravity).
    let (mut energy_change, mut energy_scale) = (0.0f64, d0.kinetic + d0.elastic);
    // The largest gain E(t) − E(0) alone: energy the scheme created (dissipation is a
    // loss and does not count), for stability maps.
    let mut energy_gain = 0.0f64;
    let (mut error_sum, mut error_max) = (0.0f64, 0.0f64);
    let progress = Progress::new(ctx.options.progress, steps as u64, &spec.scene.name);
    let start = Instant::now();
    let mut failure: Option<CliError> = None;
    let mut last = d0;
    let mut last_total = e0;
    let mut max_wave_courant = d0.wave_courant;
    let mut step = 0;
    while sim.time() < ctx.end_time * (1.0 - 1e-12) {
        step += 1;
        if let TimeStepControl::Adaptive { .. } = sim.settings().time_step {
            sim.settings_mut().dt = dt_cap.min(ctx.end_time - sim.time());
        }
        if ctx
            .options
            .interrupt
            .as_ref()
            .is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed))
        {
            failure = Some(CliError::Interrupted {
                time: sim.time(),
                step: sim.step_count(),
            });
            break;
        }
        // Reactions are summed only for the steps whose history row reads them (the last
        // step is predicted with half a step of margin).
        let dt = sim.settings().dt;
        sim.settings_mut().measure_reactions = step % spec.output.history_every == 0
            || sim.time() + 1.5 * dt >= ctx.end_time * (1.0 - 1e-12);
        if let Err(e) = sim.step() {
            failure = Some(e.into());
            break;
        }
        if sim.particle_sorts() != sorts {
            sorts = sim.particle_sorts();
            follow_sorted(
                &*sim,
                &seeds.position,
                &mut reference_positions,
                &mut probes,
            );
        }
        let error = reference_error(&*sim, &reference_positions)?;
        if let Some(e) = error {
            error_sum += e * e;
            error_max = error_max.max(e);
        }
        let last_step = sim.time() >= ctx.end_time * (1.0 - 1e-12);
        if step % spec.output.history_every == 0 || last_step {
            let (total, d, r) =
                record(&*sim, &mut history, error, (&reference_positions, &probes))?;
            max_wave_courant = max_wave_courant.max(d.wave_courant);
            energies.push(r);
            energy_change = energy_change.max((total - e0).abs());
            energy_gain = energy_gain.max(total - e0);
            last_total = total;
            energy_scale = energy_scale.max(d.kinetic + d.elastic);
            last = d;
        }
        if next_frame < frames && sim.time() >= frame_time(next_frame) - 0.5 * sim.settings().dt {
            sim.write_particles(&mut out, &reference_positions)?;
            next_frame += 1;
        }
        progress.advance();
    }
    let wall = start.elapsed().as_secs_f64();
    progress.finish();
    if failure.is_some() {
        // The state the run stopped in (the last frame may be far behind it), and its
        // history row. A state whose stresses cannot be evaluated (an inverted particle)
        // has no frame; the summary still says why the run stopped.
        if let Err(e) = sim.write_particles(&mut out, &reference_positions) {
            warnings.push(format!("the state the run stopped in has no frame: {e}"));
        }
        if let Ok((total, d, r)) =
            record(&*sim, &mut history, None, (&reference_positions, &probes))
        {
            energies.push(r);
            last_total = total;
            last = d;
        }
    }
    history.flush()?;
    let (mass, velocity) = sim.grid();
    let mesh = setup.background.mesh();
    if mesh_kernel {
        if let Some(mesh) = mesh {
            out.write_mesh(mesh, &setup.groups, Some((mass, velocity)))?;
        }
    } else {
        if let Some(mesh) = mesh {
            out.write_mesh(mesh, &setup.groups, None)?;
        }
        let nodes = sim.node_positions();
        out.write_grid(&nodes, mass, velocity)?;
    }
    crate::plot::energy_plot(
        &out.path("energies.svg"),
        &format!(
            "{}: energies ({}, {})",
            spec.scene.name,
            ctx.kernel.name(),
            transfer_name(&spec.transfer)
        ),
        D,
        &energies,
        setup.gravity.norm() > 0.0,
    )?;
    let taken = sim.step_count();
    let mut metrics = serde_json::Map::new();
    let energy_error = if energy_scale > 0.0 {
        energy_change / energy_scale
    } else {
        0.0
    };
    metrics.insert("energy_error".into(), json!(energy_error));
    let relative = |e: f64| {
        if energy_scale > 0.0 {
            e / energy_scale
        } else {
            0.0
        }
    };
    metrics.insert("energy_gain_max".into(), json!(relative(energy_gain)));
    metrics.insert(
        "energy_change_final".into(),
        json!(relative(last_total - e0)),
    );
    metrics.insert("initial_energy".into(), json!(e0));
    metrics.insert("final_energy".into(), json!(last_total));
    metrics.insert(
        "momentum_change".into(),
        json!((last.momentum - d0.momentum).norm()),
    );
    metrics.insert("dropped_mass".into(), json!(last.dropped_mass));
    metrics.insert(
        "redistributed_momentum".into(),
        json!(last.redistributed_momentum.norm()),
    );
    metrics.insert("wall_corrections".into(), json!(last.wall_corrections));
    metrics.insert("mass_scaled_nodes".into(), json!(last.mass_scaled_nodes));
    if setup.reference.is_some() && taken > 0 {
        metrics.insert(
            "velocity_rmse".into(),
            json!((error_sum / taken as f64).sqrt()),
        );
        metrics.insert("velocity_error_max".into(), json!(error_max));
    }
    metrics.extend(end_metrics::end_state(
        scene,
        setup,
        &*sim,
        &reference_positions,
        &probes,
        failure.is_some(),
        e0,
    )?);
    if let Some((wall, _, _)) = &wall_pressure {
        metrics.extend(wall.metrics());
    }
    if setup.probe_reference.is_some() {
        metrics.insert("probe_error_max".into(), json!(probe_error));
    }
    if let (Some(&last), Some(max)) = (
        displacement_errors.last(),
        displacement_errors.iter().copied().reduce(f64::max),
    ) {
        metrics.insert("displacement_error_final".into(), json!(last));
        metrics.insert("displacement_error_max".into(), json!(max));
    }
    let summary = json!({
        "scene": spec.scene.name,
        "source": scene.label,
        "dimension": D,
        "kernel": ctx.kernel.name(),
        "transfer": transfer_name(&spec.transfer),
        "stress_update": spec.time.stress_update.name(),
        "stencils": spec.kernel.stencils.name(),
        "particle_sort_interval": spec.kernel.particle_sort_interval,
        "particle_sorts": sim.particle_sorts(),
        "materials": setup.material_names,
        "particles": sim.positions().len(),
        "nodes": sim.node_count(),
        "cells": setup.background.cell_count(),
        "dt": sim.last_dt(),
        "time_step": match sim.settings().time_step {
            TimeStepControl::Fixed => "fixed",
            TimeStepControl::Adaptive { .. } => "adaptive",
        },
        "stable_dt": stable_dt,
        "dt_exceeds_stable": sim.settings().time_step == TimeStepControl::Fixed && sim.settings().dt > stable_dt,
        "max_wave_courant": max_wave_courant,
        "warnings": warnings,
        "end_time": ctx.end_time,
        "steps_planned": steps,
        "steps": taken,
        "threads": rayon::current_num_threads(),
        "status": match &failure {
            None => "completed",
            Some(CliError::Interrupted { .. }) => "interrupted",
            Some(_) => "failed",
        },
        "error": failure.as_ref().map(|e| e.to_string()),
        "failure_kind": match &failure {
            Some(CliError::Engine(e)) => Some(e.kind()),
            Some(CliError::Interrupted { .. }) | None => None,
            Some(_) => Some("other"),
        },
        "peak_memory_bytes": crate::memory::peak_resident_bytes(),
        "engine_memory": engine_memory(&sim.memory_use()),
        "wall_time_s": wall,
        "stage_seconds": stage_seconds(&sim.stage_times()),
        "particle_steps_per_second": if wall > 0.0 { (sim.positions().len() * taken) as f64 / wall } else { 0.0 },
        "metrics": metrics,
        "outputs": {
            "particles": "particles.pvd",
            "frames": out.frames(),
            "mesh": mesh.map(|_| "mesh.vtu"),
            "grid": if mesh_kernel { None } else { Some("grid.vtu") },
            "history": "history.csv",
            "energy_plot": "energies.svg",
        },
    });
    let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
    let path = out.path("summary.json");
    std::fs::write(&path, text + "\n").map_err(|source| CliError::File { path, source })?;
    match failure {
        Some(e) => Err(e),
        None => Ok(RunReport {
            summary,
            out: ctx.options.out.clone(),
        }),
    }
}

/// The simulation's own accounting of its memory (`Simulation::memory_use`).
fn engine_memory(m: &umls_engine::MemoryUse) -> serde_json::Value {
    json!({
        "particle_state_bytes": m.particles,
        "particle_scratch_bytes": m.particle_scratch,
        "stored_stencil_bytes": m.stencils,
        "node_bytes": m.nodes,
        "bytes_per_particle": m.bytes_per_particle(),
        "bytes_per_particle_with_stencils": m.bytes_per_particle_with_stencils(),
    })
}

/// Seconds per stage of the step, and their share of the stepping time.
fn stage_seconds(times: &StageTimes) -> serde_json::Value {
    let total = times.total();
    let mut map = serde_json::Map::new();
    for (name, seconds) in times.stages() {
        map.insert(name.into(), json!(seconds));
    }
    map.insert("total".into(), json!(total));
    map.insert(
        "fractions".into(),
        json!(
            times
                .stages()
                .iter()
                .map(|(name, s)| (
                    name.to_string(),
                    json!(if total > 0.0 { s / total } else { 0.0 })
                ))
                .collect::<serde_json::Map<_, _>>()
        ),
    );
    json!(map)
}

/// Columns of `history.csv`.
fn history_header(dimension: usize, with_reference: bool, with_displacement: bool) -> Vec<String> {
    let mut header: Vec<String> = ["step", "time", "kinetic", "elastic", "potential", "total"]
        .map(String::from)
        .into();
    header.extend(
        ["x", "y", "z"][..dimension]
            .iter()
            .map(|a| format!("momentum_{a}")),
    );
    header.extend(
        [
            "mass",
            "max_speed",
            "courant",
            "dt",
            "wave_courant",
            "dropped_mass",
            "wall_corrections",
            "mass_scaled_nodes",
        ]
        .map(String::from),
    );
    if with_reference {
        header.push("velocity_error".into());
    }
    if with_displacement {
        header.push("displacement_error".into());
    }
    header
}

/// One row of `history.csv`, in the order of [`history_header`].
fn history_row<const D: usize>(
    d: &Diagnostics<D>,
    potential: f64,
    total: f64,
    error: Option<f64>,
) -> Vec<f64> {
    let mut row = vec![
        d.step as f64,
        d.time,
        d.kinetic,
        d.elastic,
        potential,
        total,
    ];
    row.extend(d.momentum.iter());
    row.extend([
        d.mass,
        d.max_speed,
        d.courant,
        d.dt,
        d.wave_courant,
        d.dropped_mass,
        d.wall_corrections as f64,
        d.mass_scaled_nodes as f64,
    ]);
    row.extend(error);
    row
}

/// The fixed step (or the cap of the adaptive one) and the planned number of steps;
/// warns when a fixed step exceeds the stable one.
fn plan_time_step<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
    stable_dt: f64,
    warnings: &mut Vec<String>,
) -> Result<(usize, f64)> {
    let (scene, spec) = (ctx.scene, &ctx.scene.spec);
    let target_dt = match (spec.time.dt, spec.time.cfl, spec.time.adaptive) {
        (_, Some(cfl), true) => {
            sim.settings_mut().time_step = TimeStepControl::Adaptive { cfl };
            spec.time
                .dt
                .unwrap_or(f64::INFINITY)
                .min(sim.stable_time_step(cfl))
        }
        (Some(dt), _, _) => dt,
        (_, Some(cfl), _) => sim.stable_time_step(cfl),
        _ => unreachable_dt(scene)?,
    };
    let planned = ((ctx.end_time / target_dt) - 1e-9).ceil().max(1.0);
    // A typo in end_time (1e12 for 1.2) should be an error, not a run of years.
    const MAX_STEPS: f64 = 1e9;
    if planned > MAX_STEPS {
        return Err(scene.value_error(
            "scene.end_time",
            format!(
                "{} with a time step of {target_dt:.4e} is {planned:.3e} steps (limit {MAX_STEPS:.0e})",
                ctx.end_time
            ),
        ));
    }
    let steps = planned as usize;
    let dt_cap = match sim.settings().time_step {
        TimeStepControl::Adaptive { .. } => spec.time.dt.unwrap_or(ctx.end_time),
        TimeStepControl::Fixed => ctx.end_time / steps as f64,
    };
    sim.settings_mut().dt = dt_cap;
    if sim.settings().time_step == TimeStepControl::Fixed && sim.settings().dt > stable_dt {
        warnings.push(format!(
            "time.dt = {:.4e} exceeds the stable step {stable_dt:.4e} (wave Courant number {:.3} > 1): expect the run to blow up",
            sim.settings().dt,
            sim.settings().dt / stable_dt
        ));
    }

    Ok((steps, dt_cap))
}

/// `check_header` guarantees a time step setting; this keeps the match total without a panic.
fn unreachable_dt(scene: &Scene) -> Result<f64> {
    Err(scene.value_error("time", "give exactly one of `dt` and `cfl`"))
}
