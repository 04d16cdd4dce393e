//! The TOML scene format. Every table rejects keys it does not know, so a typo is an
//! error that names the key instead of a silently ignored setting.

use serde::Deserialize;

/// A whole scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Name, dimension, duration, gravity.
    pub scene: SceneHeader,
    /// The background mesh.
    pub mesh: MeshSpec,
    /// Shape functions.
    #[serde(default)]
    pub kernel: KernelSpec,
    /// Particle–grid transfer.
    #[serde(default)]
    pub transfer: TransferSpec,
    /// Time stepping.
    pub time: TimeSpec,
    /// Output.
    #[serde(default)]
    pub output: OutputSpec,
    /// Materials, referred to by name from bodies.
    pub materials: Vec<MaterialSpec>,
    /// Bodies of material: region, seeding, initial velocity.
    pub bodies: Vec<BodySpec>,
    /// Velocity boundary conditions.
    #[serde(default)]
    pub boundaries: Vec<BoundarySpec>,
    /// Analytic reference solution, if the scene has one.
    pub reference: Option<ReferenceSpec>,
    /// Damping of the nodal forces (quasi-static runs).
    pub damping: Option<DampingSpec>,
    /// Initial stress of the particles.
    pub initial_stress: Option<InitialStressSpec>,
    /// A rotation of the whole scene into the world frame.
    pub transform: Option<TransformSpec>,
    /// Named expressions the scene's fields may use as variables.
    #[serde(default)]
    pub definitions: std::collections::BTreeMap<String, String>,
    /// A body acceleration field added to gravity.
    pub body_force: Option<BodyForceSpec>,
}

/// `[output] profile`: the body's surface height `up` at the end, in `bins` equal bins
/// along `along` from `start` to `end` (scene frame).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileSpec {
    /// Direction the bins follow.
    pub along: Vec<f64>,
    /// Direction of the height.
    pub up: Vec<f64>,
    /// Where the bins start and end along `along`.
    pub start: f64,
    /// See `start`.
    pub end: f64,
    /// Number of bins.
    pub bins: usize,
}

/// `[body_force]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyForceSpec {
    /// D components: acceleration b(x, t), with x the position `position` names.
    pub acceleration: Vec<Component>,
    /// Which position of a particle x stands for in `acceleration`.
    #[serde(default)]
    pub position: ForcePosition,
}

/// `[body_force] position`: where a particle's body force is evaluated.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ForcePosition {
    /// Where the particle is now: a field of space (a trap, a centrifuge).
    #[default]
    Current,
    /// Where the particle started, X: a field of the material, as a manufactured
    /// solution's force is (b(X, t) makes the exact motion a solution for each particle,
    /// whereas at a drifted current position it acts with the force meant for another
    /// place).
    Reference,
}

/// `[transform]`: the scene as written is turned by `rotation` degrees (counter-clockwise
/// about `axis` through `centre`) before it runs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformSpec {
    /// Angle in degrees.
    pub rotation: f64,
    /// 3D: the axis (default z); 2D scenes turn about z and take no axis.
    pub axis: Option<Vec<f64>>,
    /// The fixed point (default: the origin).
    pub centre: Option<Vec<f64>>,
}

/// `[damping]`: exactly one of `local` (Cundall's α) and `mass` (β in 1/s).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// Local non-viscous damping coefficient α ∈ [0, 1).
    pub local: Option<f64>,
    /// Mass-proportional damping β ≥ 0 in 1/s.
    pub mass: Option<f64>,
}

/// `[initial_stress]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialStressSpec {
    /// Geostatic stress with this lateral ratio K0 = σ_h / σ_v (needs gravity).
    pub geostatic_k0: f64,
}

/// `[scene]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneHeader {
    /// Short name (used in messages and `summary.json`).
    pub name: String,
    /// One line on what the scene shows.
    #[serde(default)]
    pub description: String,
    /// 1, 2 or 3.
    pub dimension: usize,
    /// Simulated time.
    pub end_time: f64,
    /// Gravity vector (D components); zero if absent.
    pub gravity: Option<Vec<f64>>,
    /// Time over which gravity grows linearly from zero to its full value.
    pub gravity_ramp: Option<f64>,
}

