//! The one-screen summary that opens the report, generated from the results: for each
//! class of scene, which kernel is on the speed–accuracy front at equal time and at equal
//! error, the lowest error the best mesh and grid kernels reach, and how long each takes
//! to an accuracy both reach; then each stability map's failures per kernel.
//!
//! "Equal error" is the finest error both families reach (the larger of their best
//! errors); "equal time" is the smallest budget both can spend (the larger of their
//! cheapest runs). A kernel's time to an error is its fastest completed run at or below it.

use serde::Deserialize;

use crate::matrix::{AccuracyStudy, Matrix};
use crate::record::Record;

/// What a scene measures, for grouping studies in the summary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SceneClass {
    /// Walls and loads on grid lines, where a Cartesian grid fits the body.
    GridAligned,
    /// Walls off the grid lines or curved, where only a mesh conforms.
    OffGrid,
    /// Bodies that move far or deform much (collisions, swings).
    LargeDeformation,
    /// States at or near rest (stress under gravity).
    QuasiStatic,
}

impl SceneClass {
    /// Every class, in summary order.
    pub const ALL: [SceneClass; 4] = [
        SceneClass::GridAligned,
        SceneClass::OffGrid,
        SceneClass::LargeDeformation,
        SceneClass::QuasiStatic,
    ];

    /// Its name in the summary.
    pub fn label(self) -> &'static str {
        match self {
            SceneClass::GridAligned => "grid-aligned",
            SceneClass::OffGrid => "walls off grid lines or curved",
            SceneClass::LargeDeformation => "large deformation",
            SceneClass::QuasiStatic => "quasi-static",
        }
    }
}

/// Whether a kernel's nodes are a Cartesian grid (`bspline*`, `ugimp`) rather than a
/// mesh's vertices.
pub fn on_grid(kernel: &str) -> bool {
    kernel.starts_with("bspline") || kernel == "ugimp"
}

/// Most variants a study may have to get a summary row for each.
pub const MAX_VARIANT_ROWS: usize = 4;

/// A completed run's (time in the steps, error, its series label).
type Point = (f64, f64, String);

/// The completed runs of a study with a time and an error.
fn points(runs: &[&Record], grid: Option<bool>) -> Vec<Point> {
    runs.iter()
        .filter(|r| r.completed() && grid.is_none_or(|g| on_grid(&r.kernel) == g))
        .filter_map(|r| match (r.step_time_s, r.metric) {
            (Some(t), Some(e)) if t.is_finite() && e.is_finite() && t > 0.0 => {
                Some((t, e.abs(), r.series()))
            }
            _ => None,
        })
        .collect()
}

/// The fastest point at or below `error`.
fn fastest_to(points: &[Point], error: f64) -> Option<&Point> {
    points
        .iter()
        .filter(|p| p.1 <= error)
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The most accurate point within `time`.
fn best_within(points: &[Point], time: f64) -> Option<&Point> {
    points
        .iter()
        .filter(|p| p.0 <= time)
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// One study's line of the summary.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyVerdict {
    /// The most accurate series within the equal-time budget, its error and the budget.
    pub at_equal_time: Option<(String, f64, f64)>,
    /// The fastest series to the equal error, its time and that error.
    pub at_equal_error: Option<(String, f64, f64)>,
    /// The best mesh and grid series to the equal error: (mesh series, its time, grid
    /// series, its time).
    pub mesh_against_grid: Option<(String, f64, String, f64)>,
    /// The lowest error each family reaches at any cost: (mesh series, its error, grid
    /// series, its error).
    pub lowest: Option<(String, f64, String, f64)>,
}

/// The verdict on one study's runs.
pub fn verdict(runs: &[&Record]) -> StudyVerdict {
    let all = points(runs, None);
    let mesh = points(runs, Some(false));
    let grid = points(runs, Some(true));
    let least =
        |p: &[Point], pick: fn(&Point) -> f64| p.iter().map(pick).fold(f64::INFINITY, f64::min);
    // With one family only, "equal" is within that family: its best error, its cheapest run.
    let families: Vec<&Vec<Point>> = [&mesh, &grid]
        .into_iter()
        .filter(|p| !p.is_empty())
        .collect();
    if families.is_empty() {
        return StudyVerdict {
            at_equal_time: None,
            at_equal_error: None,
            mesh_against_grid: None,
            lowest: None,
        };
    }
    let error = families
        .iter()
        .map(|p| least(p, |q| q.1))
        .fold(0.0, f64::max);
    let time = families
        .iter()
        .map(|p| least(p, |q| q.0))
        .fold(0.0, f64::max);
    let at_equal_error = fastest_to(&all, error).map(|p| (p.2.clone(), p.0, error));
    let at_equal_time = best_within(&all, time).map(|p| (p.2.clone(), p.1, time));
    let mesh_against_grid = match (fastest_to(&mesh, error), fastest_to(&grid, error)) {
        (Some(m), Some(g)) => Some((m.2.clone(), m.0, g.2.clone(), g.0)),
        _ => None,
    };
    let most_accurate = |p: &[Point]| {
        p.iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|q| (q.2.clone(), q.1))
    };
    let lowest = match (most_accurate(&mesh), most_accurate(&grid)) {
        (Some((m, em)), Some((g, eg))) => Some((m, em, g, eg)),
        _ => None,
    };
    StudyVerdict {
        at_equal_time,
        at_equal_error,
        mesh_against_grid,
        lowest,
    }
}

