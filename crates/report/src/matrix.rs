//! The study matrix: which scenes run with which kernels, transfers and resolutions, and
//! what each study charts. A matrix is a TOML file (`matrices/quick.toml` and
//! `matrices/full.toml` are built in; `umls report --matrix FILE` reads another):
//!
//! - `[[accuracy]]`: a scene's error metric over refinement levels, per kernel, transfer
//!   and variant (e.g. mesh rotations): speed against accuracy and convergence;
//! - `[[stability]]`: a grid over two parameters (time step × mesh jitter, …) per kernel,
//!   each run classified as completed, energy growth, or failed with its kind;
//! - `[[history]]`: a column of `history.csv` (the disks' total energy) per kernel and
//!   transfer;
//! - `[[throughput]]`: particle-steps per second, time per stage and memory per particle
//!   per kernel, thread count and size.

use serde::Deserialize;

use crate::error::{ReportError, Result};
use crate::summary::SceneClass;

/// The built-in matrices: `quick` (coarse levels, about 4 minutes on 2 cores)
/// and `full`.
pub const BUILTIN: [(&str, &str); 2] = [
    ("quick", include_str!("../matrices/quick.toml")),
    ("full", include_str!("../matrices/full.toml")),
];

/// A whole matrix.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Matrix {
    /// Title of the report.
    pub title: String,
    /// Worker threads of every run that does not sweep them.
    #[serde(default = "default_threads")]
    pub threads: usize,
    /// Speed-against-accuracy and convergence studies.
    #[serde(default)]
    pub accuracy: Vec<AccuracyStudy>,
    /// Stability maps.
    #[serde(default)]
    pub stability: Vec<StabilityStudy>,
    /// History comparisons.
    #[serde(default)]
    pub history: Vec<HistoryStudy>,
    /// Throughput measurements.
    #[serde(default)]
    pub throughput: Vec<ThroughputStudy>,
}

fn default_threads() -> usize {
    2
}

/// What every study names: an id, a heading, the scene and its edits.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Common {
    /// Identifier, used in file names (letters, digits, `-`).
    pub name: String,
    /// Heading in the report.
    pub title: String,
    /// Built-in scene name or scene file path.
    pub scene: String,
    /// Simulated time (default: the scene's).
    pub end_time: Option<f64>,
    /// `KEY=VALUE` edits of the scene for every run of the study (`umls run --set`).
    #[serde(default)]
    pub set: Vec<String>,
    /// Kernels (`umls run --kernel` names).
    pub kernels: Vec<String>,
    /// Transfers: `pic`, `apic`, `flip:ALPHA`; empty for the scene's own.
    #[serde(default)]
    pub transfers: Vec<String>,
}

/// A named set of extra edits, e.g. a mesh rotation.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// Label in legends and tables.
    pub label: String,
    /// `KEY=VALUE` edits.
    #[serde(default)]
    pub set: Vec<String>,
    /// The study's kernels that run it (empty: all of them), for a variant only some
    /// kernels see, such as a mesh layout that a B-spline grid ignores.
    #[serde(default)]
    pub kernels: Vec<String>,
}

impl AccuracyStudy {
    /// The edits of refinement level `refine` when the study gives its levels as edits.
    pub fn level_edits(&self, refine: f64) -> Option<&[String]> {
        self.levels
            .iter()
            .find(|l| l.refine == refine)
            .map(|l| l.set.as_slice())
    }

    /// Whether the fitted orders use refinement level `refine`.
    pub fn fits(&self, refine: f64) -> bool {
        self.fit_levels.as_ref().is_none_or(|l| l.contains(&refine))
    }
}

impl Variant {
    /// Whether `kernel` runs this variant.
    pub fn runs_with(&self, kernel: &str) -> bool {
        self.kernels.is_empty() || self.kernels.iter().any(|k| k == kernel)
    }
}