/// `[mesh]`: exactly one of `file` and `lattice`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// A Gmsh file, relative to the scene file.
    pub file: Option<String>,
    /// A generated lattice mesh.
    pub lattice: Option<LatticeSpec>,
    /// Turn the background mesh alone (not the bodies) before the run: a mesh at an
    /// angle to the material it carries.
    pub transform: Option<TransformSpec>,
    /// Reject (instead of fixing) negatively oriented cells of a file.
    #[serde(default)]
    pub reject_inverted: bool,
}

/// `[mesh.lattice]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeSpec {
    /// Lower corner.
    pub lower: Vec<f64>,
    /// Upper corner.
    pub upper: Vec<f64>,
    /// Cells per axis.
    pub cells: Vec<usize>,
    /// Interior vertex jitter as a fraction of the cell size (0 to 0.45 in 2D, 0.2 in 3D).
    #[serde(default)]
    pub jitter: f64,
    /// Seed of the jitter.
    #[serde(default)]
    pub seed: u64,
    /// Triangle diagonals (2D only).
    pub diagonal: Option<DiagonalSpec>,
}

/// Kernel names: the kernels' presets (`umls_kernels::presets::Preset`, whose variants
/// say what each kernel is and which study chose it) and `ugimp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum KernelKind {
    #[default]
    /// `umls`.
    Umls,
    /// `umls-quadratic`.
    UmlsQuadratic,
    /// `umls-wendland`.
    UmlsWendland,
    /// `umls-sharp`.
    UmlsSharp,
    /// `umls-wide`.
    UmlsWide,
    /// `umls-paper`.
    UmlsPaper,
    /// `umls-full-gradient`.
    UmlsFullGradient,
    /// `umls-frozen-eta`.
    UmlsFrozenEta,
    /// `umls-uncorrected`.
    UmlsUncorrected,
    /// `umls-eta4`.
    UmlsEta4,
    /// `umls-eta8`.
    UmlsEta8,
    /// `umls-element-size`.
    UmlsElementSize,
    /// `linear-fe`.
    LinearFe,
    /// `bspline2`.
    Bspline2,
    /// `bspline3`.
    Bspline3,
    /// uGIMP (Bardenhagen & Kober 2004) on the grid the B-splines use: the linear hat
    /// averaged over each particle's box of half its initial spacing (`umls-ugimp`).
    Ugimp,
}

impl KernelKind {
    /// Every preset, in the order the command line lists them.
    pub const ALL: [KernelKind; 16] = [
        KernelKind::Umls,
        KernelKind::UmlsQuadratic,
        KernelKind::UmlsWendland,
        KernelKind::UmlsSharp,
        KernelKind::UmlsWide,
        KernelKind::UmlsPaper,
        KernelKind::UmlsFullGradient,
        KernelKind::UmlsFrozenEta,
        KernelKind::UmlsUncorrected,
        KernelKind::UmlsEta4,
        KernelKind::UmlsEta8,
        KernelKind::UmlsElementSize,
        KernelKind::LinearFe,
        KernelKind::Bspline2,
        KernelKind::Bspline3,
        KernelKind::Ugimp,
    ];

    /// The preset named `name` (as in scene files and on the command line).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        self.preset()
            .map_or("ugimp", umls_kernels::presets::Preset::name)
    }

    /// The kernels' preset of this name (all but `ugimp`, whose kernel is its own
    /// crate's).
    pub fn preset(self) -> Option<umls_kernels::presets::Preset> {
        use umls_kernels::presets::Preset;
        Some(match self {
            KernelKind::Umls => Preset::Umls,
            KernelKind::UmlsQuadratic => Preset::UmlsQuadratic,
            KernelKind::UmlsWendland => Preset::UmlsWendland,
            KernelKind::UmlsSharp => Preset::UmlsSharp,
            KernelKind::UmlsWide => Preset::UmlsWide,
            KernelKind::UmlsPaper => Preset::UmlsPaper,
            KernelKind::UmlsFullGradient => Preset::UmlsFullGradient,
            KernelKind::UmlsFrozenEta => Preset::UmlsFrozenEta,
            KernelKind::UmlsUncorrected => Preset::UmlsUncorrected,
            KernelKind::UmlsEta4 => Preset::UmlsEta4,
            KernelKind::UmlsEta8 => Preset::UmlsEta8,
            KernelKind::UmlsElementSize => Preset::UmlsElementSize,
            KernelKind::LinearFe => Preset::LinearFe,
            KernelKind::Bspline2 => Preset::Bspline2,
            KernelKind::Bspline3 => Preset::Bspline3,
            KernelKind::Ugimp => return None,
        })
    }
}

