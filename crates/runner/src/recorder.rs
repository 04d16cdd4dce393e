//! The observers of a run: the history (`history.csv` and the report's rows), the error
//! against the scene's reference, the probes, the measured wall's pressure and the
//! energy accounting, sampled after each step or at each history row, and the end
//! metrics they add up to.

use nalgebra::SVector;
use serde_json::{Map, Value, json};
use umls_engine::Diagnostics;
use umls_io::csv::HistoryWriter;

use crate::context::{Context, History};
use crate::end_metrics;
use crate::error::Result;
use crate::handle::Run;
use crate::output::OutputDir;
use crate::plot::EnergyRecord;
use crate::pressure::WallPressure;
use crate::probes::Probes;
use crate::reference;

/// The measured wall: its pressure record, where its reactions start among all
/// reaction-set nodes, and its nodes' positions.
type MeasuredWall<const D: usize> = (WallPressure<D>, usize, Vec<SVector<f64, D>>);

/// What the observers keep between steps.
pub(crate) struct Recorder<'a, const D: usize> {
    ctx: &'a Context<'a, D>,
    file: Option<HistoryWriter>,
    history: History,
    probes: Probes,
    wall: Option<MeasuredWall<D>>,
    /// Where each stored particle started: the seeds, in the simulation's storage order
    /// (which a particle sort changes; [`Recorder::after_step`]).
    reference_positions: Vec<SVector<f64, D>>,
    sorts: usize,
    energies: Vec<EnergyRecord>,
    /// The last velocity error against the reference (sampled every step).
    error: Option<f64>,
    error_sum: f64,
    error_max: f64,
    displacement_errors: Vec<f64>,
    probe_error: f64,
    energy: EnergyAccount<D>,
}

/// The run's energy accounting: the first and last recorded states and the extremes
/// between them.
#[derive(Default)]
struct EnergyAccount<const D: usize> {
    first: Option<(f64, Diagnostics<D>)>,
    last: Option<(f64, Diagnostics<D>)>,
    /// The largest |E(t) − E(0)|.
    change: f64,
    /// The largest mechanical energy (kinetic + elastic) of the run: the energy error's
    /// scale, meaningful when E(0) is 0 (a body released from rest under gravity).
    scale: f64,
    /// The largest gain E(t) − E(0) alone: energy the scheme created (dissipation is a
    /// loss and does not count), for stability maps.
    gain: f64,
    /// The largest work of the external forces: with the initial mechanical energy, the
    /// energy put in (what the engine's blow-up check compares against).
    max_work: f64,
    /// Whether the run failed: its errors are then on the scale of the energy put in.
    failed: bool,
}

impl<'a, const D: usize> Recorder<'a, D> {
    /// The observers of `ctx`'s scene; `history.csv` is created in `out`.
    pub(crate) fn new(
        ctx: &'a Context<'a, D>,
        sim: &mut dyn Run<D>,
        out: &OutputDir,
    ) -> Result<Self> {
        let setup = &ctx.setup;
        let probes = Probes::new(ctx.scene, &setup.frame, &setup.seeds.position)?;
        let wall = setup.pressure.map(|(boundary, centre, area)| {
            let sets = sim.boundary_mut().reaction_sets.clone();
            let offset: usize = sets[..boundary].iter().map(Vec::len).sum();
            let positions = sim.node_positions();
            let nodes = sets[boundary]
                .iter()
                .map(|&n| positions[n as usize])
                .collect();
            (WallPressure::new(boundary, centre, area), offset, nodes)
        });
        let mut columns =
            history_header(D, setup.reference.is_some(), setup.displacement.is_some());
        columns.extend(probes.columns(D));
        for k in 0..setup.boundaries.len() {
            columns.extend(
                ["x", "y", "z"][..D]
                    .iter()
                    .map(|a| format!("reaction{k}_{a}")),
            );
            columns.push(format!("reaction{k}_magnitude"));
        }
        let file = match out.path("history.csv") {
            Some(path) => {
                let names: Vec<&str> = columns.iter().map(String::as_str).collect();
                Some(HistoryWriter::create(path, &names)?)
            }
            None => None,
        };
        Ok(Self {
            ctx,
            file,
            history: History {
                columns,
                rows: Vec::new(),
            },
            probes,
            wall,
            reference_positions: setup.seeds.position.clone(),
            sorts: sim.particle_sorts(),
            energies: Vec::new(),
            error: None,
            error_sum: 0.0,
            error_max: 0.0,
            displacement_errors: Vec::new(),
            probe_error: 0.0,
            energy: EnergyAccount::default(),
        })
    }

    /// Where each stored particle started, in the storage order.
    pub(crate) fn reference_positions(&self) -> &[SVector<f64, D>] {
        &self.reference_positions
    }