/// `[[accuracy]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccuracyStudy {
    /// Name, title, scene, kernels, transfers, edits.
    #[serde(flatten)]
    pub common: Common,
    /// The `summary.json` metric that measures the error; `-name` negates it (the
    /// energy lost is `-energy_change_final`).
    pub metric: String,
    /// Its axis label, with unit.
    pub metric_label: String,
    /// Refinement factors (`umls run --refine`), or the factors of `levels`.
    pub refine: Vec<f64>,
    /// Refinement levels given as edits instead of `--refine`, for a scene on a mesh
    /// file (which `--refine` cannot refine): each names its factor, one of `refine`,
    /// and the edits that refine the scene by it (a finer mesh file, a finer seeding).
    #[serde(default)]
    pub levels: Vec<Level>,
    /// Cell size at refinement 1, for the convergence axis.
    pub h: f64,
    /// Variants (default: the scene as it is).
    #[serde(default)]
    pub variants: Vec<Variant>,
    /// The regime the levels are in, stated in the report (e.g. "asymptotic: second-order
    /// levels", or why an error floor is reached).
    #[serde(default)]
    pub regime: String,
    /// The refinement factors inside the asymptotic regime, which the fitted orders use
    /// (default: every level; empty: no order is fitted).
    pub fit_levels: Option<Vec<f64>>,
    /// The class of scene the summary lists it under (`grid-aligned`, `off-grid`,
    /// `large-deformation`, `quasi-static`); none keeps it out of the summary.
    #[serde(default)]
    pub class: Option<SceneClass>,
}

/// A refinement level given as scene edits.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Level {
    /// Its refinement factor (the cell size is `h / refine`).
    pub refine: f64,
    /// The edits that make it.
    #[serde(default)]
    pub set: Vec<String>,
}

/// One axis of a stability map.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// A scene key (`time.cfl`, `mesh.lattice.jitter`, `mesh.transform.rotation`), or
    /// `refine` / `particle-refine` for the run options of those names.
    pub key: String,
    /// Axis label, with unit.
    pub label: String,
    /// The values, in axis order.
    pub values: Vec<toml::Value>,
}

/// `[[stability]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StabilityStudy {
    /// Name, title, scene, kernels, transfers, edits.
    #[serde(flatten)]
    pub common: Common,
    /// Horizontal axis.
    pub x: Sweep,
    /// Vertical axis.
    pub y: Sweep,
    /// A completed run whose energy rose above its start by more than this fraction of
    /// its largest mechanical energy (`energy_gain_max` in `summary.json`) is marked
    /// "energy growth".
    #[serde(default = "default_growth")]
    pub energy_growth: f64,
}

fn default_growth() -> f64 {
    0.05
}

/// `[[history]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HistoryStudy {
    /// Name, title, scene, kernels, transfers, edits.
    #[serde(flatten)]
    pub common: Common,
    /// The `history.csv` column to chart against time.
    pub column: String,
    /// Its axis label, with unit.
    pub column_label: String,
    /// Divide the column by its first value (e.g. energy relative to the start).
    #[serde(default)]
    pub relative: bool,
}

/// `[[throughput]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThroughputStudy {
    /// Name, title, scene, kernels, transfers, edits.
    #[serde(flatten)]
    pub common: Common,
    /// Thread counts.
    pub threads: Vec<usize>,
    /// Refinement factors (sizes).
    #[serde(default = "default_refine")]
    pub refine: Vec<f64>,
    /// Runs of each measurement (default 1); the report keeps the fastest, since a
    /// shared machine only ever slows a run down.
    #[serde(default = "default_repeats")]
    pub repeats: usize,
}

fn default_repeats() -> usize {
    1
}

fn default_refine() -> Vec<f64> {
    vec![1.0]
}

impl Matrix {
    /// Reads matrix text; `label` names it in errors.
    pub fn parse(text: &str, label: &str) -> Result<Self> {
        let matrix: Matrix = toml::from_str(text).map_err(|e| ReportError::Matrix {
            file: label.to_string(),
            message: e.to_string(),
        })?;
        matrix.check(label)?;
        Ok(matrix)
    }

