//! The charts of each study, drawn from its records with `umls_io::chart`.

use std::collections::BTreeMap;

use umls_io::chart::{
    Axis, Bar, LineChart, MapCell, MapPanel, Outcome, Series, StackedBars, StatusMap,
};

use crate::matrix::{AccuracyStudy, HistoryStudy, StabilityStudy, ThroughputStudy, value_text};
use crate::record::{Record, STAGES};

/// Records grouped by chart series, in first-seen order.
pub fn by_series<'a>(records: &[&'a Record]) -> Vec<(String, Vec<&'a Record>)> {
    let mut groups: Vec<(String, Vec<&Record>)> = Vec::new();
    for r in records {
        let label = r.series();
        match groups.iter_mut().find(|(l, _)| *l == label) {
            Some((_, group)) => group.push(r),
            None => groups.push((label, vec![r])),
        }
    }
    groups
}

/// The (h, error) points of a series' completed runs.
pub fn convergence_points(study: &AccuracyStudy, runs: &[&Record]) -> Vec<(f64, f64)> {
    runs.iter()
        .filter(|r| r.completed())
        .filter_map(|r| r.metric.map(|e| (study.h / r.refine, e)))
        .collect()
}

/// Error against stepping wall time, one series per kernel (and transfer, variant).
pub fn speed_accuracy(study: &AccuracyStudy, records: &[&Record]) -> LineChart {
    let series = by_series(records)
        .into_iter()
        .map(|(label, runs)| {
            let points = runs
                .iter()
                .filter(|r| r.completed())
                .filter_map(|r| Some((r.step_time_s?, r.metric?)))
                .collect();
            Series::new(label, points).with_markers()
        })
        .collect();
    LineChart {
        title: format!("{}: error against run time", study.common.title),
        x: Axis::log("time in the steps [s] (output excluded)"),
        y: Axis::log(study.metric_label.clone()),
        series,
    }
}

/// Error against cell size, one series per kernel (and transfer, variant).
pub fn convergence(study: &AccuracyStudy, records: &[&Record]) -> LineChart {
    let series = by_series(records)
        .into_iter()
        .map(|(label, runs)| Series::new(label, convergence_points(study, &runs)).with_markers())
        .collect();
    LineChart {
        title: format!("{}: convergence", study.common.title),
        x: Axis::log("cell size h [m]"),
        y: Axis::log(study.metric_label.clone()),
        series,
    }
}

/// One panel per kernel (and transfer): how each run of the sweep ended.
pub fn stability_map(study: &StabilityStudy, records: &[&Record]) -> StatusMap {
    let index =
        |values: &[toml::Value], text: &str| values.iter().position(|v| value_text(v) == text);
    let panels = by_series(records)
        .into_iter()
        .map(|(title, runs)| MapPanel {
            title,
            cells: runs
                .iter()
                .filter_map(|r| {
                    let x = index(&study.x.values, &r.x)?;
                    let y = index(&study.y.values, &r.y)?;
                    let (outcome, note) = match r.outcome.as_str() {
                        "completed" => (
                            Outcome::Completed,
                            r.energy_change
                                .map(|e| format!("{:+.0}%", 100.0 * e))
                                .unwrap_or_default(),
                        ),
                        "energy-growth" => (
                            Outcome::EnergyGrowth,
                            r.energy_gain
                                .map(|e| format!("gain {:.0}%", 100.0 * e))
                                .unwrap_or_default(),
                        ),
                        _ => (Outcome::Failed, short_kind(&r.failure_kind).to_string()),
                    };
                    Some(MapCell {
                        x,
                        y,
                        outcome,
                        note,
                    })
                })
                .collect(),
        })
        .collect();
    StatusMap {
        title: format!(
            "{}: outcome (energy change at the end, the gain, or why it failed)",
            study.common.title
        ),
        x_label: study.x.label.clone(),
        x_ticks: study.x.values.iter().map(value_text).collect(),
        y_label: study.y.label.clone(),
        y_ticks: study.y.values.iter().map(value_text).collect(),
        panels,
    }
}

/// A history column against time per series.
pub fn history(study: &HistoryStudy, curves: &[(String, Vec<(f64, f64)>)]) -> LineChart {
    LineChart {
        title: study.common.title.clone(),
        x: Axis::linear("time t [s]"),
        y: Axis::linear(study.column_label.clone()),
        series: curves
            .iter()
            .map(|(label, points)| Series::new(label.clone(), points.clone()))
            .collect(),
    }
}

/// Nanoseconds per particle-step of a run, split by stage.
pub fn stage_ns(r: &Record) -> Option<Vec<f64>> {
    let work = (r.particles? * r.steps?) as f64;
    (work > 0.0).then(|| {
        r.stages()
            .iter()
            .map(|s| s.unwrap_or(0.0) * 1e9 / work)
            .collect()
    })
}

/// Stacked bars of time per particle-step by stage, one bar per run.
pub fn stages(study: &ThroughputStudy, records: &[&Record]) -> StackedBars {
    StackedBars {
        title: format!("{}: time per particle-step by stage", study.common.title),
        value_label: "time per particle-step [ns]".into(),
        parts: STAGES.iter().map(|(_, label)| label.to_string()).collect(),
        bars: records
            .iter()
            .filter(|r| r.completed())
            .filter_map(|r| {
                Some(Bar {
                    label: format!(
                        "{}, {} particles, {} thr",
                        r.series(),
                        r.particles?,
                        r.threads
                    ),
                    values: stage_ns(r)?,
                })
            })
            .collect(),
    }
}

/// Time per particle-step against particle count per kernel and thread count (flat
/// lines are linear scaling).
pub fn scaling(study: &ThroughputStudy, records: &[&Record]) -> LineChart {
    let mut groups: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    for r in records.iter().filter(|r| r.completed()) {
        if let (Some(n), Some(rate)) = (r.particles, r.particle_steps_per_second) {
            groups
                .entry(format!("{}, {} threads", r.series(), r.threads))
                .or_default()
                .push((n as f64, 1e9 / rate));
        }
    }
    LineChart {
        title: format!(
            "{}: cost per particle-step against size",
            study.common.title
        ),
        x: Axis::log("particles"),
        y: Axis::log("wall time per particle-step [ns]"),
        series: groups
            .into_iter()
            .map(|(label, mut points)| {
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                Series::new(label, points).with_markers()
            })
            .collect(),
    }
}

/// A failure kind short enough for a map cell (the tables give the full kind and message).
fn short_kind(kind: &str) -> &str {
    match kind {
        "time-step-too-large" => "Δt > stable",
        "particle-kick" => "kick",
        "energy-blow-up" => "blow-up",
        "non-finite" => "NaN",
        "no-summary" => "no run",
        other => other,
    }
}
