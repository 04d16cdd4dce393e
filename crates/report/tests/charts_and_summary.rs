//! The summary's verdict on a study, and the charts a reader gets from a crowded study (13 kernels × 5 transfers, failures
//! among them, as the colliding disks have): at most eight curves per panel, every curve
//! of a panel in a style of its own, each kernel in the same style in every chart, failed
//! runs marked, and every legend line inside the canvas.

use std::collections::{HashMap, HashSet};

use umls_io::chart::{CHAR_WIDTH, PanelChart, Style};
use umls_report::case::StudyKind;
use umls_report::charts::{self, MAX_SERIES};
use umls_report::matrix::Matrix;
use umls_report::record::Record;
use umls_report::styles::kernel_style;
use umls_report::summary::verdict;

const KERNELS: [&str; 13] = [
    "umls",
    "umls-eta4",
    "umls-eta8",
    "umls-element-size",
    "umls-wide",
    "umls-frozen-eta",
    "umls-uncorrected",
    "umls-quadratic",
    "umls-sharp",
    "linear-fe",
    "bspline2",
    "bspline3",
    "my-own-kernel",
];
const TRANSFERS: [&str; 5] = [
    "flip:0.99",
    "apic",
    "apic-flip:0.99",
    "quadratic-apic",
    "quadratic-apic-flip:0.99",
];

fn record(kernel: &str, transfer: &str, refine: f64, completed: bool) -> Record {
    let seed = (kernel.len() * 7 + transfer.len() * 3) as f64;
    Record {
        study: "disks".into(),
        kind: StudyKind::Accuracy,
        scene: "colliding-disks".into(),
        kernel: kernel.into(),
        transfer: transfer.into(),
        variant: String::new(),
        refine,
        particle_refine: 1.0,
        x: String::new(),
        y: String::new(),
        threads: 2,
        repeat: 0,
        status: if completed { "completed" } else { "failed" }.into(),
        outcome: if completed { "completed" } else { "failed" }.into(),
        failure_kind: if completed { "" } else { "inverted" }.into(),
        error: String::new(),
        metric_name: "-energy_change_final".into(),
        metric: completed.then(|| 0.01 * seed / refine),
        energy_gain: Some(0.0),
        energy_change: Some(-0.1),
        particles: Some(1000),
        nodes: Some(500),
        steps: Some(100),
        dt: Some(1e-3),
        max_wave_courant: Some(0.3),
        step_time_s: Some(0.1 * seed * refine),
        wall_time_s: Some(1.0),
        process_time_s: 1.0,
        particle_steps_per_second: Some(1e6),
        peak_memory_bytes: Some(1 << 20),
        stage_stencils_s: None,
        stage_p2g_s: None,
        stage_grid_update_s: None,
        stage_g2p_s: None,
        stage_constitutive_s: None,
        stage_checks_s: None,
        out: String::new(),
    }
}

fn crowded() -> Vec<Record> {
    let mut records = Vec::new();
    for transfer in TRANSFERS {
        for kernel in KERNELS {
            for refine in [1.0, 2.0] {
                // linear-fe fails at the fine level under FLIP, as it may.
                let failed = kernel == "linear-fe" && transfer == "flip:0.99" && refine == 2.0;
                records.push(record(kernel, transfer, refine, !failed));
            }
        }
    }
    records
}

/// A text element of an SVG.
struct Text {
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    content: String,
}

/// The `<text>` elements of an SVG, with their horizontal extent estimated from the
/// font size, the anchor and [`CHAR_WIDTH`].
fn texts(svg: &str) -> Vec<Text> {
    let attribute = |tag: &str, name: &str| -> Option<String> {
        let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
        tag[start..].split('"').next().map(str::to_string)
    };
    let number = |tag: &str, name: &str| attribute(tag, name)?.parse::<f64>().ok();
    svg.split("<text")
        .skip(1)
        .filter_map(|rest| {
            let (tag, after) = rest.split_once('>')?;
            let content = after.split("</text>").next()?.trim().to_string();
            let (x, y, size) = (
                number(tag, "x")?,
                number(tag, "y")?,
                number(tag, "font-size")?,
            );
            let width = CHAR_WIDTH * size * content.chars().count() as f64;
            let (start, end) = match attribute(tag, "text-anchor").as_deref() {
                Some("middle") => (-width / 2.0, width / 2.0),
                Some("end") => (-width, 0.0),
                _ => (0.0, width),
            };
            // An axis label turned upright runs along y.
            let (left, right, top, bottom) = if tag.contains("rotate(270") {
                (x, x + size, y - end, y - start)
            } else if tag.contains("dy=\"0.76em\"") {
                // Hung from y: the glyphs lie below it.
                (x + start, x + end, y, y + size)
            } else {
                (x + start, x + end, y - size, y + size / 2.0)
            };
            Some(Text {
                left,
                right,
                top,
                bottom,
                content,
            })
        })
        .collect()
}

