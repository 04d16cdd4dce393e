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
    /// Interior vertex jitter as a fraction of the cell size (0 to 0.2).
    #[serde(default)]
    pub jitter: f64,
    /// Seed of the jitter.
    #[serde(default)]
    pub seed: u64,
    /// Triangle diagonals (2D): "right", "left", "alternating", "crossed".
    pub diagonal: Option<String>,
}

/// Kernel names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum KernelKind {
    /// C¹ UMLS kernel on the mesh (linear basis).
    #[default]
    Umls,
    /// Linear finite-element shape functions on the mesh.
    LinearFe,
    /// Quadratic B-splines on a Cartesian grid covering the mesh.
    Bspline2,
    /// Cubic B-splines on a Cartesian grid covering the mesh.
    Bspline3,
}

impl KernelKind {
    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            KernelKind::Umls => "umls",
            KernelKind::LinearFe => "linear-fe",
            KernelKind::Bspline2 => "bspline2",
            KernelKind::Bspline3 => "bspline3",
        }
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
    /// Affine transfer with C = ∇v.
    VelocityGradient,
}

/// `[transfer]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferSpec {
    /// Which scheme (default `flip`).
    #[serde(default)]
    pub kind: TransferKind,
    /// FLIP fraction (default 0.99).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
}

fn default_alpha() -> f64 {
    0.99
}

impl Default for TransferSpec {
    fn default() -> Self {
        Self {
            kind: TransferKind::default(),
            alpha: default_alpha(),
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
    /// "usl" (default) or "musl".
    pub stress_update: Option<String>,
    /// Recompute Δt = cfl · h / (c + |v|_max) before every step (needs `cfl`; `dt`, if
    /// also given, is the largest step).
    #[serde(default)]
    pub adaptive: bool,
}

/// `[output]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Particle frames written over the run, the initial state included (default 50).
    pub frames: Option<usize>,
    /// Time between particle frames (instead of `frames`).
    pub interval: Option<f64>,
    /// Write diagnostics to `history.csv` every this many steps (default 1).
    #[serde(default = "default_history_every")]
    pub history_every: usize,
    /// "binary" (default) or "ascii" VTK data arrays.
    pub encoding: Option<String>,
}

fn default_history_every() -> usize {
    1
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            frames: None,
            interval: None,
            history_every: default_history_every(),
            encoding: None,
        }
    }
}

/// `[[materials]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name bodies refer to.
    pub name: String,
    /// "linear-elastic", "neo-hookean", "st-venant-kirchhoff", "fixed-corotated",
    /// "fluid", "drucker-prager", "von-mises".
    pub model: String,
    /// Density.
    pub density: f64,
    /// Young's modulus (solids).
    pub young: Option<f64>,
    /// Poisson's ratio (solids).
    pub poisson: Option<f64>,
    /// Bulk modulus (fluid).
    pub bulk: Option<f64>,
    /// Pressure exponent γ (fluid, default 7).
    pub gamma: Option<f64>,
    /// Cohesion (Drucker–Prager).
    pub cohesion: Option<f64>,
    /// Friction angle in degrees (Drucker–Prager).
    pub friction_angle: Option<f64>,
    /// Dilatancy angle in degrees (Drucker–Prager, default 0).
    pub dilatancy_angle: Option<f64>,
    /// Uniaxial yield stress (von Mises).
    pub yield_stress: Option<f64>,
    /// Linear hardening modulus (von Mises, default 0).
    pub hardening: Option<f64>,
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
    /// The cells of a physical group of the mesh file (mesh seeding only).
    Group(String),
}

/// How particles are placed.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub enum SeedingSpec {
    /// A regular lattice of this spacing over the mesh's bounding box.
    Lattice(f64),
    /// Quadrature points of the mesh cells: "centroid" or "gauss2".
    Mesh(String),
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
    /// Initial velocity (D components, numbers or expressions in x, y, z); zero if absent.
    pub velocity: Option<Vec<Component>>,
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

/// `[[boundaries]]`: nodes on a plane, or the vertices of a physical group.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Fixed or slip.
    pub kind: BoundaryKind,
    /// The nodes on this plane.
    pub plane: Option<PlaneSpec>,
    /// The vertices of this physical group (mesh kernels).
    pub group: Option<String>,
}

/// `[reference]`: an analytic velocity field v(X, t) at the particles' initial positions X.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// D expressions in x, y, z (initial position) and t.
    pub velocity: Vec<Component>,
    /// Velocity scale the RMSE is divided by (default: the largest |v(X, 0)|).
    pub scale: Option<f64>,
}