/// `[kernel]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KernelSpec {
    /// Which kernel (default `umls`).
    #[serde(default)]
    pub kind: KernelKind,
    /// Cell size of the B-spline grid (default: the lattice cell size, or the mesh's
    /// longest edge / √D for a file mesh).
    pub grid_spacing: Option<f64>,
    /// UMLS kernels: the distance-weight profile (default: the kernel name's).
    pub weight: Option<WeightSpec>,
    /// UMLS kernels with `weight = "sharpened"`: ε of the divisor 1 + (r/ε)², in units
    /// of the support radius (default 0.4).
    pub sharpening: Option<f64>,
    /// UMLS kernels: how the support radius h_v is chosen (default: the kernel name's).
    pub support: Option<SupportSpec>,
    /// UMLS kernels: multiplier of the support radius (default: the kernel name's).
    pub support_factor: Option<f64>,
    /// UMLS kernels: which shape-function gradient (default: the kernel name's).
    pub gradient: Option<GradientSpec>,
    /// UMLS kernels: the exponent p ≥ 1 of the weights η^p · d (default: the kernel
    /// name's; 1 for every name but `umls-eta4`, 4, and `umls-eta8`, 8).
    pub diminishing_exponent: Option<u32>,
    /// UMLS kernels: whether the force's gradients are corrected node by node to
    /// integrate like the fit's full derivative (default: the kernel name's; `umls`
    /// corrects, the other names do not). Kernels whose gradient is their derivative
    /// are unchanged by it.
    pub integration_correction: Option<bool>,
    /// Whether stencils are stored for the step or recomputed where used (default: the
    /// kernel's choice, `auto`).
    #[serde(default)]
    pub stencils: StencilsSpec,
    /// Every this many steps, store the particles in the order P2G visits them (by the
    /// lowest node of their stencils), so the transfers read them nearly sequentially;
    /// 0 (default) never sorts. The results are the same bit for bit; outputs follow
    /// each particle by its index in the scene.
    #[serde(default)]
    pub particle_sort_interval: usize,
}

/// `kernel.stencils`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StencilsSpec {
    /// As the kernel prefers: B-splines recompute, mesh kernels store.
    #[default]
    Auto,
    /// Store every particle's stencil entries for the step.
    Store,
    /// Store the kernel's factors of each stencil (UMLS: the fit's weights and inverse
    /// moment matrix) and rebuild the entries where used: about half the stencil memory
    /// for 10–17 % more time; entries for kernels without factors.
    Factored,
    /// Recompute stencils in P2G and G2P (less memory, more work).
    Recompute,
}

impl StencilsSpec {
    /// The name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Store => "store",
            Self::Factored => "factored",
            Self::Recompute => "recompute",
        }
    }

    /// The engine's setting.
    pub fn storage(self) -> umls_engine::StencilStorage {
        match self {
            Self::Auto => umls_engine::StencilStorage::KernelChoice,
            Self::Store => umls_engine::StencilStorage::Store,
            Self::Factored => umls_engine::StencilStorage::Factored,
            Self::Recompute => umls_engine::StencilStorage::Recompute,
        }
    }
}

/// `kernel.weight`: the UMLS distance-weight profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WeightSpec {
    /// The cubic B-spline (the paper's).
    CubicBspline,
    /// Wendland's C² function.
    Wendland,
    /// The cubic B-spline divided by 1 + (r/ε)², ε from `kernel.sharpening`.
    Sharpened,
}

/// `kernel.gradient`: the UMLS shape-function gradient.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GradientSpec {
    /// The MLS fit's reconstructed gradient, continuous across facets.
    Reconstructed,
    /// The full derivative of the fit, weights included.
    Full,
    /// The derivative of the fit with the diminishing factors held fixed: continuous
    /// across facets.
    FrozenEta,
}

impl GradientSpec {
    /// The MLS crate's setting.
    pub fn kind(self) -> umls_kernels::GradientKind {
        match self {
            Self::Reconstructed => umls_kernels::GradientKind::Reconstructed,
            Self::Full => umls_kernels::GradientKind::Full,
            Self::FrozenEta => umls_kernels::GradientKind::FrozenEta,
        }
    }
}

