//! From a parsed scene to the pieces of a D-dimensional simulation, one concern per
//! module: the background mesh, the materials, the bodies' particles, the boundary
//! conditions, the loads, the references, and the turn into the world frame.

mod bodies;
mod boundaries;
mod header;
mod loads;
mod materials;
mod mesh;
mod references;
mod regions;
mod world;

use nalgebra::SVector;
use umls_constitutive::table::{Model, PlasticModel};
use umls_engine::{Damping, Region, StressUpdate};
use umls_io::gmsh::PhysicalGroup;

use crate::background::Background;
use crate::error::Result;
use crate::expression::{Definitions, VectorField};
use crate::frame::SceneFrame;
use crate::hydrostatic::Hydrostatic;
use crate::probes::ProbeReference;
use crate::scene::Scene;
use crate::schema::{BoundaryKind, ForcePosition, Imposed};
pub use crate::seeds::Seeds;

pub use header::{DEFAULT_FRAMES, check_header, frame_count, plastic_in_1d};
pub use mesh::{Split, segments, tetrahedra, triangles};

/// Most lattice points a seeding may generate before filtering by region, and most cells
/// of a generated lattice mesh: a typo in a spacing or count should be an error, not an
/// exhausted memory (2·10⁷ tetrahedra already take several GB). Larger runs use the
/// library directly.
pub const MAX_LATTICE_POINTS: f64 = 2e7;

/// A boundary condition resolved to geometry.
#[derive(Debug, Clone)]
pub enum BoundaryTarget<const D: usize> {
    /// Nodes on the plane through `point` with unit `normal`.
    Plane {
        /// Point on the plane.
        point: SVector<f64, D>,
        /// Unit normal.
        normal: SVector<f64, D>,
    },
    /// These mesh vertices (with their outward normals, for slip).
    Vertices(Vec<(u32, SVector<f64, D>)>),
    /// The surface of a region of the scene frame as a wall: the material stays inside
    /// it (a container) or outside it (an obstacle).
    Shape {
        /// The region, in the scene's own frame.
        region: Region<D>,
        /// Whether the material is inside the region.
        inside: bool,
        /// Its velocity, scene frame (zero: at rest).
        velocity: SVector<f64, D>,
    },
    /// The kernel's nodes inside a region of the scene frame (a clamp that need not
    /// conform to the mesh), with the wall normal of a slip condition (world frame).
    Region {
        /// The region, in the scene's own frame.
        region: Region<D>,
        /// Unit normal (slip only).
        normal: Option<SVector<f64, D>>,
        /// How a fixed region holds the body: on its nodes, on the fit at the particles
        /// inside it, or on its face (`Nodes` for slip).
        imposed: Imposed,
        /// The face clamp's penalty (`imposed = "face"` only).
        penalty: Option<f64>,
    },
}

/// Everything a D-dimensional run needs besides the kernel, material and transfer types.
#[derive(Debug, Clone)]
pub struct Setup<const D: usize> {
    /// The background: a mesh, or the box of a lattice no kernel reads as simplices.
    pub background: Background<D>,
    /// Cell size of a lattice mesh (B-spline grids default to it).
    pub lattice_spacing: Option<f64>,
    /// Physical groups of a file mesh.
    pub groups: Vec<PhysicalGroup>,
    /// The particles.
    pub seeds: Seeds<D>,
    /// Material models, by index.
    pub models: Vec<Model<PlasticModel>>,
    /// Material names, by index.
    pub material_names: Vec<String>,
    /// Boundary conditions.
    pub boundaries: Vec<(BoundaryKind, BoundaryTarget<D>)>,
    /// Gravity.
    pub gravity: SVector<f64, D>,
    /// USL or MUSL.
    pub stress_update: StressUpdate,
    /// Gravity ramp time (0: none).
    pub gravity_ramp: f64,
    /// Damping of the nodal forces.
    pub damping: Damping,
    /// Geostatic K0, if the particles start with their geostatic stress.
    pub geostatic_k0: Option<f64>,
    /// What the user should hear about the setup (a body clipped by the mesh, …).
    pub warnings: Vec<String>,
    /// The analytic velocity v(X, t) (scene frame), the scale its RMSE is divided by,
    /// and whether it is compared half a step before a step's end.
    pub reference: Option<VelocityReference<D>>,
    /// The hydrostatic column's closed form (scene frame).
    pub hydrostatic: Option<Hydrostatic<D>>,
    /// The exact displacement u(X, t) (scene frame).
    pub displacement: Option<VectorField<D>>,
    /// A stored displacement history of one probe (scene frame).
    pub probe_reference: Option<ProbeReference<D>>,
    /// The wall whose pressure is measured: boundary index, centre (world), area.
    pub pressure: Option<(usize, SVector<f64, D>, f64)>,
    /// The body acceleration b(x, t) (scene frame), added to gravity, and whether x is
    /// the particle's current or its reference position.
    pub body_force: Option<(VectorField<D>, ForcePosition)>,
    /// The rotation from the scene as written into the world it runs in; everything
    /// above except the references is already in the world frame.
    pub frame: SceneFrame<D>,
}

