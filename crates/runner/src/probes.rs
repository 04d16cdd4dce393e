//! `[output] probes` and `[reference.probe]`: particles followed through the run (the
//! tip of a cantilever), and their displacement against a stored reference history.
//!
//! A probe is the particle nearest to a point of the scene frame at the start; its
//! displacement, in the scene frame, goes into `history.csv` as `probeK_ux`, `_uy`
//! (`_uz`). A reference history is a CSV file of rows `time, u_x, u_y[, u_z]` (one
//! header line); the run reports the largest distance between the probe's displacement
//! and the reference, linearly interpolated in time, over the largest reference
//! displacement.

use nalgebra::SVector;

use crate::error::Result;
use crate::frame::SceneFrame;
use crate::scene::Scene;

/// The particles followed.
#[derive(Debug, Clone, Default)]
pub struct Probes {
    /// Their indices in the scene.
    particles: Vec<usize>,
    /// Where the simulation stores them (their indices until the particles are sorted).
    slots: Vec<usize>,
}

impl Probes {
    /// The particles nearest to the scene's probe points; `initial` are the particles'
    /// world positions.
    pub fn new<const D: usize>(
        scene: &Scene,
        frame: &SceneFrame<D>,
        initial: &[SVector<f64, D>],
    ) -> Result<Self> {
        let mut particles = Vec::new();
        for (k, point) in scene.spec.output.probes.iter().enumerate() {
            let point: SVector<f64, D> = scene.vector(&format!("output.probes[{k}]"), point)?;
            let world = frame.point_to_world(&point);
            let nearest = initial
                .iter()
                .enumerate()
                .min_by(|a, b| (a.1 - world).norm().total_cmp(&(b.1 - world).norm()))
                .map(|(i, _)| i);
            match nearest {
                Some(i) => particles.push(i),
                None => return Err(scene.value_error("output.probes", "the scene has no particle")),
            }
        }
        Ok(Self {
            slots: particles.clone(),
            particles,
        })
    }

    /// Follows the probes' particles to the slots a sort moved them to: `slot_of[i]` is
    /// where the scene's particle i is stored now.
    pub fn follow(&mut self, slot_of: &[usize]) {
        for (slot, &i) in self.slots.iter_mut().zip(&self.particles) {
            *slot = slot_of[i];
        }
    }

    /// Number of probes.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// The `history.csv` columns.
    pub fn columns(&self, dimension: usize) -> Vec<String> {
        (0..self.len())
            .flat_map(|k| {
                ["x", "y", "z"][..dimension]
                    .iter()
                    .map(move |a| format!("probe{k}_u{a}"))
            })
            .collect()
    }

    /// Displacement of probe `k` in the scene frame; `initial` and `positions` are in
    /// the simulation's storage order.
    pub fn displacement<const D: usize>(
        &self,
        k: usize,
        frame: &SceneFrame<D>,
        initial: &[SVector<f64, D>],
        positions: &[SVector<f64, D>],
    ) -> SVector<f64, D> {
        let i = self.slots[k];
        frame.vector_to_scene(&(positions[i] - initial[i]))
    }
}

/// A stored displacement history of one probe.
#[derive(Debug, Clone)]
pub struct ProbeReference<const D: usize> {
    /// Which probe it is compared with.
    pub probe: usize,
    /// (time, displacement), times increasing.
    rows: Vec<(f64, SVector<f64, D>)>,
    /// The largest reference displacement.
    scale: f64,
}

impl<const D: usize> ProbeReference<D> {
    /// Parses `text` (CSV: one header line, then `time, u_x, …`); `key` names the
    /// scene's key in errors.
    pub fn parse(scene: &Scene, key: &str, text: &str, probe: usize) -> Result<Self> {
        let mut rows: Vec<(f64, SVector<f64, D>)> = Vec::new();
        for (n, line) in text.lines().enumerate().skip(1) {
            if line.trim().is_empty() {
                continue;
            }
            let values: std::result::Result<Vec<f64>, _> =
                line.split(',').map(|v| v.trim().parse::<f64>()).collect();
            let values = match values {
                Ok(v) if v.len() == D + 1 && v.iter().all(|x| x.is_finite()) => v,
                _ => {
                    return Err(scene.value_error(
                        key,
                        format!(
                            "line {}: `{line}` is not {} finite numbers (time and {D} displacement components)",
                            n + 1,
                            D + 1
                        ),
                    ));
                }
            };
            if rows.last().is_some_and(|(t, _)| values[0] <= *t) {
                return Err(scene.value_error(key, format!("line {}: times must increase", n + 1)));
            }
            rows.push((values[0], SVector::from_fn(|k, _| values[k + 1])));
        }
        if rows.len() < 2 {
            return Err(scene.value_error(key, "needs at least two rows after the header"));
        }
        let scale = rows.iter().map(|(_, u)| u.norm()).fold(0.0, f64::max);
        if scale == 0.0 {
            return Err(scene.value_error(key, "the reference displacement is zero throughout"));
        }
        Ok(Self { probe, rows, scale })
    }

    /// The reference at time `t`, if `t` lies within its span.
    pub fn at(&self, t: f64) -> Option<SVector<f64, D>> {
        let after = self.rows.partition_point(|(time, _)| *time < t);
        if after == 0 {
            return (self.rows[0].0 == t).then_some(self.rows[0].1);
        }
        let (t1, u1) = self.rows.get(after)?;
        let (t0, u0) = &self.rows[after - 1];
        let w = (t - t0) / (t1 - t0);
        Some(u0 * (1.0 - w) + u1 * w)
    }

    /// The largest reference displacement.
    pub fn scale(&self) -> f64 {
        self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn reference_interpolates_within_its_span_only() {
        let scene = Scene::parse(crate::builtin::BUILTIN[0].toml, "disks.toml", None).unwrap();
        let r = ProbeReference::<2>::parse(
            &scene,
            "reference.probe.file",
            "t,ux,uy\n0,0,0\n1,0,-2\n3,2,-2\n",
            0,
        )
        .unwrap();
        assert_eq!(r.at(0.0), Some(Vector2::new(0.0, 0.0)));
        assert_eq!(r.at(0.5), Some(Vector2::new(0.0, -1.0)));
        assert_eq!(r.at(2.0), Some(Vector2::new(1.0, -2.0)));
        assert_eq!(r.at(3.0), Some(Vector2::new(2.0, -2.0)));
        assert_eq!(r.at(3.5), None);
        assert!((r.scale() - 8f64.sqrt()).abs() < 1e-15);
        let e = ProbeReference::<2>::parse(&scene, "k", "t,u\n0,1,2\n0,1,2\n", 0).unwrap_err();
        assert!(e.to_string().contains("line 3: times must increase"), "{e}");
        let e = ProbeReference::<2>::parse(&scene, "k", "t,u\n0,1\n", 0).unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
    }
}
