//! From a parsed scene to the pieces of a D-dimensional simulation: mesh, particles,
//! materials, boundary conditions, time step and the optional reference solution.

use std::sync::Arc;

use nalgebra::{SMatrix, SVector};
use umls_constitutive::{
    ConeFit, DruckerPrager, ElasticParameters, ElastoPlastic, FixedCorotated, LinearElastic,
    NeoHookean, StVenantKirchhoff, VonMises, WeaklyCompressibleFluid,
};
use umls_engine::{Damping, Region, StressUpdate, lattice_points};
use umls_io::gmsh::{PhysicalGroup, ReadOptions, parse_msh};
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mesh::{Orientation, SampleRule, SimplexMesh};

use crate::background::Background;
use crate::error::{Result, RunError};
use crate::expression::{Definitions, VectorField};
use crate::frame::SceneFrame;
use crate::hydrostatic::Hydrostatic;
use crate::jitter::Jitter;
use crate::probes::ProbeReference;
use crate::scene::Scene;
use crate::schema::{
    AffineStartSpec, BoundaryKind, DiagonalSpec, ForcePosition, Imposed, MaterialSpec,
    QuadratureSpec, RegionSpec, SeedingSpec, SolidSpec, StressUpdateSpec, TransferKind,
    VelocityTimeSpec,
};
pub use crate::seeds::Seeds;
use umls_constitutive::table::{ElasticModel, Model, PlasticModel};

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

/// Splits a lattice into simplices (segments, triangles with the given diagonals, or
/// tetrahedra); the generator's split exists per dimension, so the caller supplies it.
pub type Split<const D: usize> =
    fn(&Lattice<D>, Diagonal) -> std::result::Result<SimplexMesh<D>, umls_mesh::MeshError>;

/// [`Split`] for D = 1: segments.
pub fn segments(
    l: &Lattice<1>,
    _: Diagonal,
) -> std::result::Result<SimplexMesh<1>, umls_mesh::MeshError> {
    l.segments()
}

/// [`Split`] for D = 2: triangles with the given diagonals.
pub fn triangles(
    l: &Lattice<2>,
    d: Diagonal,
) -> std::result::Result<SimplexMesh<2>, umls_mesh::MeshError> {
    l.triangles(d)
}

/// [`Split`] for D = 3: Kuhn tetrahedra.
pub fn tetrahedra(
    l: &Lattice<3>,
    _: Diagonal,
) -> std::result::Result<SimplexMesh<3>, umls_mesh::MeshError> {
    l.tetrahedra()
}

/// The scene's background; a lattice is split into simplices unless `lean` (a grid
/// kernel, no mesh seeding) says no one will read them.
fn background<const D: usize>(
    scene: &Scene,
    split: Split<D>,
    lean: bool,
) -> Result<(Background<D>, Option<f64>, Vec<PhysicalGroup>)> {
    let spec = &scene.spec.mesh;
    match (&spec.file, &spec.lattice) {
        (Some(file), None) => {
            let options = ReadOptions {
                orientation: if spec.reject_inverted {
                    Orientation::Reject
                } else {
                    Orientation::Fix
                },
            };
            let read = parse_msh::<D>(&scene.mesh_bytes(file)?, options)
                .map_err(|e| scene.value_error("mesh.file", format!("{file}: {e}")))?;
            Ok((Background::Mesh(Arc::new(read.mesh)), None, read.groups))
        }
        (None, Some(l)) => {
            let lower: SVector<f64, D> = scene.vector("mesh.lattice.lower", &l.lower)?;
            let upper: SVector<f64, D> = scene.vector("mesh.lattice.upper", &l.upper)?;
            if l.cells.len() != D {
                return Err(scene.value_error("mesh.lattice.cells", format!("needs {D} counts")));
            }
            let cells: [usize; D] = std::array::from_fn(|k| l.cells[k]);
            let total = cells.iter().map(|&n| n as f64).product::<f64>();
            if total > MAX_LATTICE_POINTS {
                return Err(scene.value_error(
                    "mesh.lattice.cells",
                    format!("{total:.3e} cells (limit {MAX_LATTICE_POINTS:.0e})"),
                ));
            }
            let spacing = (0..D)
                .map(|k| (upper[k] - lower[k]) / cells[k].max(1) as f64)
                .fold(f64::INFINITY, f64::min);
            let lattice = Lattice::new(lower.into(), upper.into(), cells).jitter(l.jitter, l.seed);
            if l.diagonal.is_some() && D != 2 {
                return Err(
                    scene.value_error("mesh.lattice.diagonal", "only 2D lattices have diagonals")
                );
            }
            let diagonal = match l.diagonal.unwrap_or_default() {
                DiagonalSpec::Alternating => Diagonal::Alternating,
                DiagonalSpec::Right => Diagonal::Right,
                DiagonalSpec::Left => Diagonal::Left,
                DiagonalSpec::Crossed => Diagonal::Crossed,
            };
            if lean {
                if (0..D).any(|k| upper[k] <= lower[k]) {
                    return Err(scene.value_error(
                        "mesh.lattice",
                        "`upper` must exceed `lower` in every component",
                    ));
                }
                let frame = SceneFrame::default();
                return Ok((
                    Background::Box {
                        lower,
                        upper,
                        frame,
                    },
                    Some(spacing),
                    Vec::new(),
                ));
            }
            let mesh = split(&lattice, diagonal)
                .map_err(|e| scene.value_error("mesh.lattice", e.to_string()))?;
            Ok((Background::Mesh(Arc::new(mesh)), Some(spacing), Vec::new()))
        }
        _ => Err(scene.value_error("mesh", "give exactly one of `file` and `lattice`")),
    }
}

