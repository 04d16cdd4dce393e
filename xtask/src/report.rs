//! Gathers criterion's `estimates.json` files into one Markdown table.
//!
//! Criterion writes `target/criterion/<group>/<function>/<parameter>/new/estimates.json`;
//! the median point estimate (ns per iteration) is all the table needs, so a
//! few lines of string scanning replace a JSON dependency in the build tool.

use std::path::Path;

/// One row per benchmark: its id and the median time per iteration.
pub fn collect(root: &Path) -> Result<String, String> {
    let mut rows = Vec::new();
    visit(root, root, &mut rows)?;
    rows.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out = String::from(
        "# Benchmark report\n\n| benchmark | median time per iteration |\n|---|---|\n",
    );
    for (id, ns) in rows {
        out.push_str(&format!("| `{id}` | {} |\n", human(ns)));
    }
    Ok(out)
}

fn visit(root: &Path, dir: &Path, rows: &mut Vec<(String, f64)>) -> Result<(), String> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(_) => return Ok(()),
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if path.file_name().is_some_and(|n| n == "report") {
                continue;
            }
            let estimates = path.join("new/estimates.json");
            if estimates.is_file() {
                let text = std::fs::read_to_string(&estimates)
                    .map_err(|e| format!("{}: {e}", estimates.display()))?;
                if let Some(ns) = median(&text) {
                    let id = path
                        .strip_prefix(root)
                        .unwrap_or(&path)
                        .display()
                        .to_string();
                    rows.push((id, ns));
                }
            } else {
                visit(root, &path, rows)?;
            }
        }
    }
    Ok(())
}

/// `"median":{"confidence_interval":{...},"point_estimate":123.4,...}` → 123.4
fn median(json: &str) -> Option<f64> {
    let start = json.find("\"median\"")?;
    let rest = &json[start..];
    let key = "\"point_estimate\":";
    let at = rest.find(key)? + key.len();
    let number: String = rest[at..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || "+-.eE".contains(*c))
        .collect();
    number.parse().ok()
}

fn human(ns: f64) -> String {
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

    #[test]
    fn reads_the_median_point_estimate() {
        let json = r#"{"mean":{"point_estimate":5.0},"median":{"confidence_interval":{"lower_bound":1.0},"point_estimate":1234.5,"standard_error":2.0}}"#;
        assert_eq!(median(json), Some(1234.5));
        assert_eq!(human(1234.5), "1.234 µs");
    }
}