/// `[reference] velocity`, compiled.
#[derive(Debug, Clone)]
pub struct VelocityReference<const D: usize> {
    /// v(X, t) in the scene frame.
    pub field: VectorField<D>,
    /// The scale the RMSE is divided by.
    pub scale: f64,
    /// Compare at t_{n+1} − Δt/2 (`velocity_time = "mid-step"`) instead of t_{n+1}.
    pub mid_step: bool,
}

impl<const D: usize> Setup<D> {
    /// Whether any material is plastic.
    pub fn has_plasticity(&self) -> bool {
        self.models.iter().any(|m| matches!(m, Model::Plastic(_)))
    }
}

/// Builds the D-dimensional setup of `scene`, with its mesh.
pub fn build<const D: usize>(scene: &Scene, split: Split<D>) -> Result<Setup<D>> {
    build_for(scene, split, false)
}

/// Builds the D-dimensional setup of `scene`; `grid_kernel` says the run's kernel reads
/// only the background's box, so a `[mesh.lattice]` is not split into simplices unless a
/// body is seeded at mesh quadrature points.
pub fn build_for<const D: usize>(
    scene: &Scene,
    split: Split<D>,
    grid_kernel: bool,
) -> Result<Setup<D>> {
    let (background, lattice_spacing, groups) = mesh::mesh_for::<D>(scene, split, grid_kernel)?;
    let definitions = definitions(scene)?;
    let (models, material_names) = materials::materials(scene)?;
    let (mut seeds, warnings) =
        bodies::seed_bodies(scene, &background, &groups, &material_names, &definitions)?;
    let mut boundaries = boundaries::boundaries(scene, &groups, &background)?;
    let loads = loads::loads::<D>(scene)?;
    let frame = SceneFrame::<D>::from_scene(scene)?;
    let references = references::references(scene, &definitions, &loads.gravity, &seeds, &frame)?;
    let body_force = loads::body_force(scene, &definitions, &seeds.position)?;
    let (background, gravity) = world::Geometry {
        background,
        gravity: loads.gravity,
        seeds: &mut seeds,
        boundaries: &mut boundaries,
    }
    .into_world(scene, &frame)?;
    Ok(Setup {
        background,
        lattice_spacing,
        groups,
        seeds,
        models,
        material_names,
        boundaries,
        gravity,
        stress_update: loads.stress_update,
        gravity_ramp: loads.gravity_ramp,
        damping: loads.damping,
        geostatic_k0: loads.geostatic_k0,
        warnings,
        reference: references.velocity,
        hydrostatic: references.hydrostatic,
        displacement: references.displacement,
        probe_reference: references.probe,
        pressure: references.pressure,
        body_force,
        frame,
    })
}

/// `[definitions]`, compiled, with errors naming the definition.
fn definitions(scene: &Scene) -> Result<Definitions> {
    Definitions::compile(&scene.spec.definitions).map_err(|(name, reason)| {
        scene.value_error(
            if name.is_empty() {
                "definitions".to_string()
            } else {
                format!("definitions.{name}")
            },
            reason,
        )
    })
}