fn material(scene: &Scene, index: usize) -> Result<Model<PlasticModel>> {
    let spec = &scene.spec.materials[index];
    let key = |field: &str| format!("materials[{index}].{field}");
    // The key of the parameter the model rejected, with angles shown in the degrees the
    // file gives them in.
    let bad = |e: umls_constitutive::ConstitutiveError| match e {
        umls_constitutive::ConstitutiveError::InvalidParameter {
            parameter,
            value,
            reason,
        } => {
            let (field, value) = match parameter {
                "E (Young's modulus)" => ("young", value),
                "ν (Poisson's ratio)" => ("poisson", value),
                "cohesion" => ("cohesion", value),
                "friction angle (rad)" => ("friction_angle", value.to_degrees()),
                "dilatancy angle (rad)" => ("dilatancy_angle", value.to_degrees()),
                "yield stress" => ("yield_stress", value),
                "hardening modulus" => ("hardening", value),
                "K (bulk modulus)" => ("bulk", value),
                "γ (exponent)" => ("gamma", value),
                other => (other, value),
            };
            let reason = reason
                .replace("[0, π/2)", "[0°, 90°)")
                .replace("[0, friction angle]", "[0°, friction_angle]");
            scene.value_error(key(field), format!("{value}: {reason}"))
        }
        other => scene.value_error(key("model"), other.to_string()),
    };
    let density = spec.density();
    if !(density.is_finite() && density > 0.0) {
        return Err(scene.value_error(key("density"), "must be finite and positive"));
    }
    let elastic = |young: f64, poisson: f64| {
        ElasticParameters::from_young_poisson(young, poisson).map_err(bad)
    };
    let solid = |m: &SolidSpec| elastic(m.young, m.poisson);
    Ok(match spec {
        MaterialSpec::LinearElastic(m) => Model::Elastic(ElasticModel::Linear(LinearElastic {
            parameters: solid(m)?,
        })),
        MaterialSpec::NeoHookean(m) => Model::Elastic(ElasticModel::NeoHookean(NeoHookean {
            parameters: solid(m)?,
        })),
        MaterialSpec::StVenantKirchhoff(m) => {
            Model::Elastic(ElasticModel::StVenantKirchhoff(StVenantKirchhoff {
                parameters: solid(m)?,
            }))
        }
        MaterialSpec::FixedCorotated(m) => {
            Model::Elastic(ElasticModel::Corotated(FixedCorotated {
                parameters: solid(m)?,
            }))
        }
        MaterialSpec::Fluid(m) => Model::Elastic(ElasticModel::Fluid(
            WeaklyCompressibleFluid::new(m.bulk, m.gamma.unwrap_or(7.0)).map_err(bad)?,
        )),
        MaterialSpec::DruckerPrager(m) => {
            let criterion = DruckerPrager::from_mohr_coulomb(
                m.cohesion,
                m.friction_angle.to_radians(),
                m.dilatancy_angle.unwrap_or(0.0).to_radians(),
                ConeFit::PlaneStrain,
            )
            .map_err(bad)?;
            Model::Plastic(PlasticModel::DruckerPrager(ElastoPlastic::new(
                elastic(m.young, m.poisson)?,
                criterion,
            )))
        }
        MaterialSpec::VonMises(m) => {
            let criterion =
                VonMises::new(m.yield_stress, m.hardening.unwrap_or(0.0)).map_err(bad)?;
            Model::Plastic(PlasticModel::VonMises(ElastoPlastic::new(
                elastic(m.young, m.poisson)?,
                criterion,
            )))
        }
    })
}

fn group<'a>(
    scene: &Scene,
    groups: &'a [PhysicalGroup],
    key: &str,
    name: &str,
) -> Result<&'a PhysicalGroup> {
    groups.iter().find(|g| g.name == name).ok_or_else(|| {
        let known: Vec<&str> = groups.iter().map(|g| g.name.as_str()).collect();
        scene.value_error(
            key,
            if known.is_empty() {
                format!("no physical group `{name}`: the mesh has none (only Gmsh files do)")
            } else {
                format!(
                    "no physical group `{name}` (the mesh has: {})",
                    known.join(", ")
                )
            },
        )
    })
}

