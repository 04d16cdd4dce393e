//! Making the report: run every case of the matrix, write the raw results, draw the
//! charts and write `report.md` that links them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::analysis::{fitted_order, pareto_front};
use crate::case::{Case, StudyKind, cases};
use crate::charts;
use crate::criterion::{self, Bench};
use crate::error::{Result, file_error};
use crate::host::Host;
use crate::matrix::Matrix;
use crate::record::{Record, STAGES, to_csv};
use crate::runner::{Runner, history_column};

/// Where criterion's results are and which result sets to read.
#[derive(Debug, Clone)]
pub struct CriterionSource {
    /// `target/criterion`.
    pub root: PathBuf,
    /// The result set of this run: `new`, or the name given to `--save-baseline`.
    pub current: String,
    /// A saved baseline to compare with.
    pub baseline: Option<String>,
}

/// How to make a report.
#[derive(Debug, Clone)]
pub struct Options {
    /// The `umls` executable that runs the cases.
    pub exe: PathBuf,
    /// Output directory: `report.md`, `charts/`, `results.csv`, `results.json`,
    /// `histories/`.
    pub out: PathBuf,
    /// Where runs write (default `<out>/runs`); their ParaView frames are deleted after
    /// reading unless `keep_frames`.
    pub work: Option<PathBuf>,
    /// Keep each run's ParaView frames.
    pub keep_frames: bool,
    /// Name of the matrix, for the report's header.
    pub matrix_name: String,
    /// The workspace (for the git revision).
    pub workspace: PathBuf,
    /// Criterion results to include.
    pub criterion: Option<CriterionSource>,
}

/// Progress of a report, for a caller that shows it.
#[derive(Debug, Clone, Copy)]
pub struct Progress<'a> {
    /// Runs done, including this one.
    pub done: usize,
    /// Runs in the matrix.
    pub total: usize,
    /// The run.
    pub case: &'a Case,
    /// Its record.
    pub record: &'a Record,
}

/// What a finished report holds.
#[derive(Debug, Clone)]
pub struct Report {
    /// Every run's record.
    pub records: Vec<Record>,
    /// `report.md`.
    pub path: PathBuf,
    /// The charts written, relative to the output directory.
    pub charts: Vec<String>,
}

