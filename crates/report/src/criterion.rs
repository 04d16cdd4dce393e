//! The criterion benches' results: for every benchmark its median time per iteration,
//! its throughput where the bench declares one, and the change against a saved baseline
//! (`cargo bench -- --save-baseline NAME`, then `cargo xtask bench --baseline NAME`).
//!
//! Criterion keeps `<root>/<benchmark>/benchmark.json` (the id and the throughput) and
//! one `estimates.json` per result set: `new` for the latest run, `<NAME>` for a saved
//! baseline.

use std::path::Path;

use serde::Serialize;

/// One benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct Bench {
    /// Criterion's full id, `group/function/parameter`.
    pub id: String,
    /// Median time per iteration, in nanoseconds.
    pub median_ns: f64,
    /// Lower and upper bound of the median's confidence interval.
    pub median_interval_ns: (f64, f64),
    /// Elements (or bytes) per iteration, with the unit.
    pub throughput: Option<(u64, String)>,
    /// Median of the baseline, if one was asked for and exists.
    pub baseline_ns: Option<f64>,
}

impl Bench {
    /// Elements (or bytes) per second at the median.
    pub fn per_second(&self) -> Option<(f64, &str)> {
        self.throughput
            .as_ref()
            .map(|(n, unit)| (*n as f64 / (self.median_ns * 1e-9), unit.as_str()))
    }

    /// Relative change of the median against the baseline (+0.10 = 10 % slower).
    pub fn change(&self) -> Option<f64> {
        self.baseline_ns.map(|b| self.median_ns / b - 1.0)
    }
}

/// Every benchmark under `root` with results in `current` (usually `new`), compared
/// with `baseline` where given; sorted by id. A missing root gives no benchmarks.
pub fn collect(root: &Path, current: &str, baseline: Option<&str>) -> Vec<Bench> {
    let mut benches = Vec::new();
    visit(root, current, baseline, &mut benches);
    benches.sort_by(|a, b| a.id.cmp(&b.id));
    benches
}

fn visit(dir: &Path, current: &str, baseline: Option<&str>, out: &mut Vec<Bench>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for path in entries.flatten().map(|e| e.path()) {
        if !path.is_dir() || path.file_name().is_some_and(|n| n == "report") {
            continue;
        }
        let results = path.join(current).join("estimates.json");
        let meta = path.join(current).join("benchmark.json");
        if results.is_file() {
            if let Some(bench) = read(&meta, &results, baseline.map(|b| path.join(b))) {
                out.push(bench);
            }
        } else {
            visit(&path, current, baseline, out);
        }
    }
}

fn json(path: &Path) -> Option<serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

/// The median and its interval from an `estimates.json`.
fn median(estimates: &serde_json::Value) -> Option<(f64, (f64, f64))> {
    let m = &estimates["median"];
    Some((
        m["point_estimate"].as_f64()?,
        (
            m["confidence_interval"]["lower_bound"].as_f64()?,
            m["confidence_interval"]["upper_bound"].as_f64()?,
        ),
    ))
}

fn read(meta: &Path, results: &Path, baseline: Option<std::path::PathBuf>) -> Option<Bench> {
    let meta = json(meta)?;
    let (median_ns, median_interval_ns) = median(&json(results)?)?;
    let throughput = meta["throughput"].as_object().and_then(|t| {
        t.iter()
            .next()
            .and_then(|(unit, n)| n.as_u64().map(|n| (n, unit.to_lowercase())))
    });
    let baseline_ns = baseline
        .and_then(|dir| json(&dir.join("estimates.json")))
        .and_then(|e| median(&e))
        .map(|(m, _)| m);
    Some(Bench {
        id: meta["full_id"].as_str()?.to_string(),
        median_ns,
        median_interval_ns,
        throughput,
        baseline_ns,
    })
}

/// A time in ns with a readable unit.
pub fn human_time(ns: f64) -> String {
    match ns {
        n if n >= 1e9 => format!("{:.3} s", n / 1e9),
        n if n >= 1e6 => format!("{:.3} ms", n / 1e6),
        n if n >= 1e3 => format!("{:.3} µs", n / 1e3),
        n => format!("{n:.1} ns"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(path: &Path, text: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }

    #[test]
    fn reads_medians_throughput_and_baseline_change() {
        let root = std::env::temp_dir().join(format!("umls-criterion-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let bench = root.join("step/umls/2thread");
        let meta = r#"{"full_id":"step/umls/2thread","throughput":{"Elements":1000}}"#;
        let estimates = |m: f64| {
            format!(
                r#"{{"mean":{{"point_estimate":1.0}},"median":{{"confidence_interval":{{"lower_bound":{},"upper_bound":{}}},"point_estimate":{m}}}}}"#,
                m * 0.9,
                m * 1.1
            )
        };
        write(&bench.join("new/benchmark.json"), meta);
        write(&bench.join("new/estimates.json"), &estimates(2e6));
        write(&bench.join("main/estimates.json"), &estimates(1.6e6));
        let found = collect(&root, "new", Some("main"));
        assert_eq!(found.len(), 1);
        let b = &found[0];
        assert_eq!(b.id, "step/umls/2thread");
        assert_eq!(b.median_ns, 2e6);
        assert_eq!(b.throughput, Some((1000, "elements".to_string())));
        let (rate, unit) = b.per_second().unwrap();
        assert!((rate - 5e5).abs() < 1e-6 && unit == "elements");
        assert!((b.change().unwrap() - 0.25).abs() < 1e-12);
        assert_eq!(human_time(1234.5), "1.234 µs");
        std::fs::remove_dir_all(&root).unwrap();
    }
}