/// A region of the file (not a physical group) at `key`.
pub(crate) fn region<const D: usize>(
    scene: &Scene,
    key: &str,
    spec: &RegionSpec,
) -> Result<Region<D>> {
    let parts = |name: &str, list: &[RegionSpec]| -> Result<Vec<Region<D>>> {
        if list.is_empty() {
            return Err(scene.value_error(format!("{key}.{name}"), "lists no region"));
        }
        list.iter()
            .enumerate()
            .map(|(i, r)| region(scene, &format!("{key}.{name}[{i}]"), r))
            .collect()
    };
    Ok(match spec {
        RegionSpec::Everywhere(true) => Region::Everywhere,
        RegionSpec::Everywhere(false) => {
            return Err(scene.value_error(
                format!("{key}.everywhere"),
                "`false` selects nothing; omit the region instead",
            ));
        }
        RegionSpec::Box { lower, upper } => Region::Box {
            lower: scene.vector(&format!("{key}.box.lower"), lower)?,
            upper: scene.vector(&format!("{key}.box.upper"), upper)?,
        },
        RegionSpec::Ball { centre, radius } => Region::Ball {
            centre: scene.vector(&format!("{key}.ball.centre"), centre)?,
            radius: *radius,
        },
        RegionSpec::HalfSpace { normal, offset } => Region::HalfSpace {
            normal: scene.vector(&format!("{key}.half-space.normal"), normal)?,
            offset: *offset,
        },
        RegionSpec::Group(_) => {
            return Err(scene.value_error(
                format!("{key}.group"),
                "a physical group can only be a body's whole region",
            ));
        }
        RegionSpec::Intersection(list) => Region::Intersection(parts("intersection", list)?),
        RegionSpec::Union(list) => Region::Union(parts("union", list)?),
        RegionSpec::Difference(list) => Region::Difference(parts("difference", list)?),
    })
}

