//! One run of the matrix: the scene, kernel, transfer and edits, and where in its study
//! it belongs. [`cases`] expands a matrix into its runs, in a fixed order.

use crate::matrix::{Common, Matrix, Sweep, transfer_edits, value_text};

/// Which kind of study a run belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StudyKind {
    /// `[[accuracy]]`.
    Accuracy,
    /// `[[stability]]`.
    Stability,
    /// `[[history]]`.
    History,
    /// `[[throughput]]`.
    Throughput,
}

/// One run.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The study's name.
    pub study: String,
    /// Its kind.
    pub kind: StudyKind,
    /// Scene name or file.
    pub scene: String,
    /// Kernel name.
    pub kernel: String,
    /// Transfer name (empty: the scene's).
    pub transfer: String,
    /// Variant label (empty: none).
    pub variant: String,
    /// `--refine` factor.
    pub refine: f64,
    /// The refinement is made by the study's level edits (in `set`), not `--refine`.
    pub refine_by_edits: bool,
    /// `--particle-refine` factor.
    pub particle_refine: f64,
    /// `--end-time`.
    pub end_time: Option<f64>,
    /// Worker threads.
    pub threads: usize,
    /// Which repetition of a throughput measurement (0 for the first and for every other
    /// kind of study).
    pub repeat: usize,
    /// `KEY=VALUE` scene edits, in order (study, transfer, variant, sweep).
    pub set: Vec<String>,
    /// Column and row of a stability map, with their values as text.
    pub cell: Option<((usize, String), (usize, String))>,
}

impl Case {
    /// A directory name unique within the matrix.
    pub fn slug(&self) -> String {
        let mut parts = vec![self.study.clone(), self.kernel.clone()];
        parts.extend([self.transfer.clone(), self.variant.clone()]);
        parts.push(format!("r{}", self.refine));
        if self.particle_refine != 1.0 {
            parts.push(format!("p{}", self.particle_refine));
        }
        if let Some(((x, _), (y, _))) = &self.cell {
            parts.push(format!("x{x}y{y}"));
        }
        parts.push(format!("t{}", self.threads));
        if self.repeat > 0 {
            parts.push(format!("rep{}", self.repeat));
        }
        parts
            .iter()
            .filter(|p| !p.is_empty())
            .map(|p| {
                p.chars()
                    .map(|c| {
                        if c.is_ascii_alphanumeric() || c == '.' {
                            c
                        } else {
                            '-'
                        }
                    })
                    .collect::<String>()
            })
            .collect::<Vec<_>>()
            .join("_")
    }

    /// The arguments of `umls run` after the scene.
    pub fn arguments(&self) -> Vec<String> {
        let mut args = vec![
            "--quiet".to_string(),
            "--threads".into(),
            self.threads.to_string(),
            "--kernel".into(),
            self.kernel.clone(),
        ];
        if self.refine != 1.0 && !self.refine_by_edits {
            args.extend(["--refine".into(), self.refine.to_string()]);
        }
        if self.particle_refine != 1.0 {
            args.extend(["--particle-refine".into(), self.particle_refine.to_string()]);
        }
        if let Some(t) = self.end_time {
            args.extend(["--end-time".into(), t.to_string()]);
        }
        for s in &self.set {
            args.extend(["--set".into(), s.clone()]);
        }
        args
    }
}

/// A case with the study's common settings, before the study's own axes.
fn base(common: &Common, kind: StudyKind, kernel: &str, transfer: &str, threads: usize) -> Case {
    let mut set = common.set.clone();
    set.extend(transfer_edits(transfer).unwrap_or_default());
    Case {
        study: common.name.clone(),
        kind,
        scene: common.scene.clone(),
        kernel: kernel.to_string(),
        transfer: transfer.to_string(),
        variant: String::new(),
        refine: 1.0,
        refine_by_edits: false,
        particle_refine: 1.0,
        end_time: common.end_time,
        threads,
        repeat: 0,
        set,
        cell: None,
    }
}

/// The transfers of a study, or the scene's own (written as the empty name).
fn transfers(common: &Common) -> Vec<String> {
    if common.transfers.is_empty() {
        vec![String::new()]
    } else {
        common.transfers.clone()
    }
}

/// Applies one sweep value to a case.
fn apply(case: &mut Case, sweep: &Sweep, value: &toml::Value) {
    let number = value
        .as_float()
        .or_else(|| value.as_integer().map(|i| i as f64));
    match (sweep.key.as_str(), number) {
        ("refine", Some(f)) => case.refine = f,
        ("particle-refine", Some(f)) => case.particle_refine = f,
        _ => case.set.push(format!("{}={}", sweep.key, value)),
    }
}

/// Every run of `matrix`, study by study: for accuracy studies kernel × transfer ×
/// variant × refinement, for stability maps kernel × transfer × y × x, for histories
/// kernel × transfer, for throughput kernel × transfer × size × threads.
pub fn cases(matrix: &Matrix) -> Vec<Case> {
    let mut out = Vec::new();
    for study in &matrix.accuracy {
        let variants = if study.variants.is_empty() {
            vec![crate::matrix::Variant {
                label: String::new(),
                set: vec![],
                kernels: vec![],
            }]
        } else {
            study.variants.clone()
        };
        for kernel in &study.common.kernels {
            for transfer in transfers(&study.common) {
                for variant in variants.iter().filter(|v| v.runs_with(kernel)) {
                    for &refine in &study.refine {
                        let mut case = base(
                            &study.common,
                            StudyKind::Accuracy,
                            kernel,
                            &transfer,
                            matrix.threads,
                        );
                        case.variant = variant.label.clone();
                        case.set.extend(variant.set.iter().cloned());
                        case.refine = refine;
                        if let Some(edits) = study.level_edits(refine) {
                            case.set.extend(edits.iter().cloned());
                            case.refine_by_edits = true;
                        }
                        out.push(case);
                    }
                }
            }
        }
    }
    for study in &matrix.stability {
        for kernel in &study.common.kernels {
            for transfer in transfers(&study.common) {
                for (j, y) in study.y.values.iter().enumerate() {
                    for (i, x) in study.x.values.iter().enumerate() {
                        let mut case = base(
                            &study.common,
                            StudyKind::Stability,
                            kernel,
                            &transfer,
                            matrix.threads,
                        );
                        apply(&mut case, &study.x, x);
                        apply(&mut case, &study.y, y);
                        case.cell = Some(((i, value_text(x)), (j, value_text(y))));
                        out.push(case);
                    }
                }
            }
        }
    }
    for study in &matrix.history {
        for kernel in &study.common.kernels {
            for transfer in transfers(&study.common) {
                out.push(base(
                    &study.common,
                    StudyKind::History,
                    kernel,
                    &transfer,
                    matrix.threads,
                ));
            }
        }
    }
    // Repetitions outermost, thread counts innermost: every repetition measures each
    // size at every thread count back to back, and the repetitions are spread over the
    // study, so a spell of load on the machine slows one of them, not all.
    for study in &matrix.throughput {
        for repeat in 0..study.repeats {
            for kernel in &study.common.kernels {
                for transfer in transfers(&study.common) {
                    for &refine in &study.refine {
                        for &threads in &study.threads {
                            let mut case = base(
                                &study.common,
                                StudyKind::Throughput,
                                kernel,
                                &transfer,
                                threads,
                            );
                            case.refine = refine;
                            case.repeat = repeat;
                            out.push(case);
                        }
                    }
                }
            }
        }
    }
    out
}
