//! The charts of each study, drawn from its records with `umls_io::chart`: every kernel
//! in its fixed style ([`crate::styles`]), at most [`MAX_SERIES`] curves per panel,
//! failed runs marked.

use std::collections::BTreeMap;

use umls_io::chart::{
    Axis, Bar, LineChart, MapCell, MapPanel, Outcome, PanelChart, Series, StackedBars, StatusMap,
};

use crate::matrix::{AccuracyStudy, HistoryStudy, StabilityStudy, ThroughputStudy, value_text};
use crate::record::{Record, STAGES};
use crate::styles::{distinct, kernel_style};

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

/// Runs grouped by kernel, in first-seen order.
type KernelRuns<'a> = Vec<(String, Vec<&'a Record>)>;

/// A scaling curve: (series label, threads) → (kernel, (particles, ns per particle-step)).
type ScalingCurves = BTreeMap<(String, usize), (String, Vec<(f64, f64)>)>;

/// Most curves one panel shows; a study with more is split into panels.
pub const MAX_SERIES: usize = 8;

/// One panel's runs: a transfer and variant, and the kernels in it.
#[derive(Debug, Clone)]
pub struct Facet<'a> {
    /// Panel title: the transfer and variant, and the kernel family when split.
    pub title: String,
    /// (kernel, its runs), at most [`MAX_SERIES`].
    pub kernels: KernelRuns<'a>,
}

/// The records split into panels: one per transfer and variant, in first-seen order,
/// each with one series per kernel. A panel with more than [`MAX_SERIES`] kernels is
/// split into the established kernels (UMLS among them) and UMLS's variants (`umls-*`),
/// the variants led by `umls` itself, the reference to read them against, when it fits.
pub fn facets<'a>(records: &[&'a Record]) -> Vec<Facet<'a>> {
    let mut groups: Vec<((String, String), KernelRuns<'a>)> = Vec::new();
    for r in records {
        let key = (r.transfer.clone(), r.variant.clone());
        let at = match groups.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                groups.push((key, Vec::new()));
                groups.len() - 1
            }
        };
        let kernels = &mut groups[at].1;
        match kernels.iter_mut().find(|(k, _)| *k == r.kernel) {
            Some((_, runs)) => runs.push(r),
            None => kernels.push((r.kernel.clone(), vec![r])),
        }
    }
    let mut facets = Vec::new();
    for ((transfer, variant), kernels) in groups {
        let base: Vec<&str> = [transfer.as_str(), variant.as_str()]
            .into_iter()
            .filter(|p| !p.is_empty())
            .collect();
        let title = |family: &str| {
            let mut parts = base.clone();
            if !family.is_empty() {
                parts.push(family);
            }
            parts.join(", ")
        };
        if kernels.len() <= MAX_SERIES {
            facets.push(Facet {
                title: title(""),
                kernels,
            });
            continue;
        }
        let reference = kernels.iter().find(|(k, _)| k == "umls").cloned();
        let (variants, established): (Vec<_>, Vec<_>) = kernels
            .into_iter()
            .partition(|(k, _)| k.starts_with("umls-"));
        for chunk in established.chunks(MAX_SERIES) {
            facets.push(Facet {
                title: title("established kernels"),
                kernels: chunk.to_vec(),
            });
        }
        // The reference leads the variants' panel when there is room for it; otherwise
        // it is in the panel just above.
        let reference = reference.filter(|_| variants.len() < MAX_SERIES);
        let room = MAX_SERIES - usize::from(reference.is_some());
        for chunk in variants.chunks(room) {
            facets.push(Facet {
                title: title("UMLS variants"),
                kernels: reference
                    .iter()
                    .cloned()
                    .chain(chunk.iter().cloned())
                    .collect(),
            });
        }
    }
    facets
}

/// A figure of one panel per facet; `series` makes a kernel's curve from its runs.
fn panels(
    title: String,
    x: Axis,
    y: Axis,
    records: &[&Record],
    series: impl Fn(&str, &[&Record]) -> Series,
) -> PanelChart {
    let panels = facets(records)
        .into_iter()
        .map(|facet| {
            let styles: Vec<_> = facet.kernels.iter().map(|(k, _)| kernel_style(k)).collect();
            let styles = distinct(&styles);
            LineChart {
                title: facet.title,
                x: x.clone(),
                y: y.clone(),
                series: facet
                    .kernels
                    .iter()
                    .zip(styles)
                    .map(|((kernel, runs), style)| {
                        let s = series(kernel, runs);
                        match style {
                            Some(style) => s.with_style(style),
                            None => s,
                        }
                    })
                    .collect(),
            }
        })
        .collect();
    PanelChart { title, panels }
}