    /// A built-in matrix by name, or else a matrix file at that path.
    pub fn load(name_or_path: &str) -> Result<Self> {
        if let Some((name, text)) = BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
            return Self::parse(text, name);
        }
        let text = std::fs::read_to_string(name_or_path).map_err(|e| ReportError::Matrix {
            file: name_or_path.to_string(),
            message: format!(
                "{e} (built-in matrices: {})",
                BUILTIN.map(|(n, _)| n).join(", ")
            ),
        })?;
        Self::parse(&text, name_or_path)
    }

    /// Every study's common part.
    pub fn studies(&self) -> impl Iterator<Item = &Common> {
        self.accuracy
            .iter()
            .map(|s| &s.common)
            .chain(self.stability.iter().map(|s| &s.common))
            .chain(self.history.iter().map(|s| &s.common))
            .chain(self.throughput.iter().map(|s| &s.common))
    }

    /// Names unique and file-safe, lists non-empty, factors positive.
    fn check(&self, label: &str) -> Result<()> {
        let bad = |key: String, message: &str| ReportError::Matrix {
            file: label.to_string(),
            message: format!("`{key}`: {message}"),
        };
        let mut names = std::collections::HashSet::new();
        for study in self.studies() {
            let n = &study.name;
            if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '-') {
                return Err(bad(n.clone(), "a study name is letters, digits and `-`"));
            }
            if !names.insert(n.clone()) {
                return Err(bad(n.clone(), "two studies have this name"));
            }
            if study.kernels.is_empty() {
                return Err(bad(format!("{n}.kernels"), "lists no kernel"));
            }
            if let Some(t) = study.transfers.iter().find(|t| transfer_edits(t).is_none()) {
                return Err(bad(
                    format!("{n}.transfers"),
                    &format!("`{t}`: expected pic, apic or flip:ALPHA"),
                ));
            }
            if let Some(s) = study.set.iter().find(|s| !s.contains('=')) {
                return Err(bad(
                    format!("{n}.set"),
                    &format!("`{s}`: expected KEY=VALUE"),
                ));
            }
        }
        for s in &self.accuracy {
            let n = &s.common.name;
            if s.refine.is_empty() || s.refine.iter().any(|f| !(f.is_finite() && *f > 0.0)) {
                return Err(bad(format!("{n}.refine"), "needs positive factors"));
            }
            if !(s.h.is_finite() && s.h > 0.0) {
                return Err(bad(format!("{n}.h"), "must be positive"));
            }
            if !s.levels.is_empty() {
                let factors: Vec<f64> = s.levels.iter().map(|l| l.refine).collect();
                if factors != s.refine {
                    return Err(bad(
                        format!("{n}.levels"),
                        "must give the factors of `refine`, in its order",
                    ));
                }
            }
            if let Some(f) = s
                .fit_levels
                .iter()
                .flatten()
                .find(|f| !s.refine.contains(f))
            {
                return Err(bad(
                    format!("{n}.fit_levels"),
                    &format!("{f} is not one of the study's refinement factors"),
                ));
            }
            for v in &s.variants {
                if let Some(k) = v.kernels.iter().find(|k| !s.common.kernels.contains(k)) {
                    return Err(bad(
                        format!("{n}.variants `{}`.kernels", v.label),
                        &format!("`{k}` is not one of the study's kernels"),
                    ));
                }
            }
        }
        for s in &self.stability {
            let n = &s.common.name;
            if s.x.values.is_empty() || s.y.values.is_empty() {
                return Err(bad(format!("{n}.x/y.values"), "an axis has no values"));
            }
        }
        for s in &self.throughput {
            if s.threads.is_empty() || s.threads.contains(&0) {
                return Err(bad(
                    format!("{}.threads", s.common.name),
                    "needs thread counts ≥ 1",
                ));
            }
            if s.repeats == 0 {
                return Err(bad(
                    format!("{}.repeats", s.common.name),
                    "needs at least one run",
                ));
            }
        }
        Ok(())
    }
}

