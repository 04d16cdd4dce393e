//! `[[bodies]]`: the particles seeded in each body's region, with their material, initial
//! velocity and affine matrix.

use nalgebra::{SMatrix, SVector};
use umls_engine::{Region, lattice_points};
use umls_io::gmsh::PhysicalGroup;
use umls_mesh::SampleRule;

use super::MAX_LATTICE_POINTS;
use super::regions::{group, listed, region};
use crate::background::Background;
use crate::error::Result;
use crate::expression::{Definitions, VectorField};
use crate::jitter::Jitter;
use crate::scene::Scene;
use crate::schema::{AffineStartSpec, QuadratureSpec, RegionSpec, SeedingSpec, TransferKind};
use crate::seeds::Seeds;

/// Points with their volumes, before the region and the jitter are applied.
type Samples<const D: usize> = Vec<(SVector<f64, D>, f64)>;

/// Seeds every body; returns the particles and the warnings about bodies the mesh clips.
pub(super) fn seed_bodies<const D: usize>(
    scene: &Scene,
    background: &Background<D>,
    groups: &[PhysicalGroup],
    material_names: &[String],
    definitions: &Definitions,
) -> Result<(Seeds<D>, Vec<String>)> {
    let spec = &scene.spec;
    if spec.bodies.is_empty() {
        return Err(scene.value_error("bodies", "at least one body is needed"));
    }
    let mut seeds = Seeds::default();
    let mut warnings = Vec::new();
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
        let body = Body {
            scene,
            index: i,
            background,
            material: material as u16,
        };
        warnings.extend(body.seed(groups, definitions, &mut seeds)?);
    }
    Ok((seeds, warnings))
}

/// One body being seeded: where it is in the file, and what it is seeded into.
struct Body<'a, const D: usize> {
    scene: &'a Scene,
    index: usize,
    background: &'a Background<D>,
    material: u16,
}

