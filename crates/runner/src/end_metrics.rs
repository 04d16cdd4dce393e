//! Metrics of a run's end state that the scene asks for: the largest value of each
//! material state scalar, each body's bulk motion where there are several, a front's
//! advance, the probes' final displacements, the particles found beyond a mesh group's
//! wall, and the hydrostatic column's comparison with its closed form.

use nalgebra::SVector;
use serde_json::{Map, Value, json};

use crate::error::Result;
use crate::group_wall::GroupWall;
use crate::handle::Run;
use crate::probes::Probes;
use crate::sampled_wall::count_beyond;
use crate::scene::Scene;
use crate::schema::ProfileSpec;
use crate::setup::{BoundaryTarget, Setup};

/// The end-state metrics of `sim`; `initial` are the particles' initial (world)
/// positions, `initial_energy` the run's initial mechanical energy. The column's
/// stresses and the bodies' motion are not evaluated after a failure.
pub(crate) fn end_state<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    sim: &dyn Run<D>,
    initial: &[SVector<f64, D>],
    probes: &Probes,
    failed: bool,
    initial_energy: f64,
) -> Result<Map<String, Value>> {
    let mut metrics = Map::new();
    for (name, max) in sim.state_scalar_maxima() {
        metrics.insert(format!("max_{name}"), json!(max));
    }
    if scene.spec.bodies.len() > 1 && !failed {
        metrics.extend(bodies_in_bulk(
            setup,
            sim,
            scene.spec.bodies.len(),
            initial_energy,
        ));
    }
    if let Some(direction) = &scene.spec.output.front {
        let d: SVector<f64, D> = scene.vector("output.front", direction)?;
        if d.norm() == 0.0 {
            return Err(scene.value_error("output.front", "must not be zero"));
        }
        let d = setup.frame.vector_to_world(&d.normalize());
        let farthest = |xs: &[SVector<f64, D>]| {
            xs.iter()
                .map(|x| x.dot(&d))
                .fold(f64::NEG_INFINITY, f64::max)
        };
        metrics.insert(
            "front_advance".into(),
            json!(farthest(sim.positions()) - farthest(initial)),
        );
    }
    if let Some(profile) = &scene.spec.output.profile {
        metrics.insert(
            "surface_profile".into(),
            surface_profile(scene, setup, sim, profile)?,
        );
    }
    if !probes.is_empty() {
        let finals: Vec<Vec<f64>> = (0..probes.len())
            .map(|k| {
                probes
                    .displacement(k, &setup.frame, initial, sim.positions())
                    .iter()
                    .copied()
                    .collect()
            })
            .collect();
        metrics.insert("probe_displacements".into(), json!(finals));
    }
    if let Some((crossings, depth)) = wall_crossings(setup, sim) {
        metrics.insert("wall_crossings".into(), json!(crossings));
        metrics.insert("max_wall_depth".into(), json!(depth));
    }
    if let (Some(column), false) = (&setup.hydrostatic, failed) {
        let stresses = sim.cauchy_stresses()?;
        metrics.extend(column.metrics(&setup.frame, initial, sim.positions(), &stresses));
    }
    Ok(metrics)
}

/// Each body's bulk motion at the end, for scenes of several bodies: `body_velocities`,
/// the centre-of-mass velocity of each body (scene frame, in `[[bodies]]` order), and
/// `bulk_kinetic_fraction`, the kinetic energy of those bulk motions, Σ_b ½ M_b |V_b|²,
/// over the initial energy (absent when that is zero). After a collision of bodies that
/// started in rigid motion it is the share of the energy that left as bulk motion (for
/// two equal bodies meeting head-on, the restitution squared); the rest of what the
/// run's energy keeps is inside the bodies (ringing, strain).
fn bodies_in_bulk<const D: usize>(
    setup: &Setup<D>,
    sim: &dyn Run<D>,
    bodies: usize,
    initial_energy: f64,
) -> Map<String, Value> {
    let mut mass = vec![0.0; bodies];
    let mut momentum = vec![SVector::<f64, D>::zeros(); bodies];
    for (slot, (m, v)) in sim.masses().iter().zip(sim.velocities()).enumerate() {
        let body = setup.seeds.body[sim.particle_id(slot)] as usize;
        mass[body] += m;
        momentum[body] += v * *m;
    }
    let velocities: Vec<SVector<f64, D>> =
        momentum.iter().zip(&mass).map(|(p, m)| p / *m).collect();
    let bulk: f64 = velocities
        .iter()
        .zip(&mass)
        .map(|(v, m)| 0.5 * m * v.norm_squared())
        .sum();
    let mut metrics = Map::new();
    let listed: Vec<Vec<f64>> = velocities
        .iter()
        .map(|v| setup.frame.vector_to_scene(v).iter().copied().collect())
        .collect();
    metrics.insert("body_velocities".into(), json!(listed));
    if initial_energy > 0.0 {
        metrics.insert("bulk_kinetic_fraction".into(), json!(bulk / initial_energy));
    }
    metrics
}