    /// The first history row, with the initial state's reference error.
    pub(crate) fn record_first(&mut self, sim: &dyn Run<D>) -> Result<()> {
        self.error = self.velocity_error(sim)?;
        self.record(sim)
    }

    /// After a step: follows a particle sort, and samples the reference error.
    pub(crate) fn after_step(&mut self, sim: &dyn Run<D>) -> Result<()> {
        if sim.particle_sorts() != self.sorts {
            self.sorts = sim.particle_sorts();
            self.follow_sorted(sim);
        }
        self.error = self.velocity_error(sim)?;
        if let Some(e) = self.error {
            self.error_sum += e * e;
            self.error_max = self.error_max.max(e);
        }
        Ok(())
    }

    /// The row of the state a run stopped in, if it can be evaluated (no reference
    /// error: the state is not a step's end).
    pub(crate) fn record_stop(&mut self, sim: &dyn Run<D>) {
        self.error = None;
        // A failed run's energy errors are on the scale of the energy put in: on the
        // largest mechanical energy, a blow-up would be its own scale, and the error
        // would read below 1 however far the energy ran away.
        self.energy.failed = true;
        let _ = self.record(sim);
    }

    /// One history row.
    pub(crate) fn record(&mut self, sim: &dyn Run<D>) -> Result<()> {
        let (ctx, setup) = (self.ctx, &self.ctx.setup);
        let d = sim.diagnostics()?;
        let (potential, total) = (-d.external_work, d.energy_balance());
        let displacement = reference::displacement_error(
            ctx.scene,
            setup,
            &self.reference_positions,
            sim.positions(),
            sim.time(),
        )?;
        self.displacement_errors.extend(displacement);
        let mut row = history_row(&d, potential, total, self.error);
        row.extend(displacement);
        for k in 0..self.probes.len() {
            let u = self.probes.displacement(
                k,
                &setup.frame,
                &self.reference_positions,
                sim.positions(),
            );
            row.extend(u.iter());
            if let Some(reference) = setup.probe_reference.as_ref().filter(|r| r.probe == k) {
                if let Some(exact) = reference.at(sim.time()) {
                    self.probe_error = self.probe_error.max((u - exact).norm() / reference.scale());
                }
            }
        }
        if let Some((wall, offset, nodes)) = self.wall.as_mut() {
            let all = sim.node_reactions();
            if all.len() >= *offset + nodes.len() {
                wall.record(nodes, &all[*offset..*offset + nodes.len()]);
            }
        }
        // Reactions after the probes, as the header has them.
        let reactions = sim.reactions();
        for k in 0..setup.boundaries.len() {
            let r = reactions.get(k).copied().unwrap_or_default();
            row.extend(r.force.iter());
            row.push(r.magnitude);
        }
        if let Some(file) = self.file.as_mut() {
            file.row(&row)?;
        }
        self.history.rows.push(row);
        self.energies.push(EnergyRecord {
            time: d.time,
            kinetic: d.kinetic,
            elastic: d.elastic,
            potential,
            total,
        });
        self.energy.add(total, d);
        Ok(())
    }

    /// Flushes `history.csv`; the history recorded (the recorder keeps no copy).
    pub(crate) fn finish(&mut self) -> Result<History> {
        if let Some(file) = self.file.as_mut() {
            file.flush()?;
        }
        Ok(std::mem::take(&mut self.history))
    }

    /// `energies.svg`.
    pub(crate) fn energy_plot(&self, out: &OutputDir) -> Result<()> {
        let ctx = self.ctx;
        let Some(path) = out.path("energies.svg") else {
            return Ok(());
        };
        crate::plot::energy_plot(
            &path,
            &format!(
                "{}: energies ({}, {})",
                ctx.scene.spec.scene.name,
                ctx.kernel_name,
                crate::summary::transfer_name(&ctx.scene.spec.transfer)
            ),
            D,
            &self.energies,
            ctx.setup.gravity.norm() > 0.0,
        )
    }

    /// The end metrics: energy and momentum, the reference errors, and the scene's own
    /// (end state, wall pressure, probes).
    pub(crate) fn metrics(&self, sim: &dyn Run<D>, failed: bool) -> Result<Map<String, Value>> {
        let ctx = self.ctx;
        let mut metrics = self.energy.metrics();
        let taken = sim.step_count();
        if ctx.setup.reference.is_some() && taken > 0 {
            metrics.insert(
                "velocity_rmse".into(),
                json!((self.error_sum / taken as f64).sqrt()),
            );
            metrics.insert("velocity_error_max".into(), json!(self.error_max));
        }
        let e0 = self.energy.first.as_ref().map_or(0.0, |(e, _)| *e);
        metrics.extend(end_metrics::end_state(
            ctx.scene,
            &ctx.setup,
            sim,
            &self.reference_positions,
            &self.probes,
            failed,
            e0,
        )?);
        if let Some((wall, _, _)) = &self.wall {
            metrics.extend(wall.metrics());
        }
        if ctx.setup.probe_reference.is_some() {
            metrics.insert("probe_error_max".into(), json!(self.probe_error));
        }
        if let (Some(&last), Some(max)) = (
            self.displacement_errors.last(),
            self.displacement_errors.iter().copied().reduce(f64::max),
        ) {
            metrics.insert("displacement_error_final".into(), json!(last));
            metrics.insert("displacement_error_max".into(), json!(max));
        }
        Ok(metrics)
    }