/// The scene edits of a transfer name: `pic`, `apic`, `quadratic-apic`, `mls-mpm`,
/// `flip:ALPHA`, `apic-flip:ALPHA` and `quadratic-apic-flip:ALPHA` (the FLIP blends alone
/// have α = 1).
pub fn transfer_edits(name: &str) -> Option<Vec<String>> {
    let (kind, alpha) = match name.split_once(':') {
        None if ["pic", "apic", "quadratic-apic", "mls-mpm"].contains(&name) => {
            return Some(vec![format!("transfer.kind={name}")]);
        }
        None => (name, "1.0"),
        Some(pair) => pair,
    };
    if !["flip", "apic-flip", "quadratic-apic-flip"].contains(&kind) {
        return None;
    }
    let a: f64 = alpha.parse().ok()?;
    (0.0..=1.0).contains(&a).then(|| {
        vec![
            format!("transfer.kind={kind}"),
            format!("transfer.alpha={a:?}"),
        ]
    })
}

/// A TOML value as axis text: `0.25`, `15`, `"x"` → `x`.
pub fn value_text(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::{BUILTIN, Matrix, transfer_edits};

    /// The built-in matrices are read at run time, so an edit that breaks one would
    /// otherwise surface only when someone runs the report.
    #[test]
    fn built_in_matrices_parse_and_name_kernels_in_every_study() {
        for (name, _) in BUILTIN {
            let matrix = Matrix::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!matrix.accuracy.is_empty(), "{name}");
            for study in matrix.studies() {
                assert!(!study.kernels.is_empty(), "{name}: {}", study.name);
            }
        }
    }

    #[test]
    fn transfer_names_become_scene_edits() {
        for (name, expected) in [
            ("apic", "transfer.kind=apic"),
            ("pic", "transfer.kind=pic"),
            ("mls-mpm", "transfer.kind=mls-mpm"),
            ("flip", "transfer.kind=flip transfer.alpha=1.0"),
            ("flip:0.99", "transfer.kind=flip transfer.alpha=0.99"),
            (
                "apic-flip:0.95",
                "transfer.kind=apic-flip transfer.alpha=0.95",
            ),
            ("apic-flip", "transfer.kind=apic-flip transfer.alpha=1.0"),
            ("quadratic-apic", "transfer.kind=quadratic-apic"),
            (
                "quadratic-apic-flip:0.99",
                "transfer.kind=quadratic-apic-flip transfer.alpha=0.99",
            ),
        ] {
            assert_eq!(
                transfer_edits(name).map(|e| e.join(" ")).as_deref(),
                Some(expected),
                "{name}"
            );
        }
        for bad in [
            "flip:1.5",
            "flip:x",
            "apic:0.5",
            "pic-flip:0.5",
            "flip:-0.1",
        ] {
            assert_eq!(transfer_edits(bad), None, "{bad}");
        }
    }

    /// A variant may name the kernels that run it, only among the study's own.
    #[test]
    fn a_variant_names_only_kernels_of_its_study() {
        let matrix = |kernels: &str| {
            format!(
                r#"title = "t"
[[accuracy]]
name = "a"
title = "a"
scene = "vortex"
metric = "m"
metric_label = "m"
kernels = ["umls", "bspline2"]
refine = [1]
h = 0.1
variants = [{{ label = "v", kernels = {kernels} }}]
"#
            )
        };
        let ok = Matrix::parse(&matrix(r#"["umls"]"#), "m.toml").unwrap();
        let variant = &ok.accuracy[0].variants[0];
        assert!(variant.runs_with("umls") && !variant.runs_with("bspline2"));
        let every = Matrix::parse(&matrix("[]"), "m.toml").unwrap();
        assert!(every.accuracy[0].variants[0].runs_with("bspline2"));
        let err = Matrix::parse(&matrix(r#"["linear-fe"]"#), "m.toml")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("m.toml")
                && err.contains("a.variants `v`.kernels")
                && err.contains("`linear-fe`"),
            "{err}"
        );
    }
}