/// `kernel.support`: the UMLS support radius rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SupportSpec {
    /// Per vertex: the farthest reach of the vertex's stencils.
    PerVertex,
    /// Per vertex: the longest edge incident to the vertex.
    IncidentEdge,
    /// Per vertex: the edge of the right-angled simplex with the mean volume of the
    /// vertex's simplices (h on any split of a lattice of cells h).
    ElementSize,
    /// One radius, the mesh's longest edge (the paper's).
    Global,
}

/// Transfer names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TransferKind {
    /// PIC.
    Pic,
    /// FLIP blended with PIC by `alpha`.
    #[default]
    Flip,
    /// APIC.
    Apic,
    /// FLIP blended with APIC by `alpha`: APIC's affine P2G, FLIP's velocity update.
    ApicFlip,
    /// APIC with quadratic velocity modes (after PolyPIC): the particles also carry the
    /// coefficients of the centred quadratic modes, which the round trip keeps.
    QuadraticApic,
    /// FLIP blended with quadratic APIC by `alpha`: quadratic APIC's P2G, FLIP's velocity
    /// update.
    QuadraticApicFlip,
    /// Affine transfer with C = ∇v.
    VelocityGradient,
    /// MLS-MPM: APIC with the force folded into the affine momentum and ∇v = C (Hu et
    /// al. 2018, Taichi's scheme); B-spline and UMLS kernels (UMLS with each particle's
    /// own D_p), not linear elements.
    MlsMpm,
}

/// `[transfer]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferSpec {
    /// Which scheme (default `flip`).
    #[serde(default)]
    pub kind: TransferKind,
    /// FLIP fraction of `flip`, `apic-flip` and `quadratic-apic-flip`, in [0, 1] (default
    /// 0.99).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    /// The consistent mass matrix, `{ iterations = k, forces = … }` (default: lumped;
    /// not with `mls-mpm`).
    pub mass: Option<MassSpec>,
}

/// `transfer.mass`: the consistent mass matrix, approximated by Jacobi iterations.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpec {
    /// Jacobi iterations (1 or more).
    pub iterations: usize,
    /// The forces' share of it (default false: the velocity only).
    #[serde(default)]
    pub forces: ForceShare,
}

/// `transfer.mass.forces`: `true` solves the forces with the consistent matrix too,
/// `false` leaves them lumped, a number β ∈ [0, 1] uses (1 − β) M_L + β M_C (½: the mixed
/// matrix).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged, expecting = "true, false or a share in [0, 1]")]
pub enum ForceShare {
    /// All (1) or nothing (0).
    Whole(bool),
    /// The consistent matrix's share β.
    Share(f64),
}

impl Default for ForceShare {
    fn default() -> Self {
        Self::Whole(false)
    }
}

impl ForceShare {
    /// β.
    pub fn share(self) -> f64 {
        match self {
            Self::Whole(whole) => f64::from(u8::from(whole)),
            Self::Share(beta) => beta,
        }
    }
}

impl MassSpec {
    /// The engine's setting (β outside [0, 1] is refused by the engine, by name).
    pub fn matrix(spec: Option<Self>) -> umls_engine::MassMatrix {
        spec.map_or(umls_engine::MassMatrix::Lumped, |m| {
            umls_engine::MassMatrix::Consistent {
                iterations: m.iterations,
                forces: m.forces.share(),
            }
        })
    }
}

fn default_alpha() -> f64 {
    0.99
}

impl Default for TransferSpec {
    fn default() -> Self {
        Self {
            kind: TransferKind::default(),
            alpha: default_alpha(),
            mass: None,
        }
    }
}

/// `[time]`: exactly one of `dt` and `cfl`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Fixed time step (shortened so that the run ends exactly at `end_time`).
    pub dt: Option<f64>,
    /// Time step as a fraction of the CFL limit h / c.
    pub cfl: Option<f64>,
    /// Stress update scheme (default USL).
    #[serde(default)]
    pub stress_update: StressUpdateSpec,
    /// Recompute Δt = cfl · h / (c + |v|_max) before every step (needs `cfl`; `dt`, if
    /// also given, is the largest step).
    #[serde(default)]
    pub adaptive: bool,
    /// The guard: the largest wave Courant number Δt (c + |v|_max) / h a step may take
    /// before the run stops (default 1; `inf` switches it off, for a kernel whose stable
    /// step exceeds the spacing's estimate).
    pub max_wave_courant: Option<f64>,
}