/// The highest particle (along `up`) in each bin along `along`, scene frame; `null` for
/// an empty bin. Two runs' profiles compare their final surfaces.
fn surface_profile<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    sim: &dyn Run<D>,
    spec: &ProfileSpec,
) -> Result<Value> {
    let along: SVector<f64, D> = scene.vector("output.profile.along", &spec.along)?;
    let up: SVector<f64, D> = scene.vector("output.profile.up", &spec.up)?;
    if along.norm() == 0.0 || up.norm() == 0.0 {
        return Err(scene.value_error("output.profile", "`along` and `up` must not be zero"));
    }
    if !(spec.start.is_finite() && spec.end.is_finite() && spec.end > spec.start) {
        return Err(scene.value_error("output.profile.end", "must exceed `start`"));
    }
    if spec.bins == 0 || spec.bins > 100_000 {
        return Err(scene.value_error("output.profile.bins", "must lie in 1..=100000"));
    }
    let (along, up) = (along.normalize(), up.normalize());
    let width = (spec.end - spec.start) / spec.bins as f64;
    let mut heights = vec![f64::NEG_INFINITY; spec.bins];
    for x in sim.positions() {
        let x = setup.frame.point_to_scene(x);
        let bin = ((x.dot(&along) - spec.start) / width).floor();
        if bin >= 0.0 && (bin as usize) < spec.bins {
            let h = &mut heights[bin as usize];
            *h = h.max(x.dot(&up));
        }
    }
    let centres: Vec<f64> = (0..spec.bins)
        .map(|k| spec.start + (k as f64 + 0.5) * width)
        .collect();
    let heights: Vec<Option<f64>> = heights
        .into_iter()
        .map(|h| h.is_finite().then_some(h))
        .collect();
    Ok(json!({ "centres": centres, "heights": heights }))
}

/// Particles beyond a wall of a mesh group or a shape (obstacle, container) at the end,
/// for any kernel: how many lie beyond one by more than 1 % of the kernel spacing
/// (`wall_crossings`), and the deepest one's depth in kernel spacings (`max_wall_depth`).
/// `None` for scenes without such a wall. A mesh kernel holds its particles on the mesh,
/// a grid kernel, and any kernel at a shape, through a collider; a particle found beyond
/// went through the wall.
fn wall_crossings<const D: usize>(setup: &Setup<D>, sim: &dyn Run<D>) -> Option<(usize, f64)> {
    let spacing = sim.spacing();
    let tolerance = 0.01 * spacing;
    let mut found: Option<(usize, f64)> = None;
    let mut add = |(count, depth): (usize, f64)| {
        let (total, deepest) = found.unwrap_or((0, 0.0));
        found = Some((total + count, f64::max(deepest, depth / spacing)));
    };
    for (_, target) in &setup.boundaries {
        match target {
            BoundaryTarget::Vertices(vertices) => {
                let Some(mesh) = setup.background.mesh() else {
                    continue;
                };
                let ids: Vec<u32> = vertices.iter().map(|(v, _)| *v).collect();
                // A group without boundary facets was refused when the condition was
                // applied.
                if let Ok(wall) = GroupWall::new(mesh, &ids) {
                    add(wall.beyond(sim.positions(), tolerance));
                }
            }
            BoundaryTarget::Shape {
                region,
                inside,
                velocity,
            } => {
                let sign = if *inside { 1.0 } else { -1.0 };
                // Where a moving shape stands now (scene frame).
                let moved = velocity * sim.time();
                let distances = sim.positions().iter().filter_map(|x| {
                    region
                        .signed_distance(&(setup.frame.point_to_scene(x) - moved))
                        .map(|d| sign * d)
                });
                add(count_beyond(distances, tolerance));
            }
            _ => {}
        }
    }
    found
}
