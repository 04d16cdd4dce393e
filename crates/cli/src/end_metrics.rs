//! Metrics of a run's end state that the scene asks for: the largest value of each
//! material state scalar, a front's advance, the probes' final displacements, and the
//! hydrostatic column's comparison with its closed form.

use nalgebra::SVector;
use serde_json::{Map, Value, json};

use crate::error::Result;
use crate::probes::Probes;
use crate::run::Run;
use crate::scene::Scene;
use crate::setup::{self, Setup};

/// The end-state metrics of `sim`; `initial` are the particles' initial (world)
/// positions. The column's stresses are not evaluated after a failure.
pub(crate) fn end_state<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    sim: &dyn Run<D>,
    initial: &[SVector<f64, D>],
    probes: &Probes,
    failed: bool,
) -> Result<Map<String, Value>> {
    let mut metrics = Map::new();
    for (name, max) in sim.state_scalar_maxima() {
        metrics.insert(format!("max_{name}"), json!(max));
    }
    if let Some(direction) = &scene.spec.output.front {
        let d: SVector<f64, D> = setup::vector(scene, "output.front", direction)?;
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
    if let (Some(column), false) = (&setup.hydrostatic, failed) {
        let stresses = sim.cauchy_stresses()?;
        metrics.extend(column.metrics(&setup.frame, initial, sim.positions(), &stresses));
    }
    Ok(metrics)
}