/// The anchor of a Markdown heading as GitHub and most renderers make it.
pub fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// A number in three significant digits.
fn short(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e4 || x.abs() < 1e-2) {
        format!("{x:.2e}")
    } else {
        format!("{}", (x * 1000.0).round() / 1000.0)
    }
}

/// The summary's lines (Markdown): a table of the accuracy studies by class, then one
/// line per stability map.
pub fn lines(matrix: &Matrix, records: &[Record]) -> Vec<String> {
    let of = |name: &str| -> Vec<&Record> { records.iter().filter(|r| r.study == name).collect() };
    let mut out = vec![
        "## Summary\n".to_string(),
        "Generated from the runs below. Equal error: the finest error both mesh and grid \
         kernels reach; equal time: the smallest budget both can spend. The last two \
         columns divide the best grid kernel's number by the best mesh kernel's, so above \
         1 the mesh kernel wins: its lowest error at any cost, and its time to the equal \
         error.\n"
            .to_string(),
        "| scene class | study | best at equal time | best at equal error | lowest error, grid ÷ mesh | time to equal error, grid ÷ mesh |".to_string(),
        "|---|---|---|---|---|---|".to_string(),
    ];
    let classified: Vec<(&AccuracyStudy, SceneClass)> = SceneClass::ALL
        .iter()
        .flat_map(|&class| {
            matrix
                .accuracy
                .iter()
                .filter(move |s| s.class == Some(class))
                .map(move |s| (s, class))
        })
        .collect();
    for (study, class) in &classified {
        let runs = of(&study.common.name);
        let link = format!("[{}](#{})", study.common.title, anchor(&study.common.title));
        // A study of a few variants (a column turned by several angles) gets a row per
        // variant, since its variants are different problems; one of many options gets
        // one row over all of them.
        let variants: Vec<&str> = if (2..=MAX_VARIANT_ROWS).contains(&study.variants.len()) {
            study.variants.iter().map(|v| v.label.as_str()).collect()
        } else {
            vec![""]
        };
        for variant in variants {
            let rows: Vec<&Record> = runs
                .iter()
                .copied()
                .filter(|r| variant.is_empty() || r.variant == variant)
                .collect();
            let v = verdict(&rows);
            let place = if variant.is_empty() {
                link.clone()
            } else {
                format!("{link}: {variant}")
            };
            let equal_time = v
                .at_equal_time
                .map_or("no completed run".into(), |(s, e, t)| {
                    format!("{s}: error {} within {} s", short(e), short(t))
                });
            let equal_error = v.at_equal_error.map_or("—".into(), |(s, t, e)| {
                format!("{s}: error {} in {} s", short(e), short(t))
            });
            let ratio = v
                .mesh_against_grid
                .map_or("one family only".into(), |(m, tm, g, tg)| {
                    format!(
                        "**{}×** ({g} {} s, {m} {} s)",
                        short(tg / tm),
                        short(tg),
                        short(tm)
                    )
                });
            let accuracy = v.lowest.map_or("one family only".into(), |(m, em, g, eg)| {
                format!(
                    "**{}×** ({g} {}, {m} {})",
                    short(eg / em),
                    short(eg),
                    short(em)
                )
            });
            out.push(format!(
                "| {} | {place} | {equal_time} | {equal_error} | {accuracy} | {ratio} |",
                class.label()
            ));
        }
    }
    if classified.is_empty() {
        out.push("| — | no study of the matrix names a class | | | | |".into());
    }
    out.push(String::new());
    for study in &matrix.stability {
        let runs = of(&study.common.name);
        let mut kernels: Vec<(String, usize, usize)> = Vec::new();
        for r in &runs {
            let label = r.series();
            let at = match kernels.iter().position(|(k, ..)| *k == label) {
                Some(i) => i,
                None => {
                    kernels.push((label, 0, 0));
                    kernels.len() - 1
                }
            };
            kernels[at].1 += 1;
            kernels[at].2 += usize::from(r.outcome != "completed");
        }
        let counts: Vec<String> = kernels
            .iter()
            .map(|(k, n, bad)| format!("{k} {bad}/{n}"))
            .collect();
        out.push(format!(
            "- [{}](#{}): cells that failed or gained energy, per kernel: {}.",
            study.common.title,
            anchor(&study.common.title),
            counts.join(", ")
        ));
    }
    if !matrix.stability.is_empty() {
        out.push(String::new());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anchors_follow_the_renderers_rule() {
        assert_eq!(
            anchor("Hydrostatic column turned by 30°"),
            "hydrostatic-column-turned-by-30"
        );
        assert_eq!(
            anchor("Colliding disks: energy lost by t = 3"),
            "colliding-disks-energy-lost-by-t--3"
        );
    }
}