/// A point's or vector's components as "a, b, c", for messages.
fn listed<const D: usize>(u: &SVector<f64, D>) -> String {
    u.iter()
        .map(|c| format!("{c}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// ∇v of `field` at `x` (entry (j, k) = ∂v_j/∂x_k) by fourth-order central differences
/// with step 10⁻³ `spacing` (the particle's own spacing): truncation of order
/// (10⁻³ spacing / λ)⁴ for a field varying on a length λ, round-off of order
/// 10⁻¹³ λ / spacing, relative to the gradient. Exact for polynomials of degree ≤ 4.
fn velocity_gradient<const D: usize>(
    field: &VectorField<D>,
    x: &SVector<f64, D>,
    spacing: f64,
) -> std::result::Result<SMatrix<f64, D, D>, String> {
    let step = 1e-3 * spacing;
    let mut gradient = SMatrix::<f64, D, D>::zeros();
    for k in 0..D {
        let at = |offset: f64| {
            let mut y = *x;
            y[k] += offset * step;
            field.eval(&y, 0.0)
        };
        let column = (at(-2.0)? - at(2.0)? + (at(1.0)? - at(-1.0)?) * 8.0) / (12.0 * step);
        if !column.iter().all(|c| c.is_finite()) {
            return Err(format!(
                "has no finite gradient at the particle ({}) for `affine = \"velocity-gradient\"`",
                listed(x)
            ));
        }
        gradient.set_column(k, &column);
    }
    Ok(gradient)
}

fn seed_body<const D: usize>(
    scene: &Scene,
    index: usize,
    background: &Background<D>,
    groups: &[PhysicalGroup],
    material: u16,
    definitions: &Definitions,
    seeds: &mut Seeds<D>,
) -> Result<Option<String>> {
    let body = &scene.spec.bodies[index];
    let key = |field: &str| format!("bodies[{index}].{field}");
    let density = scene.spec.materials[material as usize].density();
    let mut cells: Option<&[u32]> = None;
    let region: Region<D> = match &body.region {
        None => Region::Everywhere,
        Some(RegionSpec::Group(name)) => {
            let g = group(scene, groups, &key("region.group"), name)?;
            if g.dimension != D {
                return Err(scene.value_error(
                    key("region.group"),
                    format!(
                        "`{name}` is a {}D group; a body needs {D}D cells",
                        g.dimension
                    ),
                ));
            }
            cells = Some(&g.cells);
            Region::Everywhere
        }
        Some(spec) => region(scene, &key("region"), spec)?,
    };
    let samples: Vec<(SVector<f64, D>, f64)> = match &body.seeding {
        SeedingSpec::LatticeFrom { spacing: h, origin } => {
            if cells.is_some() {
                return Err(scene.value_error(
                    key("seeding"),
                    "a group region needs mesh seeding (`centroid` or `gauss2`)",
                ));
            }
            if !(h.is_finite() && *h > 0.0) {
                return Err(
                    scene.value_error(key("seeding.lattice-from.spacing"), "must be positive")
                );
            }
            let origin: SVector<f64, D> =
                scene.vector(&key("seeding.lattice-from.origin"), origin)?;
            let (lower, upper) = background.bounding_box();
            // Whole cells of the anchored lattice that meet the background's box.
            let first = SVector::<f64, D>::from_fn(|k, _| ((lower[k] - origin[k]) / h).floor());
            let last = SVector::<f64, D>::from_fn(|k, _| ((upper[k] - origin[k]) / h).ceil());
            let count: f64 = (last - first).iter().product();
            if count.is_nan() || count > MAX_LATTICE_POINTS {
                return Err(scene.value_error(
                    key("seeding.lattice-from.spacing"),
                    format!("spacing {h} puts {count:.3e} lattice points over the mesh (limit {MAX_LATTICE_POINTS:.0e})"),
                ));
            }
            let corner = origin + first * *h;
            // Only the body's points are kept: the box's whole lattice never exists.
            lattice_points(corner, origin + last * *h, *h)
                .filter(|(x, _)| region.contains(x) && background.contains(x))
                .collect()
        }
        SeedingSpec::Lattice(h) => {
            if cells.is_some() {
                return Err(scene.value_error(
                    key("seeding"),
                    "a group region needs mesh seeding (`centroid` or `gauss2`)",
                ));
            }
            if !(h.is_finite() && *h > 0.0) {
                return Err(scene.value_error(key("seeding.lattice"), "spacing must be positive"));
            }
            let (lower, upper) = background.bounding_box();
            let count: f64 = (0..D)
                .map(|k| ((upper[k] - lower[k]) / h).round().max(1.0))
                .product();
            if count > MAX_LATTICE_POINTS {
                return Err(scene.value_error(
                    key("seeding.lattice"),
                    format!("spacing {h} puts {count:.3e} lattice points over the mesh (limit {MAX_LATTICE_POINTS:.0e})"),
                ));
            }
            // Lattice points over the bounding box; those outside the mesh itself (a
            // non-convex Gmsh domain) would stop the run at its first step.
            lattice_points(lower, upper, *h)
                .filter(|(x, _)| region.contains(x) && background.contains(x))
                .collect()
        }
        SeedingSpec::Mesh(rule) => {
            let rule = match rule {
                QuadratureSpec::Centroid => SampleRule::Centroid,
                QuadratureSpec::Gauss2 => SampleRule::Gauss2,
            };
            let Some(mesh) = background.mesh() else {
                return Err(scene.value_error(key("seeding"), "mesh seeding needs the mesh"));
            };
            let all = mesh.sample_points(rule);
            match cells {
                None => all,
                Some(cells) => {
                    let per = rule.count(D);
                    cells
                        .iter()
                        .flat_map(|&c| {
                            all[c as usize * per..(c as usize + 1) * per]
                                .iter()
                                .copied()
                        })
                        .collect()
                }
            }
        }
    };
    let velocity = match &body.velocity {
        None => None,
        Some(components) => Some(
            VectorField::<D>::compile(components, false, definitions)
                .map_err(|reason| scene.value_error(key("velocity"), reason))?,
        ),
    };
    if body.affine == AffineStartSpec::VelocityGradient {
        if velocity.is_none() {
            return Err(scene.value_error(
                key("affine"),
                "starts C_p at the gradient of `velocity`, which is not given",
            ));
        }
        if matches!(
            scene.spec.transfer.kind,
            TransferKind::Pic | TransferKind::Flip
        ) {
            return Err(scene.value_error(
                key("affine"),
                "sets the affine matrices, which `transfer.kind` (pic or flip) does not carry",
            ));
        }
    }
    let jitter = match (&body.jitter, &body.seeding) {
        (None, _) => None,
        (Some(_), SeedingSpec::Mesh(_)) => {
            return Err(scene.value_error(
                key("jitter"),
                "moves lattice-seeded particles; mesh seeding has no lattice",
            ));
        }
        (Some(j), SeedingSpec::Lattice(h) | SeedingSpec::LatticeFrom { spacing: h, .. }) => {
            if !(0.0..=1.0).contains(&j.amount) {
                return Err(scene.value_error(
                    key("jitter.amount"),
                    format!("is {}; it must be in [0, 1]", j.amount),
                ));
            }
            Some(Jitter::new(j.amount, *h, j.seed))
        }
    };
    let before = seeds.position.len();
    for (i, (x, volume)) in samples
        .iter()
        .filter(|(x, _)| region.contains(x))
        .enumerate()
    {
        // Membership was decided at the cell centre; a jittered point the background
        // does not contain (a non-convex mesh's edge) stays at the centre.
        let jittered = jitter.map(|j| x + j.offset::<D>(i));
        let x = match &jittered {
            Some(y) if background.contains(y) => y,
            _ => x,
        };
        let v = match &velocity {
            None => SVector::zeros(),
            Some(field) => field
                .eval(x, 0.0)
                .map_err(|reason| scene.value_error(key("velocity"), reason))?,
        };
        // An infinite or undefined velocity (1/0, or 1/(x − a) at a particle on x = a)
        // would poison the whole run.
        if !v.iter().all(|c| c.is_finite()) {
            return Err(scene.value_error(
                key("velocity"),
                format!(
                    "is ({}) at the particle ({}): not finite",
                    listed(&v),
                    listed(x)
                ),
            ));
        }
        seeds.position.push(*x);
        seeds.volume.push(*volume);
        seeds.mass.push(volume * density);
        seeds.velocity.push(v);
        seeds.affine.push(match (&velocity, body.affine) {
            (Some(field), AffineStartSpec::VelocityGradient) => {
                velocity_gradient(field, x, volume.powf(1.0 / D as f64))
                    .map_err(|reason| scene.value_error(key("velocity"), reason))?
            }
            _ => SMatrix::zeros(),
        });
        seeds.material.push(material);
        seeds.body.push(index as u32);
    }
    if seeds.position.len() == before {
        return Err(scene.value_error(key("region"), "the region holds no particle"));
    }
    // A box or ball partly outside the mesh is clipped to it: say so.
    let expected = match &region {
        Region::Box { lower, upper } => Some((upper - lower).iter().product::<f64>()),
        Region::Ball { radius, .. } => Some(match D {
            1 => 2.0 * radius,
            2 => std::f64::consts::PI * radius * radius,
            _ => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
        }),
        _ => None,
    };
    let seeded: f64 = seeds.volume[before..].iter().sum();
    Ok(expected.filter(|v| seeded < 0.9 * v).map(|v| {
        format!(
            "bodies[{index}]: the region's volume is {v:.4}, its particles fill {seeded:.4} ({:.0} %): part of it lies outside the mesh and was left out",
            100.0 * seeded / v
        )
    }))
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
    let spec = &scene.spec;
    let lean = grid_kernel
        && spec.bodies.iter().all(|b| {
            matches!(
                b.seeding,
                SeedingSpec::Lattice(_) | SeedingSpec::LatticeFrom { .. }
            )
        })
        && spec.mesh.transform.is_none();
    let (mut background, lattice_spacing, groups) = background::<D>(scene, split, lean)?;
    if spec.mesh.transform.is_some() {
        let turn =
            SceneFrame::<D>::from_spec(scene, "mesh.transform", spec.mesh.transform.as_ref())?;
        if let Background::Mesh(mesh) = &background {
            background = Background::Mesh(Arc::new(
                turn.mesh_to_world(mesh)
                    .map_err(|e| scene.value_error("mesh.transform", e.to_string()))?,
            ));
        }
    }
    let definitions = Definitions::compile(&spec.definitions).map_err(|(name, reason)| {
        scene.value_error(
            if name.is_empty() {
                "definitions".to_string()
            } else {
                format!("definitions.{name}")
            },
            reason,
        )
    })?;
    if spec.materials.is_empty() {
        return Err(scene.value_error("materials", "at least one material is needed"));
    }
    let mut warnings = Vec::new();
    if spec.materials.len() > usize::from(u16::MAX) {
        return Err(scene.value_error("materials", "too many materials"));
    }
    let models = (0..spec.materials.len())
        .map(|i| material(scene, i))
        .collect::<Result<Vec<_>>>()?;
    let material_names: Vec<String> = spec
        .materials
        .iter()
        .map(|m| m.name().to_string())
        .collect();
    if spec.bodies.is_empty() {
        return Err(scene.value_error("bodies", "at least one body is needed"));
    }
    let mut seeds = Seeds::default();
    for (i, body) in spec.bodies.iter().enumerate() {
        let material = material_names
            .iter()
            .position(|n| *n == body.material)
            .ok_or_else(|| {
                scene.value_error(
                    format!("bodies[{i}].material"),
                    format!(
                        "no material `{}` (defined: {})",
                        body.material,
                        material_names.join(", ")
                    ),
                )
            })?;
        warnings.extend(seed_body(
            scene,
            i,
            &background,
            &groups,
            material as u16,
            &definitions,
            &mut seeds,
        )?);
    }
    let mut boundaries = Vec::new();
    for (i, b) in spec.boundaries.iter().enumerate() {
        if b.imposed.is_some() && b.region.is_none() {
            return Err(scene.value_error(
                format!("boundaries[{i}].imposed"),
                "only a `region` condition takes `imposed`",
            ));
        }
        if b.penalty.is_some() && b.imposed != Some(Imposed::Face) {
            return Err(scene.value_error(
                format!("boundaries[{i}].penalty"),
                "weighs a clamp held on its face: give it with imposed = \"face\"",
            ));
        }
        if b.normal.is_some() && b.region.is_none() {
            return Err(scene.value_error(
                format!("boundaries[{i}].normal"),
                "only a `region` condition takes a normal (a plane has its own)",
            ));
        }
        let target = match (&b.plane, &b.group, &b.region) {
            (None, None, Some(spec)) => {
                let normal = match (&b.normal, b.kind) {
                    (None, BoundaryKind::Fixed) => None,
                    (Some(n), BoundaryKind::Slip) => {
                        let n: SVector<f64, D> =
                            scene.vector(&format!("boundaries[{i}].normal"), n)?;
                        if n.norm() == 0.0 {
                            return Err(scene.value_error(
                                format!("boundaries[{i}].normal"),
                                "must not be zero",
                            ));
                        }
                        Some(n.normalize())
                    }
                    (None, BoundaryKind::Slip) => {
                        return Err(scene.value_error(
                            format!("boundaries[{i}].normal"),
                            "a slip condition on a region needs the wall's normal",
                        ));
                    }
                    (Some(_), BoundaryKind::Fixed) => {
                        return Err(scene.value_error(
                            format!("boundaries[{i}].normal"),
                            "a fixed condition takes no normal",
                        ));
                    }
                };
                let imposed = match (b.imposed, b.kind) {
                    (None | Some(Imposed::Nodes), _) => Imposed::Nodes,
                    (Some(imposed), BoundaryKind::Fixed) => imposed,
                    (Some(_), BoundaryKind::Slip) => {
                        return Err(scene.value_error(
                            format!("boundaries[{i}].imposed"),
                            "only a fixed region can be imposed on the fit or its face",
                        ));
                    }
                };
                // Given only with imposed = "face" (checked above).
                let penalty = match b.penalty {
                    Some(w) if !(w.is_finite() && w > 0.0) => {
                        return Err(scene.value_error(
                            format!("boundaries[{i}].penalty"),
                            "must be finite and positive",
                        ));
                    }
                    w => w,
                };
                BoundaryTarget::Region {
                    region: region(scene, &format!("boundaries[{i}].region"), spec)?,
                    normal,
                    imposed,
                    penalty,
                }
            }
            (Some(plane), None, None) => {
                let normal: SVector<f64, D> =
                    scene.vector(&format!("boundaries[{i}].plane.normal"), &plane.normal)?;
                if normal.norm() == 0.0 {
                    return Err(scene
                        .value_error(format!("boundaries[{i}].plane.normal"), "must not be zero"));
                }
                BoundaryTarget::Plane {
                    point: scene.vector(&format!("boundaries[{i}].plane.point"), &plane.point)?,
                    normal: normal.normalize(),
                }
            }
            (None, Some(name), None) => {
                let g = group(scene, &groups, &format!("boundaries[{i}].group"), name)?;
                let Some(mesh) = background.mesh() else {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].group"),
                        "a group needs the mesh it belongs to",
                    ));
                };
                BoundaryTarget::Vertices(
                    g.vertices
                        .iter()
                        .map(|&v| (v, mesh.topology().vertex_normal(v as usize)))
                        .collect(),
                )
            }
            _ => {
                return Err(scene.value_error(
                    format!("boundaries[{i}]"),
                    "give exactly one of `plane`, `group` and `region`",
                ));
            }
        };
        boundaries.push((b.kind, target));
    }
    let gravity: SVector<f64, D> = match &spec.scene.gravity {
        None => SVector::zeros(),
        Some(g) => scene.vector("scene.gravity", g)?,
    };
    let stress_update = match spec.time.stress_update {
        StressUpdateSpec::Usl => StressUpdate::Usl,
        StressUpdateSpec::Musl => StressUpdate::Musl,
    };
    let gravity_ramp = spec.scene.gravity_ramp.unwrap_or(0.0);
    if !(gravity_ramp.is_finite() && gravity_ramp >= 0.0) {
        return Err(scene.value_error("scene.gravity_ramp", "must be finite and non-negative"));
    }
    let damping = match &spec.damping {
        None => Damping::None,
        Some(d) => match (d.local, d.mass) {
            (Some(alpha), None) if (0.0..1.0).contains(&alpha) => Damping::Local { alpha },
            (Some(_), None) => return Err(scene.value_error("damping.local", "must lie in [0, 1)")),
            (None, Some(beta)) if beta.is_finite() && beta >= 0.0 => {
                Damping::MassProportional { beta }
            }
            (None, Some(_)) => {
                return Err(scene.value_error("damping.mass", "must be finite and non-negative"));
            }
            _ => return Err(scene.value_error("damping", "give exactly one of `local` and `mass`")),
        },
    };
    let geostatic_k0 = match &spec.initial_stress {
        None => None,
        Some(i) if !(i.geostatic_k0.is_finite() && i.geostatic_k0 >= 0.0) => {
            return Err(scene.value_error(
                "initial_stress.geostatic_k0",
                "must be finite and non-negative",
            ));
        }
        Some(_) if gravity.norm() == 0.0 => {
            return Err(scene.value_error(
                "initial_stress.geostatic_k0",
                "a geostatic stress needs `scene.gravity`",
            ));
        }
        Some(i) => Some(i.geostatic_k0),
    };
    let reference = match spec.reference.as_ref().and_then(|r| r.velocity.as_ref()) {
        None => None,
        Some(velocity) => {
            let field = VectorField::<D>::compile(velocity, true, &definitions)
                .map_err(|reason| scene.value_error("reference.velocity", reason))?;
            let scale = match spec.reference.as_ref().and_then(|r| r.scale) {
                Some(s) if s.is_finite() && s > 0.0 => s,
                Some(_) => return Err(scene.value_error("reference.scale", "must be positive")),
                None => {
                    let mut largest = 0.0f64;
                    for x in &seeds.position {
                        let v = field
                            .eval(x, 0.0)
                            .map_err(|reason| scene.value_error("reference.velocity", reason))?;
                        largest = largest.max(v.norm());
                    }
                    if largest == 0.0 {
                        return Err(scene.value_error(
                            "reference.scale",
                            "the reference velocity is zero at t = 0; give a scale",
                        ));
                    }
                    largest
                }
            };
            let mid_step = spec
                .reference
                .as_ref()
                .is_some_and(|r| r.velocity_time == VelocityTimeSpec::MidStep);
            Some(VelocityReference {
                field,
                scale,
                mid_step,
            })
        }
    };
    if spec
        .reference
        .as_ref()
        .is_some_and(|r| r.velocity.is_none() && r.velocity_time != VelocityTimeSpec::End)
    {
        return Err(scene.value_error(
            "reference.velocity_time",
            "times `reference.velocity`, which is not given",
        ));
    }
    let hydrostatic = match spec.reference.as_ref() {
        Some(r)
            if r.velocity.is_none()
                && r.hydrostatic.is_none()
                && r.displacement.is_none()
                && r.probe.is_none()
                && r.pressure.is_none() =>
        {
            return Err(scene.value_error(
                "reference",
                "give at least one of `velocity`, `displacement`, `hydrostatic`, `probe` and `pressure`",
            ));
        }
        Some(r) if r.velocity.is_none() && r.scale.is_some() => {
            return Err(scene.value_error(
                "reference.scale",
                "scales `reference.velocity`, which is not given",
            ));
        }
        Some(r) => match &r.hydrostatic {
            Some(h) => Some(Hydrostatic::new(scene, h, &gravity, &seeds)?),
            None => None,
        },
        None => None,
    };
    let displacement = match spec
        .reference
        .as_ref()
        .and_then(|r| r.displacement.as_ref())
    {
        None => None,
        Some(u) => Some(
            VectorField::<D>::compile(u, true, &definitions)
                .map_err(|reason| scene.value_error("reference.displacement", reason))?,
        ),
    };
    let body_force = match &spec.body_force {
        None => None,
        Some(b) => {
            let field = VectorField::<D>::compile(&b.acceleration, true, &definitions)
                .map_err(|reason| scene.value_error("body_force.acceleration", reason))?;
            // A field that is not finite where the particles start would poison the run.
            for x in &seeds.position {
                let value = field
                    .eval(x, 0.0)
                    .map_err(|reason| scene.value_error("body_force.acceleration", reason))?;
                if !value.iter().all(|c| c.is_finite()) {
                    return Err(scene.value_error(
                        "body_force.acceleration",
                        format!("is not finite at the particle {:?} at t = 0", x.as_slice()),
                    ));
                }
            }
            Some((field, b.position))
        }
    };
    let probe_reference = match spec.reference.as_ref().and_then(|r| r.probe.as_ref()) {
        None => None,
        Some(p) => {
            let probes = spec.output.probes.len();
            if p.probe >= probes {
                return Err(scene.value_error(
                    "reference.probe.probe",
                    format!(
                        "{} is not a probe (`output.probes` lists {probes})",
                        p.probe
                    ),
                ));
            }
            let bytes = scene.file_bytes("reference.probe.file", &p.file)?;
            let text = String::from_utf8_lossy(&bytes);
            Some(ProbeReference::parse(
                scene,
                "reference.probe.file",
                &text,
                p.probe,
            )?)
        }
    };
    let frame = SceneFrame::<D>::from_scene(scene)?;
    let pressure = match spec.reference.as_ref().and_then(|r| r.pressure.as_ref()) {
        None => None,
        Some(p) => {
            if p.boundary >= spec.boundaries.len() {
                return Err(scene.value_error(
                    "reference.pressure.boundary",
                    format!(
                        "{} is not a boundary (`boundaries` lists {})",
                        p.boundary,
                        spec.boundaries.len()
                    ),
                ));
            }
            if !(p.area.is_finite() && p.area > 0.0) {
                return Err(scene.value_error("reference.pressure.area", "must be positive"));
            }
            let centre: SVector<f64, D> = scene.vector("reference.pressure.centre", &p.centre)?;
            Some((p.boundary, frame.point_to_world(&centre), p.area))
        }
    };
    let mut gravity = gravity;
    if !frame.is_identity() {
        background = match background {
            Background::Mesh(mesh) => Background::Mesh(Arc::new(
                frame
                    .mesh_to_world(&mesh)
                    .map_err(|e| scene.value_error("transform", e.to_string()))?,
            )),
            Background::Box { lower, upper, .. } => Background::Box {
                lower,
                upper,
                frame,
            },
        };
        gravity = frame.vector_to_world(&gravity);
        for x in &mut seeds.position {
            *x = frame.point_to_world(x);
        }
        for v in &mut seeds.velocity {
            *v = frame.vector_to_world(v);
        }
        for c in &mut seeds.affine {
            *c = frame.tensor_to_world(c);
        }
        for (_, target) in &mut boundaries {
            match target {
                BoundaryTarget::Plane { point, normal } => {
                    *point = frame.point_to_world(point);
                    *normal = frame.vector_to_world(normal);
                }
                BoundaryTarget::Vertices(vertices) => {
                    for (_, normal) in vertices {
                        *normal = frame.vector_to_world(normal);
                    }
                }
                BoundaryTarget::Region { normal, .. } => {
                    if let Some(n) = normal {
                        *n = frame.vector_to_world(n);
                    }
                }
            }
        }
    }
    Ok(Setup {
        background,
        lattice_spacing,
        groups,
        seeds,
        models,
        material_names,
        boundaries,
        gravity,
        stress_update,
        gravity_ramp,
        damping,
        geostatic_k0,
        warnings,
        reference,
        hydrostatic,
        displacement,
        probe_reference,
        pressure,
        body_force,
        frame,
    })
}