fn canvas(svg: &str) -> (f64, f64) {
    let head = svg.split('>').next().unwrap();
    let number = |name: &str| -> f64 {
        let start = head.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        head[start..].split('"').next().unwrap().parse().unwrap()
    };
    (number("width"), number("height"))
}

/// Checks one figure; returns each kernel's style in it.
fn check(figure: &PanelChart, failed_kernel: &str) -> HashMap<String, Style> {
    let mut seen = HashMap::new();
    let mut marked_failure = false;
    for panel in &figure.panels {
        assert!(
            panel.series.len() <= MAX_SERIES,
            "{}: {} series",
            panel.title,
            panel.series.len()
        );
        let styles = panel.styles();
        let distinct: HashSet<&Style> = styles.iter().collect();
        assert_eq!(
            distinct.len(),
            styles.len(),
            "{}: a style repeats",
            panel.title
        );
        for (series, style) in panel.series.iter().zip(styles) {
            seen.insert(series.label.clone(), style);
            if series.label == failed_kernel && series.failed_count > 0 {
                assert!(series.legend_label().contains("1 failed"));
                marked_failure = true;
            }
        }
    }
    assert!(
        marked_failure,
        "{}: the failed run is not marked",
        figure.title
    );
    let svg = figure.to_svg().unwrap();
    let (width, height) = canvas(&svg);
    assert_eq!((width, height), {
        let (w, h) = figure.size();
        (w as f64, h as f64)
    });
    let texts = texts(&svg);
    assert!(texts.iter().any(|t| t.content.contains("failed")));
    for t in texts {
        assert!(
            t.left >= 0.0 && t.right <= width && t.top >= 0.0 && t.bottom <= height,
            "`{}` spans x {:.0}–{:.0}, y {:.0}–{:.0}: outside the {width} × {height} canvas",
            t.content,
            t.left,
            t.right,
            t.top,
            t.bottom
        );
    }
    seen
}

#[test]
fn a_crowded_study_gives_readable_panels_in_fixed_styles() {
    let matrix = Matrix::parse(
        r#"
title = "t"
[[accuracy]]
name = "disks"
title = "Colliding disks: energy lost by t = 3"
scene = "colliding-disks"
metric = "-energy_change_final"
metric_label = "energy lost / initial energy [-]"
kernels = ["umls"]
refine = [1, 2]
h = 0.05
"#,
        "test",
    )
    .unwrap();
    let study = &matrix.accuracy[0];
    let records = crowded();
    let refs: Vec<&Record> = records.iter().collect();
    let speed = charts::speed_accuracy(study, &refs);
    let convergence = charts::convergence(study, &refs);
    // 5 transfers, each split into the established kernels and UMLS's variants.
    assert_eq!(speed.panels.len(), 10);
    let a = check(&speed, "linear-fe");
    let b = check(&convergence, "linear-fe");
    for kernel in KERNELS {
        assert!(a.contains_key(kernel), "{kernel} has no curve");
        if let Some(fixed) = kernel_style(kernel) {
            assert_eq!(a[kernel], fixed, "{kernel}");
            assert_eq!(b[kernel], fixed, "{kernel}");
        }
    }
    // The kernel without a fixed style still differs from every other in its panel
    // (checked above) and keeps one style across the two charts.
    assert_eq!(a["my-own-kernel"], b["my-own-kernel"]);
}

/// A run of `kernel` taking `time` with `error`.
fn timed(kernel: &str, time: f64, error: f64) -> Record {
    Record {
        step_time_s: Some(time),
        metric: Some(error),
        ..record(kernel, "apic", 1.0, true)
    }
}

#[test]
fn the_summary_names_the_front_at_equal_time_and_error() {
    let runs = [
        timed("umls", 1.0, 0.1),
        timed("umls", 4.0, 0.01),
        timed("bspline2", 2.0, 0.05),
        timed("bspline2", 8.0, 0.02),
        Record {
            step_time_s: Some(0.5),
            ..record("linear-fe", "apic", 1.0, false)
        },
    ];
    let refs: Vec<&Record> = runs.iter().collect();
    let v = verdict(&refs);
    // Equal error: the finer of the two families' best errors, 0.02; UMLS reaches it in
    // 4 s, bspline2 in 8 s.
    assert_eq!(v.at_equal_error, Some(("umls, apic".into(), 4.0, 0.02)));
    assert_eq!(
        v.mesh_against_grid,
        Some(("umls, apic".into(), 4.0, "bspline2, apic".into(), 8.0))
    );
    // Equal time: the larger of the cheapest runs, 2 s; bspline2's 0.05 beats UMLS's 0.1.
    // The failed linear-fe run counts for neither.
    assert_eq!(v.at_equal_time, Some(("bspline2, apic".into(), 0.05, 2.0)));
    // At any cost UMLS reaches 0.01, bspline2 0.02.
    assert_eq!(
        v.lowest,
        Some(("umls, apic".into(), 0.01, "bspline2, apic".into(), 0.02))
    );
}