impl<const D: usize> Body<'_, D> {
    fn key(&self, field: &str) -> String {
        format!("bodies[{}].{field}", self.index)
    }

    /// Appends the body's particles to `seeds`; returns a warning if the mesh clips it.
    fn seed(
        &self,
        groups: &[PhysicalGroup],
        definitions: &Definitions,
        seeds: &mut Seeds<D>,
    ) -> Result<Option<String>> {
        let scene = self.scene;
        let body = &scene.spec.bodies[self.index];
        let density = scene.spec.materials[self.material as usize].density();
        let (region, cells) = self.region(groups)?;
        let samples = self.samples(&region, cells)?;
        let velocity = self.velocity(definitions)?;
        let jitter = self.jitter()?;
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
                Some(y) if self.background.contains(y) => y,
                _ => x,
            };
            let v = self.velocity_at(velocity.as_ref(), x)?;
            seeds.position.push(*x);
            seeds.volume.push(*volume);
            seeds.mass.push(volume * density);
            seeds.velocity.push(v);
            seeds.affine.push(match (&velocity, body.affine) {
                (Some(field), AffineStartSpec::VelocityGradient) => {
                    velocity_gradient(field, x, volume.powf(1.0 / D as f64))
                        .map_err(|reason| scene.value_error(self.key("velocity"), reason))?
                }
                _ => SMatrix::zeros(),
            });
            seeds.material.push(self.material);
            seeds.body.push(self.index as u32);
        }
        if seeds.position.len() == before {
            return Err(scene.value_error(self.key("region"), "the region holds no particle"));
        }
        Ok(self.clipped(&region, &seeds.volume[before..]))
    }

    /// The body's region, and the cells of the physical group it names, if any (the
    /// group's cells are the region then).
    fn region<'g>(&self, groups: &'g [PhysicalGroup]) -> Result<(Region<D>, Option<&'g [u32]>)> {
        let scene = self.scene;
        match &scene.spec.bodies[self.index].region {
            None => Ok((Region::Everywhere, None)),
            Some(RegionSpec::Group(name)) => {
                let g = group(scene, groups, &self.key("region.group"), name)?;
                if g.dimension != D {
                    return Err(scene.value_error(
                        self.key("region.group"),
                        format!(
                            "`{name}` is a {}D group; a body needs {D}D cells",
                            g.dimension
                        ),
                    ));
                }
                Ok((Region::Everywhere, Some(&g.cells)))
            }
            Some(spec) => Ok((region(scene, &self.key("region"), spec)?, None)),
        }
    }

    /// The seeding's points and volumes: a lattice (anchored or over the background's
    /// box) or the mesh's quadrature points, of a group's cells if `cells` is given.
    fn samples(&self, region: &Region<D>, cells: Option<&[u32]>) -> Result<Samples<D>> {
        let scene = self.scene;
        let seeding = &scene.spec.bodies[self.index].seeding;
        let h = match seeding {
            SeedingSpec::Mesh(rule) => return self.mesh_samples(*rule, cells),
            SeedingSpec::Lattice(h) | SeedingSpec::LatticeFrom { spacing: h, .. } => *h,
        };
        if cells.is_some() {
            return Err(scene.value_error(
                self.key("seeding"),
                "a group region needs mesh seeding (`centroid` or `gauss2`)",
            ));
        }
        let background = self.background;
        let (lower, upper) = background.bounding_box();
        let (key, first, last, count) = match seeding {
            SeedingSpec::LatticeFrom { origin, .. } => {
                if !(h.is_finite() && h > 0.0) {
                    return Err(scene.value_error(
                        self.key("seeding.lattice-from.spacing"),
                        "must be positive",
                    ));
                }
                let origin: SVector<f64, D> =
                    scene.vector(&self.key("seeding.lattice-from.origin"), origin)?;
                // Whole cells of the anchored lattice that meet the background's box.
                let first = SVector::<f64, D>::from_fn(|k, _| ((lower[k] - origin[k]) / h).floor());
                let last = SVector::<f64, D>::from_fn(|k, _| ((upper[k] - origin[k]) / h).ceil());
                let count: f64 = (last - first).iter().product();
                let key = self.key("seeding.lattice-from.spacing");
                (key, origin + first * h, origin + last * h, count)
            }
            _ => {
                if !(h.is_finite() && h > 0.0) {
                    return Err(
                        scene.value_error(self.key("seeding.lattice"), "spacing must be positive")
                    );
                }
                let count: f64 = (0..D)
                    .map(|k| ((upper[k] - lower[k]) / h).round().max(1.0))
                    .product();
                (self.key("seeding.lattice"), lower, upper, count)
            }
        };
        if count.is_nan() || count > MAX_LATTICE_POINTS {
            return Err(scene.value_error(
                key,
                format!("spacing {h} puts {count:.3e} lattice points over the mesh (limit {MAX_LATTICE_POINTS:.0e})"),
            ));
        }
        // Only the body's points are kept, and only those inside the background itself
        // (a point outside a non-convex Gmsh domain would stop the run at its first
        // step): the box's whole lattice never exists.
        Ok(lattice_points(first, last, h)
            .filter(|(x, _)| region.contains(x) && background.contains(x))
            .collect())
    }

    fn mesh_samples(&self, rule: QuadratureSpec, cells: Option<&[u32]>) -> Result<Samples<D>> {
        let rule = match rule {
            QuadratureSpec::Centroid => SampleRule::Centroid,
            QuadratureSpec::Gauss2 => SampleRule::Gauss2,
        };
        let Some(mesh) = self.background.mesh() else {
            return Err(self
                .scene
                .value_error(self.key("seeding"), "mesh seeding needs the mesh"));
        };
        let all = mesh.sample_points(rule);
        Ok(match cells {
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
        })
    }

    /// The compiled initial velocity, checked against the body's `affine` start.
    fn velocity(&self, definitions: &Definitions) -> Result<Option<VectorField<D>>> {
        let scene = self.scene;
        let body = &scene.spec.bodies[self.index];
        let velocity = match &body.velocity {
            None => None,
            Some(components) => Some(
                VectorField::<D>::compile(components, false, definitions)
                    .map_err(|reason| scene.value_error(self.key("velocity"), reason))?,
            ),
        };
        if body.affine == AffineStartSpec::VelocityGradient {
            if velocity.is_none() {
                return Err(scene.value_error(
                    self.key("affine"),
                    "starts C_p at the gradient of `velocity`, which is not given",
                ));
            }
            if matches!(
                scene.spec.transfer.kind,
                TransferKind::Pic | TransferKind::Flip
            ) {
                return Err(scene.value_error(
                    self.key("affine"),
                    "sets the affine matrices, which `transfer.kind` (pic or flip) does not carry",
                ));
            }
        }
        Ok(velocity)
    }

    /// The initial velocity at `x`, which must be finite: an infinite or undefined one
    /// (1/0, or 1/(x − a) at a particle on x = a) would poison the whole run.
    fn velocity_at(
        &self,
        velocity: Option<&VectorField<D>>,
        x: &SVector<f64, D>,
    ) -> Result<SVector<f64, D>> {
        let Some(field) = velocity else {
            return Ok(SVector::zeros());
        };
        let error = |reason: String| self.scene.value_error(self.key("velocity"), reason);
        let v = field.eval(x, 0.0).map_err(error)?;
        if !v.iter().all(|c| c.is_finite()) {
            return Err(error(format!(
                "is ({}) at the particle ({}): not finite",
                listed(&v),
                listed(x)
            )));
        }
        Ok(v)
    }

    /// The lattice jitter, which only lattice seedings take.
    fn jitter(&self) -> Result<Option<Jitter>> {
        let body = &self.scene.spec.bodies[self.index];
        match (&body.jitter, &body.seeding) {
            (None, _) => Ok(None),
            (Some(_), SeedingSpec::Mesh(_)) => Err(self.scene.value_error(
                self.key("jitter"),
                "moves lattice-seeded particles; mesh seeding has no lattice",
            )),
            (Some(j), SeedingSpec::Lattice(h) | SeedingSpec::LatticeFrom { spacing: h, .. }) => {
                if !(0.0..=1.0).contains(&j.amount) {
                    return Err(self.scene.value_error(
                        self.key("jitter.amount"),
                        format!("is {}; it must be in [0, 1]", j.amount),
                    ));
                }
                Ok(Some(Jitter::new(j.amount, *h, j.seed)))
            }
        }
    }

    /// A warning if a box or ball partly outside the mesh was clipped to it.
    fn clipped(&self, region: &Region<D>, volumes: &[f64]) -> Option<String> {
        let expected = match region {
            Region::Box { lower, upper } => (upper - lower).iter().product::<f64>(),
            Region::Ball { radius, .. } => match D {
                1 => 2.0 * radius,
                2 => std::f64::consts::PI * radius * radius,
                _ => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
            },
            _ => return None,
        };
        let seeded: f64 = volumes.iter().sum();
        (seeded < 0.9 * expected).then(|| {
            format!(
                "bodies[{}]: the region's volume is {expected:.4}, its particles fill {seeded:.4} ({:.0} %): part of it lies outside the mesh and was left out",
                self.index,
                100.0 * seeded / expected
            )
        })
    }
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
