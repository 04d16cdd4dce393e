//! Running a scene: build its set-up for its dimension, build the kernel (a built-in
//! preset or a [`KernelFactory`] of the caller's), pick the material table and transfer
//! types, and hand the typed simulation to the run loop (the private `drive` module).
//!
//! Each (dimension, kernel, transfer, plasticity) combination is its own monomorphized
//! simulation, so a run steps with exactly the code its scene needs. The run loop around
//! it (time step, boundaries, output, history, summary) sees the simulation through the
//! object-safe `Run` trait and is compiled once per dimension.

use umls_constitutive::table::{MaterialTable, Model, NoPlasticity, PlasticModel, PlasticPart};
use umls_io::vtk::Encoding;
use umls_kernels::presets::PresetKernels;
use umls_kernels::{BSplineKernel, LinearFeKernel};
use umls_ugimp::UgimpKernel;

use umls_engine::DynSimulation;

use crate::context::Context;
pub use crate::context::{History, Progress, RunOptions, RunPlan, RunReport};
use crate::error::Result;
use crate::handle::Run;
use crate::kernel_choice::{BuiltIn, KernelFactory};
use crate::scene::Scene;
use crate::schema::{EncodingSpec, KernelKind};
use crate::setup::{self, Split};

/// A dimension a scene can have, with what differs between dimensions: the UMLS kernel
/// types of the presets (from `umls_kernels::presets`), the lattice split, and the plastic part of the material table
/// (plastic models need D = 2 or 3). [`Dim`]`<1>`, `<2>` and `<3>` implement it.
pub trait SceneDimension<const D: usize>: PresetKernels<D> {
    /// The plastic part of the material table (`NoPlasticity` in 1D).
    type Plastic: PlasticPart<D>;
    /// How a lattice is split into simplices.
    const SPLIT: Split<D>;
    /// The scene's material table with plastic models, or `None` where the dimension has
    /// none.
    fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<Self::Plastic>>;
    /// Hands the built-in preset `kind` of this dimension to `w`.
    fn with_preset<W: WithFactory<D>>(kind: KernelKind, w: W) -> W::Output;
}

/// Something done with a kernel factory of dimension `D`: what
/// [`SceneDimension::with_preset`] hands a built-in preset to, so that code generic over
/// the dimension reaches the presets' concrete kernel types.
pub trait WithFactory<const D: usize> {
    /// What it gives.
    type Output;
    /// Does it with `factory`.
    fn with<F: KernelFactory<D>>(self, factory: &F) -> Self::Output;
}

/// The dimension `D` as a type (the kernels' presets name their types by it).
pub use umls_kernels::presets::Dim;

impl SceneDimension<1> for Dim<1> {
    type Plastic = NoPlasticity;
    const SPLIT: Split<1> = setup::segments;
    fn plastic_table(_: &[Model<PlasticModel>]) -> Option<MaterialTable<NoPlasticity>> {
        None
    }
    fn with_preset<W: WithFactory<1>>(kind: KernelKind, w: W) -> W::Output {
        with_preset::<1, W>(kind, w)
    }
}

impl SceneDimension<2> for Dim<2> {
    type Plastic = PlasticModel;
    const SPLIT: Split<2> = setup::triangles;
    fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<PlasticModel>> {
        plastic_table(models)
    }
    fn with_preset<W: WithFactory<2>>(kind: KernelKind, w: W) -> W::Output {
        with_preset::<2, W>(kind, w)
    }
}

impl SceneDimension<3> for Dim<3> {
    type Plastic = PlasticModel;
    const SPLIT: Split<3> = setup::tetrahedra;
    fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<PlasticModel>> {
        plastic_table(models)
    }
    fn with_preset<W: WithFactory<3>>(kind: KernelKind, w: W) -> W::Output {
        with_preset::<3, W>(kind, w)
    }
}

/// The table of the scene's models, plastic ones included (D = 2, 3).
fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<PlasticModel>> {
    Some(MaterialTable {
        models: models.to_vec(),
    })
}

/// Runs `scene` with `options`, with the scene's kernel or `options.kernel`.
pub fn run(scene: &Scene, options: &RunOptions) -> Result<RunReport> {
    in_pool(scene, options, || match scene.spec.scene.dimension {
        1 => drive_preset::<1>(scene, options),
        2 => drive_preset::<2>(scene, options),
        _ => drive_preset::<3>(scene, options),
    })
}