/// Checks shared by every dimension before any work: end time, time step, output counts.
pub fn check_header(scene: &Scene) -> Result<()> {
    let spec = &scene.spec;
    if !(spec.scene.end_time.is_finite() && spec.scene.end_time > 0.0) {
        return Err(scene.value_error("scene.end_time", "must be finite and positive"));
    }
    let dt_ok = |dt: f64| dt.is_finite() && dt > 0.0;
    let cfl_ok = |cfl: f64| cfl.is_finite() && cfl > 0.0 && cfl <= 1.0;
    match (spec.time.dt, spec.time.cfl, spec.time.adaptive) {
        (Some(dt), None, false) if dt_ok(dt) => {}
        (None, Some(cfl), _) if cfl_ok(cfl) => {}
        (Some(dt), Some(cfl), true) if dt_ok(dt) && cfl_ok(cfl) => {}
        (Some(dt), _, _) if !dt_ok(dt) => {
            return Err(scene.value_error("time.dt", "must be finite and positive"));
        }
        (_, Some(cfl), _) if !cfl_ok(cfl) => {
            return Err(scene.value_error("time.cfl", "must be in (0, 1]"));
        }
        (_, None, true) => {
            return Err(scene.value_error("time.adaptive", "an adaptive time step needs `cfl`"));
        }
        _ => {
            return Err(scene.value_error(
                "time",
                "give exactly one of `dt` and `cfl` (both only with `adaptive = true`)",
            ));
        }
    }
    match (spec.output.frames, spec.output.interval) {
        (Some(_), Some(_)) => {
            return Err(scene.value_error("output", "give at most one of `frames` and `interval`"));
        }
        (Some(n), None) if n < 2 => {
            return Err(
                scene.value_error("output.frames", "at least 2 (the first and the last state)")
            );
        }
        (None, Some(i)) if !(i.is_finite() && i > 0.0) => {
            return Err(scene.value_error("output.interval", "must be finite and positive"));
        }
        _ => {}
    }
    if spec.output.history_every == 0 {
        return Err(scene.value_error("output.history_every", "must be at least 1"));
    }
    if !(0.0..=1.0).contains(&spec.transfer.alpha) {
        return Err(scene.value_error("transfer.alpha", "must be in [0, 1]"));
    }
    if !(1..=3).contains(&spec.scene.dimension) {
        return Err(scene.value_error("scene.dimension", "must be 1, 2 or 3"));
    }
    Ok(())
}

/// Default number of particle frames.
pub const DEFAULT_FRAMES: usize = 50;

/// Particle frames over a run ending at `end_time`: `frames`, or one per `interval`
/// (the initial state included).
pub fn frame_count(scene: &Scene, end_time: f64) -> usize {
    match (scene.spec.output.frames, scene.spec.output.interval) {
        (Some(n), _) => n,
        (None, Some(i)) => ((end_time / i).round().max(1.0) as usize) + 1,
        (None, None) => DEFAULT_FRAMES,
    }
}

/// The error for a scene that is plastic in 1D.
pub fn plastic_in_1d(scene: &Scene) -> RunError {
    scene.value_error(
        "materials",
        "plastic models need dimension 2 (plane strain) or 3",
    )
}
