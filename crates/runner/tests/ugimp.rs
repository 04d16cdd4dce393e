//! uGIMP (a kernel from its own crate) through the runner: `--kernel ugimp` on the
//! built-in scenes, against the quadratic B-spline it becomes at one particle per cell,
//! and converging on the column.

#[path = "common/runs.rs"]
mod runs;

use runs::options;
use umls_runner::schema::KernelKind;
use umls_runner::{RunStatus, Scene, run};

/// `metric` of `scene` refined by `refine` with `kernel`.
fn measured(scene: &str, kernel: KernelKind, refine: f64, metric: &str) -> f64 {
    let mut loaded = Scene::load_with(scene, &[("output.frames".into(), "2".into())]).unwrap();
    umls_runner::edit::refine(&mut loaded, refine).unwrap();
    let name = format!("ugimp-{scene}-{}-{refine}", kernel.name());
    let report = run(&loaded, &options(&name, Some(kernel), None)).unwrap();
    assert_eq!(report.summary.status, RunStatus::Completed);
    assert_eq!(report.summary.kernel, kernel.name());
    report.summary.metric(metric).unwrap()
}

#[test]
fn on_the_bar_at_one_particle_per_cell_it_is_the_quadratic_b_spline() {
    // The bar seeds one particle per cell, so uGIMP's boxes are a cell wide and its
    // weights the quadratic B-spline's: the same error to round-off.
    let gimp = measured("vibrating-bar", KernelKind::Ugimp, 1.0, "velocity_rmse");
    let spline = measured("vibrating-bar", KernelKind::Bspline2, 1.0, "velocity_rmse");
    assert!(gimp < 1e-3, "{gimp}");
    assert!((gimp - spline).abs() < 1e-9 * spline, "{gimp} vs {spline}");
}

#[test]
fn on_the_column_with_smaller_boxes_it_converges() {
    // Two particles per cell: l = h/4, a kernel of its own. Measured: 6.2e-3 and 3.1e-3.
    let coarse = measured("hydrostatic-column", KernelKind::Ugimp, 1.0, "stress_rms");
    let fine = measured("hydrostatic-column", KernelKind::Ugimp, 2.0, "stress_rms");
    assert!(coarse < 0.01, "{coarse}");
    assert!(fine < 0.6 * coarse, "{coarse} -> {fine}");
}