    fn velocity_error(&self, sim: &dyn Run<D>) -> Result<Option<f64>> {
        reference::velocity_error(
            self.ctx.scene,
            &self.ctx.setup,
            &self.reference_positions,
            sim.velocities(),
            sim.time(),
            if sim.step_count() > 0 {
                sim.last_dt()
            } else {
                0.0
            },
        )
    }

    /// After a particle sort: the seeds' positions in the new storage order, and the
    /// probes' particles where they are stored now.
    fn follow_sorted(&mut self, sim: &dyn Run<D>) {
        let seeds = &self.ctx.setup.seeds.position;
        let mut slot_of = vec![0; seeds.len()];
        for (slot, x) in self.reference_positions.iter_mut().enumerate() {
            let id = sim.particle_id(slot);
            *x = seeds[id];
            slot_of[id] = slot;
        }
        self.probes.follow(&slot_of);
    }
}

impl<const D: usize> EnergyAccount<D> {
    fn add(&mut self, total: f64, d: Diagnostics<D>) {
        self.max_work = self.max_work.max(d.external_work);
        let Some((e0, _)) = self.first else {
            self.scale = d.kinetic + d.elastic;
            self.first = Some((total, d));
            self.last = Some((total, d));
            return;
        };
        self.change = self.change.max((total - e0).abs());
        self.gain = self.gain.max(total - e0);
        self.scale = self.scale.max(d.kinetic + d.elastic);
        self.last = Some((total, d));
    }

    fn metrics(&self) -> Map<String, Value> {
        let mut metrics = Map::new();
        let (Some((e0, d0)), Some((last_total, last))) = (&self.first, &self.last) else {
            return metrics;
        };
        let supplied = d0.kinetic + d0.elastic + self.max_work;
        let scale = if self.failed && supplied > 0.0 {
            supplied
        } else {
            self.scale
        };
        let relative = |e: f64| if scale > 0.0 { e / scale } else { 0.0 };
        metrics.insert("energy_error".into(), json!(relative(self.change)));
        metrics.insert("energy_gain_max".into(), json!(relative(self.gain)));
        metrics.insert(
            "energy_change_final".into(),
            json!(relative(last_total - e0)),
        );
        metrics.insert("initial_energy".into(), json!(e0));
        metrics.insert("final_energy".into(), json!(last_total));
        metrics.insert(
            "momentum_change".into(),
            json!((last.momentum - d0.momentum).norm()),
        );
        metrics.insert("dropped_mass".into(), json!(last.dropped_mass));
        metrics.insert(
            "redistributed_momentum".into(),
            json!(last.redistributed_momentum.norm()),
        );
        metrics.insert("wall_corrections".into(), json!(last.wall_corrections));
        metrics.insert("mass_scaled_nodes".into(), json!(last.mass_scaled_nodes));
        metrics
    }
}

/// Columns of `history.csv`.
fn history_header(dimension: usize, with_reference: bool, with_displacement: bool) -> Vec<String> {
    let mut header: Vec<String> = ["step", "time", "kinetic", "elastic", "potential", "total"]
        .map(String::from)
        .into();
    header.extend(
        ["x", "y", "z"][..dimension]
            .iter()
            .map(|a| format!("momentum_{a}")),
    );
    header.extend(
        [
            "mass",
            "max_speed",
            "courant",
            "dt",
            "wave_courant",
            "dropped_mass",
            "wall_corrections",
            "mass_scaled_nodes",
        ]
        .map(String::from),
    );
    if with_reference {
        header.push("velocity_error".into());
    }
    if with_displacement {
        header.push("displacement_error".into());
    }
    header
}

/// One row of `history.csv`, in the order of [`history_header`].
fn history_row<const D: usize>(
    d: &Diagnostics<D>,
    potential: f64,
    total: f64,
    error: Option<f64>,
) -> Vec<f64> {
    let mut row = vec![
        d.step as f64,
        d.time,
        d.kinetic,
        d.elastic,
        potential,
        total,
    ];
    row.extend(d.momentum.iter());
    row.extend([
        d.mass,
        d.max_speed,
        d.courant,
        d.dt,
        d.wave_courant,
        d.dropped_mass,
        d.wall_corrections as f64,
        d.mass_scaled_nodes as f64,
    ]);
    row.extend(error);
    row
}