/// Runs `matrix` and writes the report.
pub fn generate(
    matrix: &Matrix,
    options: &Options,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<Report> {
    let out = &options.out;
    let chart_dir = out.join("charts");
    for dir in [out, &chart_dir, &out.join("histories")] {
        std::fs::create_dir_all(dir).map_err(file_error(dir))?;
    }
    let runner = Runner {
        exe: options.exe.clone(),
        work: options.work.clone().unwrap_or_else(|| out.join("runs")),
    };
    let all = cases(matrix);
    let started = std::time::Instant::now();
    let mut records = Vec::with_capacity(all.len());
    let mut histories: Vec<(usize, Vec<(f64, f64)>)> = Vec::new();
    for (i, case) in all.iter().enumerate() {
        let output = runner.run(case)?;
        let (metric, growth) = study_metric(matrix, case);
        let relative = output
            .dir
            .strip_prefix(out)
            .unwrap_or(&output.dir)
            .display()
            .to_string();
        let record = Record::new(case, &output, &metric, growth, relative);
        if case.kind == StudyKind::History && output.dir.join("history.csv").is_file() {
            let column = &matrix
                .history
                .iter()
                .find(|h| h.common.name == case.study)
                .expect("the case came from this study")
                .column;
            histories.push((i, history_column(&output.dir, column)?));
        }
        if !options.keep_frames {
            remove_frames(&output.dir)?;
        }
        records.push(record);
        progress(Progress {
            done: i + 1,
            total: all.len(),
            case,
            record: &records[i],
        });
    }
    let elapsed = started.elapsed().as_secs_f64();

    write(&out.join("results.csv"), &to_csv(&records))?;
    let host = Host::detect(&options.workspace);
    let json = serde_json::json!({
        "title": matrix.title,
        "matrix": options.matrix_name,
        "host": host,
        "seconds": elapsed,
        "records": records,
    });
    write(
        &out.join("results.json"),
        &serde_json::to_string_pretty(&json).unwrap_or_default(),
    )?;
    let benches = options
        .criterion
        .as_ref()
        .map(|c| criterion::collect(&c.root, &c.current, c.baseline.as_deref()))
        .unwrap_or_default();
    let mut doc = Document {
        text: String::new(),
        charts: Vec::new(),
        out: out.clone(),
    };
    doc.header(matrix, options, &host, elapsed, &records);
    for line in crate::summary::lines(matrix, &records) {
        doc.line(line);
    }
    doc.accuracy(matrix, &records)?;
    doc.stability(matrix, &records)?;
    doc.histories(matrix, &records, &histories)?;
    doc.throughput(matrix, &records)?;
    doc.criterion(&benches, options.criterion.as_ref());
    doc.raw();
    let path = out.join("report.md");
    write(&path, &doc.text)?;
    Ok(Report {
        records,
        path,
        charts: doc.charts,
    })
}

/// The metric and energy-growth threshold a case's study reads.
fn study_metric(matrix: &Matrix, case: &Case) -> (String, f64) {
    let growth = matrix
        .stability
        .iter()
        .find(|s| s.common.name == case.study)
        .map_or(0.05, |s| s.energy_growth);
    let metric = matrix
        .accuracy
        .iter()
        .find(|s| s.common.name == case.study)
        .map(|s| s.metric.clone())
        .unwrap_or_default();
    (metric, growth)
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(file_error(path))
}

/// Deletes a run's ParaView frames (the report reads only its summary and history).
fn remove_frames(dir: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for path in entries.flatten().map(|e| e.path()) {
        if path.is_dir() && path.file_name().is_some_and(|n| n == "frames") {
            std::fs::remove_dir_all(&path).map_err(file_error(&path))?;
        } else if path.extension().is_some_and(|e| e == "vtu" || e == "pvd") {
            std::fs::remove_file(&path).map_err(file_error(&path))?;
        }
    }
    Ok(())
}

/// A number in 3 significant digits, or "—".
fn num(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() && x != 0.0 && (x.abs() >= 1e4 || x.abs() < 1e-3) => {
            format!("{x:.2e}")
        }
        Some(x) if x.is_finite() => {
            let digits = (2 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
            format!("{x:.digits$}")
        }
        _ => "—".into(),
    }
}

/// The report being written.
struct Document {
    text: String,
    charts: Vec<String>,
    out: PathBuf,
}

impl Document {
    fn line(&mut self, s: impl AsRef<str>) {
        self.text.push_str(s.as_ref());
        self.text.push('\n');
    }

    /// Writes a chart and links it.
    fn chart(
        &mut self,
        name: &str,
        write: impl FnOnce(&Path) -> umls_io::Result<()>,
    ) -> Result<()> {
        let relative = format!("charts/{name}.svg");
        write(&self.out.join(&relative))?;
        self.line(format!("![{name}]({relative})\n"));
        self.charts.push(relative);
        Ok(())
    }

    fn header(
        &mut self,
        matrix: &Matrix,
        o: &Options,
        host: &Host,
        seconds: f64,
        records: &[Record],
    ) {
        let mut kernels: Vec<&str> = Vec::new();
        for r in records {
            if !kernels.contains(&r.kernel.as_str()) {
                kernels.push(&r.kernel);
            }
        }
        let failed = records.iter().filter(|r| !r.completed()).count();
        self.line(format!("# {}\n", matrix.title));
        self.line(format!(
            "Made by `umls report` (matrix `{}`) on {}: {}, revision `{}`. \
             {} runs in {:.0} s, {} of them did not complete (each is listed with its cause).\n",
            o.matrix_name,
            host.date,
            host.machine(),
            host.revision,
            records.len(),
            seconds,
            failed
        ));
        self.line(format!(
            "Kernels: {}.\n",
            kernels
                .iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        self.line(format!(
            "Times are the time in the steps themselves (the sum of the stage times; setup, \
                 output frames and history rows excluded), each run in a process of its own on \
                 {} threads unless a table says otherwise; throughput is particles × steps over \
                 that time; peak memory is the process's resident high-water mark. Raw numbers: \
                 `results.csv`, `results.json`.\n",
            matrix.threads
        ));
    }

    fn accuracy(&mut self, matrix: &Matrix, records: &[Record]) -> Result<()> {
        if matrix.accuracy.is_empty() {
            return Ok(());
        }
        self.line("## Speed against accuracy, and convergence\n");
        for study in &matrix.accuracy {
            let runs = of_study(records, &study.common.name);
            self.line(format!("### {}\n", study.common.title));
            self.line(format!(
                "Scene `{}`, metric `{}` ({}), refinement {:?} of h = {}.\n",
                study.common.scene, study.metric, study.metric_label, study.refine, study.h
            ));
            if !study.regime.is_empty() {
                self.line(format!("Regime: {}\n", study.regime));
            }
            let name = &study.common.name;
            self.chart(&format!("{name}-speed-accuracy"), |p| {
                charts::speed_accuracy(study, &runs).write_svg(p)
            })?;
            if study.refine.len() > 1 {
                self.chart(&format!("{name}-convergence"), |p| {
                    charts::convergence(study, &runs).write_svg(p)
                })?;
            }
            // Pareto front over all runs of the study.
            let points: Vec<(f64, f64)> = runs
                .iter()
                .map(|r| match (r.completed(), r.step_time_s, r.metric) {
                    (true, Some(t), Some(e)) => (t, e),
                    _ => (f64::NAN, f64::NAN),
                })
                .collect();
            let front = pareto_front(&points);
            self.line("| kernel | h | particles | status | error | time in the steps [s] | M particle-steps/s | peak memory [MB] | Pareto |");
            self.line("|---|---|---|---|---|---|---|---|---|");
            for (i, r) in runs.iter().enumerate() {
                self.line(format!(
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    r.series(),
                    num(Some(study.h / r.refine)),
                    r.particles.map_or("—".into(), |n| n.to_string()),
                    status_text(r),
                    num(r.metric),
                    num(r.step_time_s),
                    num(r.particle_steps_per_second.map(|x| x / 1e6)),
                    num(r.peak_memory_bytes.map(|b| b as f64 / 1e6)),
                    if front.contains(&i) { "●" } else { "" },
                ));
            }
            self.line("");
            if study.refine.len() > 1 {
                let fitted: Vec<String> = study
                    .refine
                    .iter()
                    .filter(|&&f| study.fits(f))
                    .map(|f| f.to_string())
                    .collect();
                self.line(format!(
                    "Observed orders fitted over the refinements inside the regime: {}.\n",
                    if fitted.is_empty() {
                        "none (no order is fitted)".to_string()
                    } else {
                        fitted.join(", ")
                    }
                ));
                self.line("| kernel | observed order (least squares, fitted levels) | orders between levels |");
                self.line("|---|---|---|");
                for (label, group) in charts::by_series(&runs) {
                    let pts = charts::convergence_points(study, &group);
                    let inside: Vec<&Record> = group
                        .iter()
                        .copied()
                        .filter(|r| study.fits(r.refine))
                        .collect();
                    let fit_pts = charts::convergence_points(study, &inside);
                    let pairwise: Vec<String> =
                        pts.windows(2).map(|w| num(fitted_order(w))).collect();
                    self.line(format!(
                        "| {label} | {} | {} |",
                        num(fitted_order(&fit_pts)),
                        if pairwise.is_empty() {
                            "—".into()
                        } else {
                            pairwise.join(", ")
                        }
                    ));
                }
                self.line("");
            }
            self.failures(&runs);
        }
        Ok(())
    }

    /// The runs that did not complete, with their cause.
    fn failures(&mut self, runs: &[&Record]) {
        let failed: Vec<&&Record> = runs.iter().filter(|r| !r.completed()).collect();
        if failed.is_empty() {
            return;
        }
        self.line("Runs that did not complete:\n");
        for r in failed {
            let mut place = format!("refinement {}", r.refine);
            if !r.x.is_empty() {
                place = format!("{} × {}", r.x, r.y);
            }
            let message = r
                .error
                .lines()
                .next()
                .unwrap_or("")
                .chars()
                .take(200)
                .collect::<String>();
            self.line(format!(
                "- {} at {place}: {} — {message}",
                r.series(),
                status_text(r)
            ));
        }
        self.line("");
    }

    fn stability(&mut self, matrix: &Matrix, records: &[Record]) -> Result<()> {
        if matrix.stability.is_empty() {
            return Ok(());
        }
        self.line("## Stability maps\n");
        for study in &matrix.stability {
            let runs = of_study(records, &study.common.name);
            self.line(format!("### {}\n", study.common.title));
            self.line(format!(
                "Scene `{}`; columns: {} (`{}`), rows: {} (`{}`). Green: completed, the energy never \
                 more than {:.0} % (of the run's largest kinetic + elastic energy) above its start, \
                 labelled with the change at the end; amber: completed with a larger gain; red: \
                 failed, labelled with the kind of failure.\n",
                study.common.scene,
                study.x.label,
                study.x.key,
                study.y.label,
                study.y.key,
                100.0 * study.energy_growth
            ));
            self.chart(&format!("{}-stability", study.common.name), |p| {
                charts::stability_map(study, &runs).write_svg(p)
            })?;
            let mut counts: Vec<(String, usize, usize, usize)> = Vec::new();
            for (label, group) in charts::by_series(&runs) {
                let count = |o: &str| group.iter().filter(|r| r.outcome == o).count();
                counts.push((
                    label,
                    count("completed"),
                    count("energy-growth"),
                    count("failed"),
                ));
            }
            self.line("| kernel | completed | energy growth | failed |");
            self.line("|---|---|---|---|");
            for (label, c, g, f) in counts {
                self.line(format!("| {label} | {c} | {g} | {f} |"));
            }
            self.line("");
            self.failures(&runs);
        }
        Ok(())
    }

    fn histories(
        &mut self,
        matrix: &Matrix,
        records: &[Record],
        curves: &[(usize, Vec<(f64, f64)>)],
    ) -> Result<()> {
        if matrix.history.is_empty() {
            return Ok(());
        }
        self.line("## Histories\n");
        for study in &matrix.history {
            let mut series = Vec::new();
            let mut rows = Vec::new();
            for (i, points) in curves {
                let r = &records[*i];
                if r.study != study.common.name {
                    continue;
                }
                let first = points.first().map_or(1.0, |p| p.1);
                let points: Vec<(f64, f64)> = if study.relative && first != 0.0 {
                    points.iter().map(|&(t, v)| (t, v / first)).collect()
                } else {
                    points.clone()
                };
                let csv_name = format!("histories/{}_{}.csv", study.common.name, slug(&r.series()));
                let mut csv = format!("time,{}\n", study.column);
                for (t, v) in &points {
                    let _ = writeln!(csv, "{t},{v}");
                }
                write(&self.out.join(&csv_name), &csv)?;
                rows.push((
                    r.series(),
                    status_text(r),
                    points.last().map(|p| p.1),
                    csv_name,
                ));
                series.push((r, points));
            }
            self.line(format!("### {}\n", study.common.title));
            self.line(format!(
                "Scene `{}`, column `{}` of `history.csv`{}.\n",
                study.common.scene,
                study.column,
                if study.relative {
                    ", divided by its first value"
                } else {
                    ""
                }
            ));
            self.chart(&study.common.name, |p| {
                charts::history(study, &series).write_svg(p)
            })?;
            self.line("| kernel | status | final value | data |");
            self.line("|---|---|---|---|");
            for (label, status, last, file) in rows {
                self.line(format!(
                    "| {label} | {status} | {} | [{file}]({file}) |",
                    num(last)
                ));
            }
            self.line("");
            let runs = of_study(records, &study.common.name);
            self.failures(&runs);
        }
        Ok(())
    }

    fn throughput(&mut self, matrix: &Matrix, records: &[Record]) -> Result<()> {
        if matrix.throughput.is_empty() {
            return Ok(());
        }
        self.line("## Throughput\n");
        for study in &matrix.throughput {
            let runs = fastest_repeats(&of_study(records, &study.common.name));
            self.line(format!("### {}\n", study.common.title));
            self.line(format!(
                "Scene `{}`, threads {:?}, refinement {:?}, the fastest of {} run(s) each.\n",
                study.common.scene, study.threads, study.refine, study.repeats
            ));
            self.chart(&format!("{}-stages", study.common.name), |p| {
                charts::stages(study, &runs).write_svg(p)
            })?;
            if study.refine.len() > 1 {
                self.chart(&format!("{}-scaling", study.common.name), |p| {
                    charts::scaling(study, &runs).write_svg(p)
                })?;
            }
            let stage_names: Vec<&str> = STAGES.iter().map(|(_, l)| *l).collect();
            self.line(format!(
                "| kernel | particles | threads | status | M particle-steps/s | speed-up over 1 thread | peak memory [MB] | bytes per particle | ns per particle-step: {} |",
                stage_names.join(" / ")
            ));
            self.line("|---|---|---|---|---|---|---|---|---|");
            for r in &runs {
                let single = runs.iter().find(|o| {
                    o.threads == 1
                        && o.series() == r.series()
                        && o.refine == r.refine
                        && o.completed()
                });
                let speedup = match (
                    single.and_then(|s| s.particle_steps_per_second),
                    r.particle_steps_per_second,
                ) {
                    (Some(one), Some(this)) if r.threads != 1 => num(Some(this / one)),
                    _ => "—".into(),
                };
                let stages = charts::stage_ns(r)
                    .map(|v| {
                        v.iter()
                            .map(|x| format!("{x:.0}"))
                            .collect::<Vec<_>>()
                            .join(" / ")
                    })
                    .unwrap_or_else(|| "—".into());
                self.line(format!(
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    r.series(),
                    r.particles.map_or("—".into(), |n| n.to_string()),
                    r.threads,
                    status_text(r),
                    num(r.particle_steps_per_second.map(|x| x / 1e6)),
                    speedup,
                    num(r.peak_memory_bytes.map(|b| b as f64 / 1e6)),
                    match (r.peak_memory_bytes, r.particles) {
                        (Some(b), Some(n)) if n > 0 => format!("{:.0}", b as f64 / n as f64),
                        _ => "—".into(),
                    },
                    stages
                ));
            }
            self.line("");
            self.line("Bytes per particle divide the whole process's peak (mesh or grid included) by the particle count.\n");
            self.failures(&runs);
        }
        Ok(())
    }

    fn criterion(&mut self, benches: &[Bench], source: Option<&CriterionSource>) {
        let Some(source) = source else {
            return;
        };
        self.line("## Criterion benches\n");
        if benches.is_empty() {
            self.line(format!(
                "No criterion results under `{}` (run `cargo xtask bench` without `--quick`).\n",
                source.root.display()
            ));
            return;
        }
        let baseline = source.baseline.as_deref();
        self.line(format!(
            "Median time per iteration with its 95 % interval{}.\n",
            baseline.map_or(String::new(), |b| format!(
                ", and the change against the saved baseline `{b}`"
            ))
        ));
        self.line("| benchmark | median | interval | throughput | change |");
        self.line("|---|---|---|---|---|");
        for b in benches {
            let rate = b
                .per_second()
                .map(|(r, unit)| format!("{} {unit}/s", num(Some(r))))
                .unwrap_or_else(|| "—".into());
            let change = b
                .change()
                .map_or("—".into(), |c| format!("{:+.1} %", 100.0 * c));
            self.line(format!(
                "| `{}` | {} | {} – {} | {rate} | {change} |",
                b.id,
                criterion::human_time(b.median_ns),
                criterion::human_time(b.median_interval_ns.0),
                criterion::human_time(b.median_interval_ns.1),
            ));
        }
        self.line("");
    }

    fn raw(&mut self) {
        self.line("## Raw data\n");
        self.line("- [`results.csv`](results.csv): one row per run (the columns of `Record` in the `umls-report` crate).");
        self.line("- [`results.json`](results.json): the same with the host and the matrix name.");
        self.line("- `histories/`: the charted history columns, one CSV per run.");
    }
}

/// The records of one study, in run order.
fn of_study<'a>(records: &'a [Record], study: &str) -> Vec<&'a Record> {
    records.iter().filter(|r| r.study == study).collect()
}

/// One record per measurement (series, size, threads): the fastest completed repetition
/// by time in the steps, or the first repetition when none completed; in the order the
/// first repetitions were run.
fn fastest_repeats<'a>(runs: &[&'a Record]) -> Vec<&'a Record> {
    let same = |a: &Record, b: &Record| {
        a.series() == b.series() && a.refine == b.refine && a.threads == b.threads
    };
    runs.iter()
        .filter(|r| r.repeat == 0)
        .map(|first| {
            runs.iter()
                .filter(|r| same(r, first) && r.completed())
                .max_by(|a, b| {
                    let rate = |r: &Record| r.particle_steps_per_second.unwrap_or(0.0);
                    rate(a).total_cmp(&rate(b)).then(b.repeat.cmp(&a.repeat))
                })
                .copied()
                .unwrap_or(first)
        })
        .collect()
}

fn status_text(r: &Record) -> String {
    match (r.status.as_str(), r.failure_kind.as_str()) {
        ("completed", _) => "completed".into(),
        (s, "") => s.into(),
        (s, kind) if s == kind => s.into(),
        (s, kind) => format!("{s} ({kind})"),
    }
}

fn slug(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect()
}