/// `[output]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Particle frames written over the run, the initial state included (default 50).
    pub frames: Option<usize>,
    /// Time between particle frames (instead of `frames`).
    pub interval: Option<f64>,
    /// Points whose nearest particles are followed in `history.csv` (their displacement).
    #[serde(default)]
    pub probes: Vec<Vec<f64>>,
    /// A direction (scene frame) along which the body's front advance is reported: the
    /// farthest particle at the end against the farthest at the start (a run-out).
    pub front: Option<Vec<f64>>,
    /// The body's top surface at the end, as heights in bins along a direction.
    pub profile: Option<ProfileSpec>,
    /// Write diagnostics to `history.csv` every this many steps (default 1).
    #[serde(default = "default_history_every")]
    pub history_every: usize,
    /// VTK data arrays (default binary).
    #[serde(default)]
    pub encoding: EncodingSpec,
}

fn default_history_every() -> usize {
    1
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            probes: Vec::new(),
            front: None,
            profile: None,
            frames: None,
            interval: None,
            history_every: default_history_every(),
            encoding: EncodingSpec::default(),
        }
    }
}

/// `[[materials]]`: `model` selects the variant, and each variant accepts only its own
/// keys, so `yield_stress` on a linear-elastic material is an error that names the key
/// instead of a silently ignored setting.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "model", rename_all = "kebab-case")]
pub enum MaterialSpec {
    /// Small-strain linear elasticity.
    LinearElastic(SolidSpec),
    /// Compressible neo-Hookean.
    NeoHookean(SolidSpec),
    /// St. Venant–Kirchhoff.
    StVenantKirchhoff(SolidSpec),
    /// Fixed corotated.
    FixedCorotated(SolidSpec),
    /// Weakly compressible (Tait) fluid.
    Fluid(FluidSpec),
    /// Drucker–Prager elastoplasticity (cone fitted to Mohr–Coulomb in plane strain).
    DruckerPrager(DruckerPragerSpec),
    /// von Mises (J2) elastoplasticity with linear hardening.
    VonMises(VonMisesSpec),
}

impl MaterialSpec {
    /// The name bodies refer to.
    pub fn name(&self) -> &str {
        match self {
            Self::LinearElastic(m)
            | Self::NeoHookean(m)
            | Self::StVenantKirchhoff(m)
            | Self::FixedCorotated(m) => &m.name,
            Self::Fluid(m) => &m.name,
            Self::DruckerPrager(m) => &m.name,
            Self::VonMises(m) => &m.name,
        }
    }

    /// Mass density.
    pub fn density(&self) -> f64 {
        match self {
            Self::LinearElastic(m)
            | Self::NeoHookean(m)
            | Self::StVenantKirchhoff(m)
            | Self::FixedCorotated(m) => m.density,
            Self::Fluid(m) => m.density,
            Self::DruckerPrager(m) => m.density,
            Self::VonMises(m) => m.density,
        }
    }
}

/// Keys of the elastic solid models.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolidSpec {
    /// Name bodies refer to.
    pub name: String,
    /// Mass density.
    pub density: f64,
    /// Young's modulus.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

/// Keys of `model = "fluid"`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSpec {
    /// Name bodies refer to.
    pub name: String,
    /// Mass density.
    pub density: f64,
    /// Bulk modulus.
    pub bulk: f64,
    /// Pressure exponent γ (default 7).
    pub gamma: Option<f64>,
}

/// Keys of `model = "drucker-prager"`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DruckerPragerSpec {
    /// Name bodies refer to.
    pub name: String,
    /// Mass density.
    pub density: f64,
    /// Young's modulus.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Cohesion.
    pub cohesion: f64,
    /// Friction angle in degrees.
    pub friction_angle: f64,
    /// Dilatancy angle in degrees (default 0).
    pub dilatancy_angle: Option<f64>,
}

/// Keys of `model = "von-mises"`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VonMisesSpec {
    /// Name bodies refer to.
    pub name: String,
    /// Mass density.
    pub density: f64,
    /// Young's modulus.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Uniaxial yield stress.
    pub yield_stress: f64,
    /// Linear hardening modulus (default 0).
    pub hardening: Option<f64>,
}

/// `time.stress_update`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StressUpdateSpec {
    /// Update stress last.
    #[default]
    Usl,
    /// Modified update stress last (velocities re-mapped before the stress update).
    Musl,
}

impl StressUpdateSpec {
    /// The name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Usl => "usl",
            Self::Musl => "musl",
        }
    }
}