/// A kernel's curve: the completed runs' points, and the failed runs marked at `x`.
fn curve(
    kernel: &str,
    runs: &[&Record],
    point: impl Fn(&Record) -> Option<(f64, f64)>,
    x: impl Fn(&Record) -> Option<f64>,
) -> Series {
    let failed: Vec<&&Record> = runs.iter().filter(|r| !r.completed()).collect();
    Series::new(
        kernel,
        runs.iter()
            .filter(|r| r.completed())
            .filter_map(|r| point(r))
            .collect(),
    )
    .with_markers()
    .with_failures(failed.iter().filter_map(|r| x(r)).collect(), failed.len())
}

/// The study's error against `x` of each run, one series per kernel, a panel per
/// transfer and variant; failed runs are marked at their `x`.
fn error_against(
    study: &AccuracyStudy,
    records: &[&Record],
    what: &str,
    axis: Axis,
    x: impl Fn(&Record) -> Option<f64> + Copy,
) -> PanelChart {
    panels(
        format!("{}: {what}", study.common.title),
        axis,
        Axis::log(study.metric_label.clone()),
        records,
        |kernel, runs| curve(kernel, runs, |r| Some((x(r)?, r.metric?)), x),
    )
}

/// Error against stepping wall time.
pub fn speed_accuracy(study: &AccuracyStudy, records: &[&Record]) -> PanelChart {
    error_against(
        study,
        records,
        "error against run time",
        Axis::log("time in the steps [s] (output excluded)"),
        |r| r.step_time_s,
    )
}

/// Error against cell size.
pub fn convergence(study: &AccuracyStudy, records: &[&Record]) -> PanelChart {
    error_against(
        study,
        records,
        "convergence",
        Axis::log("cell size h [m]"),
        |r| Some(study.h / r.refine),
    )
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

/// A history column against time, one series per kernel, a panel per transfer and
/// variant; a run that failed ends where it stopped and is counted in the legend.
pub fn history(study: &HistoryStudy, curves: &[(&Record, Vec<(f64, f64)>)]) -> PanelChart {
    let records: Vec<&Record> = curves.iter().map(|(r, _)| *r).collect();
    let points_of = |r: &Record| {
        curves
            .iter()
            .find(|(c, _)| std::ptr::eq(*c, r))
            .map(|(_, p)| p.clone())
            .unwrap_or_default()
    };
    panels(
        study.common.title.clone(),
        Axis::linear("time t [s]"),
        Axis::linear(study.column_label.clone()),
        &records,
        |kernel, runs| {
            let points = runs.iter().flat_map(|r| points_of(r)).collect();
            let failed = runs.iter().filter(|r| !r.completed()).count();
            Series::new(kernel, points).with_failures(Vec::new(), failed)
        },
    )
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
/// lines are linear scaling), at most [`MAX_SERIES`] curves per panel.
pub fn scaling(study: &ThroughputStudy, records: &[&Record]) -> PanelChart {
    let mut groups: ScalingCurves = BTreeMap::new();
    for r in records.iter().filter(|r| r.completed()) {
        if let (Some(n), Some(rate)) = (r.particles, r.particle_steps_per_second) {
            groups
                .entry((r.series(), r.threads))
                .or_insert_with(|| (r.kernel.clone(), Vec::new()))
                .1
                .push((n as f64, 1e9 / rate));
        }
    }
    let curves: Vec<_> = groups.into_iter().collect();
    let panels = curves
        .chunks(MAX_SERIES)
        .map(|chunk| {
            let styles: Vec<_> = chunk.iter().map(|(_, (k, _))| kernel_style(k)).collect();
            LineChart {
                title: String::new(),
                x: Axis::log("particles"),
                y: Axis::log("wall time per particle-step [ns]"),
                series: chunk
                    .iter()
                    .zip(distinct(&styles))
                    .map(|(((label, threads), (_, points)), style)| {
                        let mut points = points.clone();
                        points.sort_by(|a, b| a.0.total_cmp(&b.0));
                        let s = Series::new(format!("{label}, {threads} threads"), points)
                            .with_markers();
                        match style {
                            Some(style) => s.with_style(style),
                            None => s,
                        }
                    })
                    .collect(),
            }
        })
        .collect();
    PanelChart {
        title: format!(
            "{}: cost per particle-step against size",
            study.common.title
        ),
        panels,
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
