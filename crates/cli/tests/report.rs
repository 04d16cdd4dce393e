//! `umls report` end to end on a tiny matrix: the same code path as `cargo xtask bench`
//! (every case a child process of the binary), checked for what a reader relies on —
//! every kernel named, every chart written and linked, one row of raw results per run,
//! and a run that fails recorded as failed with its cause instead of ending the report.

use std::path::PathBuf;
use std::process::Command;

const MATRIX: &str = r#"
title = "tiny matrix"
threads = 1

[[accuracy]]
name = "bar"
title = "Vibrating bar"
scene = "vibrating-bar"
end_time = 0.5
metric = "velocity_rmse"
metric_label = "velocity RMSE [m/s]"
kernels = ["umls", "bspline2"]
refine = [1, 2]
h = 0.5

[[stability]]
name = "disks"
title = "Colliding disks"
scene = "colliding-disks"
end_time = 1.0
kernels = ["linear-fe"]
set = ["transfer.alpha=1.0"]
x = { key = "time.dt", label = "time step [s]", values = [1e-3, 0.2] }
y = { key = "mesh.lattice.jitter", label = "mesh jitter [h]", values = [0.0] }

[[history]]
name = "disks-energy"
title = "Colliding disks: total energy"
scene = "colliding-disks"
end_time = 0.02
kernels = ["bspline2"]
transfers = ["apic", "flip:0.99"]
column = "total"
column_label = "total energy / initial [-]"
relative = true

[[throughput]]
name = "column"
title = "Column throughput"
scene = "hydrostatic-column"
end_time = 0.002
kernels = ["umls"]
threads = [1, 2]
repeats = 2
"#;

#[test]
fn a_tiny_matrix_makes_a_complete_report() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("report");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let matrix = dir.join("tiny.toml");
    std::fs::write(&matrix, MATRIX).unwrap();
    let out = dir.join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_umls"))
        .args(["report", "--matrix", matrix.to_str().unwrap()])
        .args(["--out", out.to_str().unwrap()])
        .args(["--criterion", dir.join("no-criterion").to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    // Progress names every run: 4 bar runs, 2 stability cells, 2 histories, and 2
    // throughput measurements run twice each.
    assert!(stderr.contains("[12/12]"), "{stderr}");

    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for kernel in ["umls", "bspline2", "linear-fe"] {
        assert!(
            report.contains(&format!("`{kernel}`")),
            "{kernel} in {report}"
        );
    }
    for chart in [
        "bar-speed-accuracy",
        "bar-convergence",
        "disks-stability",
        "disks-energy",
        "column-stages",
    ] {
        let file = out.join(format!("charts/{chart}.svg"));
        let svg = std::fs::read_to_string(&file).unwrap_or_else(|_| panic!("{chart}"));
        assert!(svg.starts_with("<svg"), "{chart}");
        assert!(
            report.contains(&format!("(charts/{chart}.svg)")),
            "{chart} linked"
        );
    }
    // The convergence chart is labelled with the metric and the cell size.
    let convergence = std::fs::read_to_string(out.join("charts/bar-convergence.svg")).unwrap();
    assert!(convergence.contains("velocity RMSE [m/s]") && convergence.contains("cell size h [m]"));
    // One CSV row per run, with the metric for the accuracy runs.
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let header = reader.headers().unwrap().clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 12);
    let bar_metrics: Vec<f64> = rows
        .iter()
        .filter(|r| &r[column("study")] == "bar")
        .map(|r| r[column("metric")].parse().unwrap())
        .collect();
    assert_eq!(bar_metrics.len(), 4);
    assert!(
        bar_metrics
            .iter()
            .all(|m| m.is_finite() && *m > 0.0 && *m < 1e-2),
        "{bar_metrics:?}"
    );
    // The huge time step failed, the small one completed; the report says which and why.
    let disks: Vec<&csv::StringRecord> = rows
        .iter()
        .filter(|r| &r[column("study")] == "disks")
        .collect();
    let outcome = |x: &str| {
        disks
            .iter()
            .find(|r| &r[column("x")] == x)
            .map(|r| {
                (
                    r[column("outcome")].to_string(),
                    r[column("failure_kind")].to_string(),
                )
            })
            .unwrap()
    };
    assert_eq!(outcome("0.001").0, "completed");
    let (failed, kind) = outcome("0.2");
    assert_eq!(failed, "failed");
    assert!(!kind.is_empty());
    assert!(
        report.contains("Runs that did not complete") && report.contains(&kind),
        "{report}"
    );
    // The histories are relative to their start and written as data.
    let apic =
        std::fs::read_to_string(out.join("histories/disks-energy_bspline2--apic.csv")).unwrap();
    let first: f64 = apic
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(first, 1.0);
    // Throughput rows carry the stage breakdown and, on 2 threads, the speed-up; each
    // measurement appears once, as the faster of its two runs.
    assert!(report.contains("speed-up over 1 thread"));
    let throughput = &report[report.find("### Column throughput").unwrap()..];
    let shown: Vec<(usize, f64)> = throughput
        .lines()
        .filter(|l| l.starts_with("| umls |"))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            Some((cells[3].parse().ok()?, cells[5].parse().ok()?))
        })
        .collect();
    assert_eq!(shown.len(), 2, "{report}");
    for (threads, rate) in shown {
        let runs: Vec<f64> = rows
            .iter()
            .filter(|r| {
                &r[column("study")] == "column" && r[column("threads")] == *threads.to_string()
            })
            .map(|r| {
                r[column("particle_steps_per_second")]
                    .parse::<f64>()
                    .unwrap()
                    / 1e6
            })
            .collect();
        assert_eq!(runs.len(), 2);
        let fastest = runs.iter().copied().fold(0.0, f64::max);
        assert!(
            (rate - fastest).abs() <= 0.01 * fastest,
            "{threads} threads: {rate} shown, runs {runs:?}"
        );
    }
    assert!(report.contains("No criterion results under"));
    // Frames are removed, summaries kept.
    let runs = out.join("runs");
    let kept: Vec<PathBuf> = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(
        kept.iter()
            .all(|d| d.join("summary.json").is_file() && !d.join("particles.pvd").exists())
    );
}

#[test]
fn a_bad_matrix_names_its_key() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("report-bad");
    std::fs::create_dir_all(&dir).unwrap();
    for (text, key, value) in [
        (
            "title = \"x\"\n[[accuracy]]\nname = \"a\"\ntitle = \"A\"\nscene = \"vortex\"\nmetric = \"m\"\nmetric_label = \"m\"\nkernels = [\"umls\"]\ntransfers = [\"flop\"]\nrefine = [1]\nh = 0.1\n",
            "a.transfers",
            "flop",
        ),
        (
            "title = \"x\"\n[[throughput]]\nname = \"t\"\ntitle = \"T\"\nscene = \"vortex\"\nkernels = [\"umls\"]\nthreads = [1]\nrepeats = 0\n",
            "t.repeats",
            "at least one",
        ),
    ] {
        let matrix = dir.join("bad.toml");
        std::fs::write(&matrix, text).unwrap();
        let run = Command::new(env!("CARGO_BIN_EXE_umls"))
            .args(["report", "--matrix", matrix.to_str().unwrap(), "--out"])
            .arg(dir.join("out"))
            .output()
            .unwrap();
        assert!(!run.status.success());
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(stderr.contains(key) && stderr.contains(value), "{stderr}");
    }
}