/// `output.encoding`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EncodingSpec {
    /// Base64 binary data arrays.
    #[default]
    Binary,
    /// ASCII data arrays.
    Ascii,
}

/// `mesh.lattice.diagonal` (2D).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DiagonalSpec {
    /// Every square split along its rising diagonal.
    Right,
    /// Every square split along its falling diagonal.
    Left,
    /// Diagonals alternating in a chequerboard.
    #[default]
    Alternating,
    /// Four triangles per square around its centre.
    Crossed,
}

/// `seeding.mesh`: where in each cell particles go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QuadratureSpec {
    /// One particle at the centroid.
    Centroid,
    /// The degree-2 Gauss points.
    Gauss2,
}

/// A velocity component: a number or an expression in x, y, z (and t for references).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum Component {
    /// A constant.
    Number(f64),
    /// An expression such as `"0.1 * sin(PI * x / 50)"`.
    Expression(String),
}

/// Where a body's material is.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub enum RegionSpec {
    /// The whole mesh.
    Everywhere(bool),
    /// An axis-aligned box.
    Box {
        /// Lower corner.
        lower: Vec<f64>,
        /// Upper corner.
        upper: Vec<f64>,
    },
    /// A ball (disk, interval).
    Ball {
        /// Centre.
        centre: Vec<f64>,
        /// Radius.
        radius: f64,
    },
    /// The half-space n·x ≤ offset.
    HalfSpace {
        /// Outward normal.
        normal: Vec<f64>,
        /// Offset.
        offset: f64,
    },
    /// The cells of a physical group of the mesh file (mesh seeding only, not inside a
    /// combination).
    Group(String),
    /// Points in all of these regions.
    Intersection(Vec<RegionSpec>),
    /// Points in any of these regions.
    Union(Vec<RegionSpec>),
    /// Points in the first region and in none of the others.
    Difference(Vec<RegionSpec>),
}

/// How particles are placed.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub enum SeedingSpec {
    /// A regular lattice of this spacing over the mesh's bounding box.
    Lattice(f64),
    /// A regular lattice anchored at a point, independent of the mesh.
    LatticeFrom {
        /// Spacing.
        spacing: f64,
        /// A corner of one lattice cell (its points are the cell centres).
        origin: Vec<f64>,
    },
    /// Quadrature points of the mesh cells.
    Mesh(QuadratureSpec),
}

/// `[[bodies]] jitter`: each lattice-seeded particle moved by a uniform random offset of
/// up to `amount` × spacing / 2 per axis (`amount` in [0, 1]), from `seed`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JitterSpec {
    /// The largest offset per axis as a fraction of half the lattice spacing.
    pub amount: f64,
    /// Seed of the offsets (default 0).
    #[serde(default)]
    pub seed: u64,
}

/// `[[bodies]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Material name.
    pub material: String,
    /// Region (default: everywhere).
    pub region: Option<RegionSpec>,
    /// Seeding.
    pub seeding: SeedingSpec,
    /// Random offsets of lattice-seeded particles within their cells.
    pub jitter: Option<JitterSpec>,
    /// Initial velocity (D components, numbers or expressions in x, y, z); zero if absent.
    pub velocity: Option<Vec<Component>>,
    /// What the particles' affine matrices C_p start from (default zero).
    #[serde(default)]
    pub affine: AffineStartSpec,
}

/// `[[bodies]] affine`: the affine matrices' start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AffineStartSpec {
    /// C_p = 0.
    #[default]
    Zero,
    /// C_p = ∇v of the body's `velocity` field at the particle (central differences).
    VelocityGradient,
}

/// Boundary kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryKind {
    /// Zero velocity.
    Fixed,
    /// Frictionless slip: zero normal velocity.
    Slip,
}

/// A plane through `point` with normal `normal`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// A point on the plane.
    pub point: Vec<f64>,
    /// Its normal (outward for slip).
    pub normal: Vec<f64>,
}