/// Runs `scene` with the kernel `factory` builds: a kernel type of the caller's goes
/// through the same set-up, run loop, outputs and summary as a built-in one. The scene
/// must be `D`-dimensional; `options.kernel` is ignored.
pub fn run_with<const D: usize, F: KernelFactory<D> + Sync>(
    scene: &Scene,
    options: &RunOptions,
    factory: &F,
) -> Result<RunReport>
where
    Dim<D>: SceneDimension<D>,
{
    check_dimension::<D>(scene)?;
    in_pool(scene, options, || {
        let (ctx, mut sim) = with_factory::<D, _>(scene, options, factory)?;
        crate::drive::drive(&ctx, &mut *sim)
    })
}

/// A scene's simulation, set up as a run starts it (geostatic stress, Δt planned to the
/// end time, boundaries applied) and handed to the caller to step: a bench, or a loop
/// of the caller's own. [`prepare`] and [`prepare_with`] build it.
pub struct Prepared<const D: usize> {
    sim: Box<dyn Run<D>>,
    plan: crate::time_plan::TimePlan,
    end_time: f64,
    kernel: String,
    warnings: Vec<String>,
}

impl<const D: usize> Prepared<D> {
    /// The simulation, to step (`step_until(end_time)` lands on the end time).
    pub fn simulation(&mut self) -> &mut (dyn DynSimulation<D> + Send) {
        self.sim.as_dyn()
    }
    /// The scene's end time (or the options').
    pub fn end_time(&self) -> f64 {
        self.end_time
    }
    /// Steps planned to the end time.
    pub fn steps_planned(&self) -> usize {
        self.plan.steps
    }
    /// The kernel's name.
    pub fn kernel(&self) -> &str {
        &self.kernel
    }
    /// What a run would warn about the set-up and the time step.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
}

impl<const D: usize> std::fmt::Debug for Prepared<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Prepared")
            .field("kernel", &self.kernel)
            .field("end_time", &self.end_time)
            .field("steps_planned", &self.plan.steps)
            .field("particles", &self.sim.positions().len())
            .finish()
    }
}

/// The simulation of the `D`-dimensional `scene` with its kernel or `options.kernel`,
/// set up to its first step ([`Prepared`]); `options.out`, `threads`, `progress` and
/// `interrupt` are a run's and are not read.
pub fn prepare<const D: usize>(scene: &Scene, options: &RunOptions) -> Result<Prepared<D>>
where
    Dim<D>: SceneDimension<D>,
{
    check_dimension::<D>(scene)?;
    check_options(scene, options)?;
    let kind = options.kernel.unwrap_or(scene.spec.kernel.kind);
    let (ctx, sim) = <Dim<D>>::with_preset(kind, Build { scene, options })?;
    prepared(&ctx, sim)
}

/// [`prepare`] with the kernel `factory` builds.
pub fn prepare_with<const D: usize, F: KernelFactory<D>>(
    scene: &Scene,
    options: &RunOptions,
    factory: &F,
) -> Result<Prepared<D>>
where
    Dim<D>: SceneDimension<D>,
{
    check_dimension::<D>(scene)?;
    check_options(scene, options)?;
    let (ctx, sim) = with_factory::<D, _>(scene, options, factory)?;
    prepared(&ctx, sim)
}

fn prepared<const D: usize>(ctx: &Context<'_, D>, mut sim: Box<dyn Run<D>>) -> Result<Prepared<D>> {
    let (plan, warnings) = crate::drive::prologue(ctx, &mut *sim)?;
    Ok(Prepared {
        sim,
        plan,
        end_time: ctx.end_time,
        kernel: ctx.kernel_name.clone(),
        warnings,
    })
}

/// Refuses a scene that is not `D`-dimensional.
fn check_dimension<const D: usize>(scene: &Scene) -> Result<()> {
    if scene.spec.scene.dimension != D {
        return Err(scene.value_error(
            "scene.dimension",
            format!(
                "is {}, and the kernel given to the run is {D}-dimensional",
                scene.spec.scene.dimension
            ),
        ));
    }
    Ok(())
}

/// Checks the scene's header and the options' end time.
fn check_options(scene: &Scene, options: &RunOptions) -> Result<()> {
    setup::check_header(scene)?;
    if let Some(t) = options.end_time {
        if !(t.is_finite() && t > 0.0) {
            return Err(scene.value_error("--end-time", "must be finite and positive"));
        }
    }
    Ok(())
}

