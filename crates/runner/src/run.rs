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
use umls_kernels::{BSplineKernel, LinearFeKernel};
use umls_ugimp::UgimpKernel;

use crate::context::Context;
pub use crate::context::{History, Progress, RunOptions, RunPlan, RunReport};
use crate::error::Result;
use crate::kernel_choice::{KernelFactory, LinearUmls, Preset, QuadraticUmls};
use crate::scene::Scene;
use crate::schema::{EncodingSpec, KernelKind};
use crate::setup::{self, Split};

/// A dimension a scene can have, with what differs between dimensions: the UMLS kernel
/// types of the presets, the lattice split, and the plastic part of the material table
/// (plastic models need D = 2 or 3). [`Dim`]`<1>`, `<2>` and `<3>` implement it.
pub trait SceneDimension<const D: usize> {
    /// `umls` and its linear-basis variants.
    type Umls: Kernel<D>;
    /// `umls-quadratic`.
    type UmlsQuadratic: Kernel<D>;
    /// The plastic part of the material table (`NoPlasticity` in 1D).
    type Plastic: PlasticPart<D>;
    /// How a lattice is split into simplices.
    const SPLIT: Split<D>;
    /// The scene's material table with plastic models, or `None` where the dimension has
    /// none.
    fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<Self::Plastic>>;
}

use umls_transfer::Kernel;

/// The dimension `D` as a type.
#[derive(Debug, Clone, Copy)]
pub struct Dim<const D: usize>;

impl SceneDimension<1> for Dim<1> {
    type Umls = LinearUmls<1, 2>;
    type UmlsQuadratic = QuadraticUmls<1, 3>;
    type Plastic = NoPlasticity;
    const SPLIT: Split<1> = setup::segments;
    fn plastic_table(_: &[Model<PlasticModel>]) -> Option<MaterialTable<NoPlasticity>> {
        None
    }
}

impl SceneDimension<2> for Dim<2> {
    type Umls = LinearUmls<2, 3>;
    type UmlsQuadratic = QuadraticUmls<2, 6>;
    type Plastic = PlasticModel;
    const SPLIT: Split<2> = setup::triangles;
    fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<PlasticModel>> {
        plastic_table(models)
    }
}

impl SceneDimension<3> for Dim<3> {
    type Umls = LinearUmls<3, 4>;
    type UmlsQuadratic = QuadraticUmls<3, 10>;
    type Plastic = PlasticModel;
    const SPLIT: Split<3> = setup::tetrahedra;
    fn plastic_table(models: &[Model<PlasticModel>]) -> Option<MaterialTable<PlasticModel>> {
        plastic_table(models)
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
    let kind = options.kernel.unwrap_or(scene.spec.kernel.kind);
    in_pool(scene, options, || match scene.spec.scene.dimension {
        1 => preset::<1>(scene, options, kind),
        2 => preset::<2>(scene, options, kind),
        _ => preset::<3>(scene, options, kind),
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
    if scene.spec.scene.dimension != D {
        return Err(scene.value_error(
            "scene.dimension",
            format!(
                "is {}, and the kernel given to the run is {D}-dimensional",
                scene.spec.scene.dimension
            ),
        ));
    }
    in_pool(scene, options, || {
        with_factory::<D, _>(scene, options, factory)
    })
}

/// Checks the scene's header and the options, then runs `body` in a thread pool of
/// `options.threads` workers.
fn in_pool(
    scene: &Scene,
    options: &RunOptions,
    body: impl FnOnce() -> Result<RunReport> + Send,
) -> Result<RunReport> {
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
    pool.install(body)
}

/// A built-in kernel preset of dimension D.
fn preset<const D: usize>(
    scene: &Scene,
    options: &RunOptions,
    kind: KernelKind,
) -> Result<RunReport>
where
    Dim<D>: SceneDimension<D>,
    Preset<LinearFeKernel<D>>: KernelFactory<D>,
    Preset<BSplineKernel<D>>: KernelFactory<D>,
    Preset<UgimpKernel<D>>: KernelFactory<D>,
    Preset<<Dim<D> as SceneDimension<D>>::Umls>: KernelFactory<D>,
    Preset<<Dim<D> as SceneDimension<D>>::UmlsQuadratic>: KernelFactory<D>,
{
    type Umls<const D: usize> = <Dim<D> as SceneDimension<D>>::Umls;
    type UmlsQuadratic<const D: usize> = <Dim<D> as SceneDimension<D>>::UmlsQuadratic;
    match kind {
        KernelKind::UmlsQuadratic => {
            with_factory::<D, _>(scene, options, &Preset::<UmlsQuadratic<D>>::new(kind))
        }
        KernelKind::LinearFe => {
            with_factory::<D, _>(scene, options, &Preset::<LinearFeKernel<D>>::new(kind))
        }
        KernelKind::Ugimp => {
            with_factory::<D, _>(scene, options, &Preset::<UgimpKernel<D>>::new(kind))
        }
        KernelKind::Bspline2 | KernelKind::Bspline3 => {
            with_factory::<D, _>(scene, options, &Preset::<BSplineKernel<D>>::new(kind))
        }
        _ => with_factory::<D, _>(scene, options, &Preset::<Umls<D>>::new(kind)),
    }
}

/// The set-up, the kernel and the run.
fn with_factory<const D: usize, F: KernelFactory<D>>(
    scene: &Scene,
    options: &RunOptions,
    factory: &F,
) -> Result<RunReport>
where
    Dim<D>: SceneDimension<D>,
{
    let setup = setup::build_for::<D>(scene, <Dim<D>>::SPLIT, !factory.on_mesh())?;
    let encoding = match scene.spec.output.encoding {
        EncodingSpec::Binary => Encoding::Binary,
        EncodingSpec::Ascii => Encoding::Ascii,
    };
    let kernel = factory.build(scene, &setup)?;
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
        return match <Dim<D>>::plastic_table(&ctx.setup.models) {
            Some(table) => crate::material_transfer::with_material(&ctx, kernel, table),
            None => Err(setup::plastic_in_1d(scene)),
        };
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
    crate::material_transfer::with_material(&ctx, kernel, MaterialTable::<NoPlasticity> { models })
}