/// `[[boundaries]]`: nodes on a plane, the vertices of a physical group, the nodes in
/// a region, or the surface of an obstacle or a container.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Fixed or slip.
    pub kind: BoundaryKind,
    /// The nodes on this plane.
    pub plane: Option<PlaneSpec>,
    /// The vertices of this physical group (mesh kernels).
    pub group: Option<String>,
    /// The kernel nodes inside this region (any kernel).
    pub region: Option<RegionSpec>,
    /// A wall around a shape the material stays outside of (any kernel): a
    /// signed-distance collider of the region's surface.
    pub obstacle: Option<RegionSpec>,
    /// A wall around a shape the material stays inside of (any kernel): a
    /// signed-distance collider of the region's surface.
    pub container: Option<RegionSpec>,
    /// The prescribed velocity of an obstacle or container (rigid translation, scene
    /// frame; default at rest): a footing pressed into the ground, a penetrator.
    pub velocity: Option<Vec<f64>>,
    /// The wall normal of a slip condition on a region.
    pub normal: Option<Vec<f64>>,
    /// Coulomb's friction coefficient μ of a slip condition (default 0, frictionless):
    /// a node moving into the wall loses that motion and up to μ times as much of its
    /// tangential speed.
    pub friction: Option<f64>,
    /// How a fixed region holds the body: on its nodes (default), on the fit or on its
    /// face.
    pub imposed: Option<Imposed>,
    /// The weight of the face points' residuals against the heaviest node's mass, for
    /// `imposed = "face"` (default `umls_engine::FACE_CLAMP_PENALTY`).
    pub penalty: Option<f64>,
}

/// `imposed` of a fixed region: where the zero velocity is imposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Imposed {
    /// Every kernel node inside the region is at rest (a staircase of whole cells).
    Nodes,
    /// The region's nodes take the velocities under which the particles inside the
    /// region neither move nor deform (velocity and velocity gradient zero there), in the
    /// mass-weighted least-squares sense (`umls_engine::FittedClamp`): the clamp ends
    /// where those particles end.
    Fit,
    /// The velocity vanishes on the region's face, where the body crosses its boundary,
    /// by the least mass-weighted change of the nodes around it; the region's other nodes
    /// are at rest (`umls_engine::FaceClamp`): the clamp's edge is the face, whatever the
    /// node layout.
    Face,
}

/// `[reference]`: an analytic velocity field v(X, t) or displacement u(X, t) at the
/// particles' initial positions X, or the hydrostatic stress of a column at rest under
/// gravity (at least one).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// D expressions in x, y, z (initial position) and t.
    pub velocity: Option<Vec<Component>>,
    /// Velocity scale the RMSE is divided by (default: the largest |v(X, 0)|).
    pub scale: Option<f64>,
    /// When after a step `velocity` is evaluated (default: at the step's end).
    #[serde(default)]
    pub velocity_time: VelocityTimeSpec,
    /// The column's exact stress at the end of the run.
    pub hydrostatic: Option<HydrostaticSpec>,
    /// D expressions in x, y, z (initial position) and t: the exact displacement.
    pub displacement: Option<Vec<Component>>,
    /// A stored displacement history of one of `[output] probes`.
    pub probe: Option<ProbeReferenceSpec>,
    /// The pressure on a closed wall, from its reaction forces.
    pub pressure: Option<PressureSpec>,
}

/// `reference.velocity_time`: the time a step's particle velocities are compared at.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum VelocityTimeSpec {
    /// t_{n+1}, the time the step ends at.
    #[default]
    End,
    /// t_{n+1} − Δt/2. The step is symplectic Euler: the velocities it gives are the
    /// leapfrog's half-step velocities, a second-order approximation of v at the step's
    /// midpoint and only a first-order one at its end. Second order from the start when
    /// the initial acceleration vanishes (a body starting undeformed, at rest or moving).
    MidStep,
}

/// `[reference.pressure]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSpec {
    /// Index into `[[boundaries]]` of the wall.
    pub boundary: usize,
    /// The point the wall is around (scene frame), for the angular bins.
    pub centre: Vec<f64>,
    /// The wall's area (length in 2D).
    pub area: f64,
}

/// `[reference.probe]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeReferenceSpec {
    /// CSV file (relative to the scene file): a header line, then `time, u_x, u_y[, u_z]`.
    pub file: String,
    /// Index into `[output] probes` (default 0).
    #[serde(default)]
    pub probe: usize,
}

/// `[reference.hydrostatic]`: a laterally confined elastic column at rest under gravity.
/// Levels are heights along −g in the scene frame (before `[transform]`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HydrostaticSpec {
    /// Level of the free surface.
    pub surface: f64,
    /// Level of the base.
    pub base: f64,
    /// Particles within this distance of the surface or the base are not interior
    /// (default: a tenth of the column's height).
    pub margin: Option<f64>,
    /// Thickness of the bottom and top rows (default: the first body's lattice spacing).
    pub row: Option<f64>,
}