/// Checks the scene's header and the options, then runs `body` in a thread pool of
/// `options.threads` workers.
fn in_pool(
    scene: &Scene,
    options: &RunOptions,
    body: impl FnOnce() -> Result<RunReport> + Send,
) -> Result<RunReport> {
    check_options(scene, options)?;
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
    pool.install(body)
}

/// Runs the `D`-dimensional scene with its kernel or `options.kernel`.
fn drive_preset<const D: usize>(scene: &Scene, options: &RunOptions) -> Result<RunReport>
where
    Dim<D>: SceneDimension<D>,
{
    let kind = options.kernel.unwrap_or(scene.spec.kernel.kind);
    let (ctx, mut sim) = <Dim<D>>::with_preset(kind, Build { scene, options })?;
    crate::drive::drive(&ctx, &mut *sim)
}

/// Builds the simulation with the factory it is given: the set-up, the kernel, the
/// material table and the transfer.
struct Build<'a> {
    scene: &'a Scene,
    options: &'a RunOptions,
}

impl<'a, const D: usize> WithFactory<D> for Build<'a>
where
    Dim<D>: SceneDimension<D>,
{
    type Output = Result<(Context<'a, D>, Box<dyn Run<D>>)>;
    fn with<F: KernelFactory<D>>(self, factory: &F) -> Self::Output {
        with_factory::<D, F>(self.scene, self.options, factory)
    }
}

/// The built-in preset `kind` of dimension D, handed to `w`.
fn with_preset<const D: usize, W: WithFactory<D>>(kind: KernelKind, w: W) -> W::Output
where
    Dim<D>: SceneDimension<D>,
    BuiltIn<LinearFeKernel<D>>: KernelFactory<D>,
    BuiltIn<BSplineKernel<D>>: KernelFactory<D>,
    BuiltIn<UgimpKernel<D>>: KernelFactory<D>,
    BuiltIn<<Dim<D> as PresetKernels<D>>::Umls>: KernelFactory<D>,
    BuiltIn<<Dim<D> as PresetKernels<D>>::UmlsQuadratic>: KernelFactory<D>,
{
    type Umls<const D: usize> = <Dim<D> as PresetKernels<D>>::Umls;
    type UmlsQuadratic<const D: usize> = <Dim<D> as PresetKernels<D>>::UmlsQuadratic;
    match kind {
        KernelKind::UmlsQuadratic => w.with(&BuiltIn::<UmlsQuadratic<D>>::new(kind)),
        KernelKind::LinearFe => w.with(&BuiltIn::<LinearFeKernel<D>>::new(kind)),
        KernelKind::Ugimp => w.with(&BuiltIn::<UgimpKernel<D>>::new(kind)),
        KernelKind::Bspline2 | KernelKind::Bspline3 => {
            w.with(&BuiltIn::<BSplineKernel<D>>::new(kind))
        }
        _ => w.with(&BuiltIn::<Umls<D>>::new(kind)),
    }
}

/// The set-up, the kernel and the run.
fn with_factory<'a, const D: usize, F: KernelFactory<D>>(
    scene: &'a Scene,
    options: &'a RunOptions,
    factory: &F,
) -> Result<(Context<'a, D>, Box<dyn Run<D>>)>
where
    Dim<D>: SceneDimension<D>,
{
    let setup = setup::build_for::<D>(scene, <Dim<D>>::SPLIT, !factory.on_mesh())?;
    let encoding = match scene.spec.output.encoding {
        EncodingSpec::Binary => Encoding::Binary,
        EncodingSpec::Ascii => Encoding::Ascii,
    };
    let mut setup = setup;
    let kernel = factory.build(scene, &setup)?;
    let warnings = factory.warnings(&setup);
    setup.warnings.extend(warnings);
    let ctx = Context {
        scene,
        kernel_name: factory.name(),
        mesh_kernel: factory.on_mesh(),
        end_time: options.end_time.unwrap_or(scene.spec.scene.end_time),
        setup,
        options,
        encoding,
    };
    if ctx.setup.has_plasticity() {
        let sim = match <Dim<D>>::plastic_table(&ctx.setup.models) {
            Some(table) => crate::material_transfer::with_material(&ctx, kernel, table)?,
            None => return Err(setup::plastic_in_1d(scene)),
        };
        return Ok((ctx, sim));
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
    let table = MaterialTable::<NoPlasticity> { models };
    let sim = crate::material_transfer::with_material(&ctx, kernel, table)?;
    Ok((ctx, sim))
}
