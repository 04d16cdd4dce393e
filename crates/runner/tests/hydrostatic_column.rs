//! The hydrostatic-column scenes: their metrics against the closed form, the metrics
//! themselves against an exactly known state, and a turned scene against the upright one.

use umls_runner::run::run;
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;

#[path = "common/runs.rs"]
mod runs;
use runs::{History, metric, options, variant};

/// The upright 2D column's summary with `kernel`, run in the output directory `name`.
fn column_with(kernel: KernelKind, name: &str) -> serde_json::Value {
    let scene = Scene::load("hydrostatic-column").unwrap();
    run(&scene, &options(name, Some(kernel), None))
        .unwrap()
        .summary
        .to_json()
}

/// Particles that start at the geostatic stress of the exact solution: one short step
/// later every stress metric reads the closed form, in the upright scene and in the
/// scene turned by 30° (where stresses and depths go through the frame), and nothing has
/// settled yet.
#[test]
fn metrics_read_the_exact_state_as_exact() {
    for name in [
        "hydrostatic-column",
        "hydrostatic-column-tilted",
        "hydrostatic-column-3d",
    ] {
        let stress = format!(
            "[initial_stress]\ngeostatic_k0 = {}\n\n[damping]",
            0.3 / 0.7
        );
        let scene = variant(name, &[("[damping]", &stress)]);
        let report = run(
            &scene,
            &options(
                &format!("{name}-exact"),
                Some(KernelKind::Bspline2),
                Some(1e-9),
            ),
        )
        .unwrap();
        let s = &report.summary.to_json();
        // The geostatic depth is measured from the top of the top particles, which is
        // the column's surface: the initial stress is the exact one (Newton's method
        // solves the pre-strain to ~1e-10 relative).
        assert!(metric(s, "stress_rms") < 1e-8, "{name}: {s}");
        assert!((metric(s, "bottom_row_ratio") - 1.0).abs() < 1e-8, "{name}");
        assert!((metric(s, "k0") - 0.3 / 0.7).abs() < 1e-8, "{name}");
        assert_eq!(metric(s, "k0_exact"), 0.3 / 0.7);
        assert!(metric(s, "settlement").abs() < 1e-12, "{name}");
        // ρ g H² / (2M), M = E(1 − ν)/((1 + ν)(1 − 2ν)).
        let modulus = 1e8 * 0.7 / (1.3 * 0.4);
        let expected = 1000.0 * 10.0 * 16.0 / (2.0 * modulus);
        assert!((metric(s, "settlement_exact") - expected).abs() < 1e-15);
    }
}

/// A fluid at rest in the curved containers, started at its hydrostatic pressure
/// (`geostatic_k0 = 1`): one short step later the stress metrics read the closed form
/// (pressure ρ g d, K0 = 1), in 2D and 3D and with a mesh and a grid kernel, and no
/// settlement is reported, since a fluid's depends on its container.
#[test]
fn fluid_metrics_read_the_exact_pressure_as_exact() {
    for name in ["fluid-bowl", "fluid-bowl-3d"] {
        for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
            let stress = "[initial_stress]\ngeostatic_k0 = 1.0\n\n[damping]";
            let scene = variant(name, &[("[damping]", stress)]);
            let report = run(
                &scene,
                &options(
                    &format!("{name}-{kernel:?}-exact"),
                    Some(kernel),
                    Some(1e-9),
                ),
            )
            .unwrap();
            let s = &report.summary.to_json();
            assert!(metric(s, "stress_rms") < 1e-8, "{name} {kernel:?}: {s}");
            assert!((metric(s, "bottom_row_ratio") - 1.0).abs() < 1e-8, "{name}");
            assert!((metric(s, "k0") - 1.0).abs() < 1e-8, "{name}");
            assert_eq!(metric(s, "k0_exact"), 1.0);
            assert!(s["metrics"].get("settlement_ratio").is_none(), "{name}");
        }
    }
}

/// Where the wall is curved, the conforming mesh carries the fluid's pressure and the
/// grid's staircase does not: at rest in the 2D bowl UMLS's interior pressure error is
/// under a third of quadratic B-splines' (5.4× lower when measured; both errors sit at
/// the wall), and its bottom row is within 5 % of the exact load.
#[test]
fn in_a_curved_container_umls_carries_the_pressure_the_grid_does_not() {
    let scene = Scene::load("fluid-bowl").unwrap();
    let summary = |kernel: KernelKind, name: &str| {
        let report = run(&scene, &options(name, Some(kernel), None)).unwrap();
        let s = report.summary.to_json();
        assert_eq!(s["status"], "completed", "{name}: {s}");
        s
    };
    let umls = summary(KernelKind::Umls, "fluid-bowl-umls");
    let grid = summary(KernelKind::Bspline2, "fluid-bowl-bspline2");
    let (u, g) = (metric(&umls, "stress_rms"), metric(&grid, "stress_rms"));
    assert!(3.0 * u < g, "umls {u}, bspline2 {g}");
    assert!((metric(&umls, "bottom_row_ratio") - 1.0).abs() < 0.05);
}

/// Quadratic B-splines bring the upright column to rest at the closed form: interior
/// stress within 1 % of ρgH (RMS), bottom row and settlement within 7 %, K0 within 1 %.
#[test]
fn bspline_column_settles_at_the_closed_form() {
    let scene = Scene::load("hydrostatic-column").unwrap();
    let report = run(
        &scene,
        &options("column-bspline2", Some(KernelKind::Bspline2), None),
    )
    .unwrap();
    let s = &report.summary.to_json();
    assert!(metric(s, "stress_rms") < 0.01, "{s}");
    assert!((metric(s, "bottom_row_ratio") - 1.0).abs() < 0.07, "{s}");
    assert!(
        (metric(s, "k0") / metric(s, "k0_exact") - 1.0).abs() < 0.01,
        "{s}"
    );
    assert!((metric(s, "settlement_ratio") - 1.0).abs() < 0.07, "{s}");
    // The walls' reactions at rest: the base carries the weight ρgHW = 40 kN, each side
    // wall the lateral thrust K0 ρ g H² / 2 = 34.3 kN (per unit depth).
    let history = History::read(report.out.as_deref().unwrap());
    let column = |name: &str| history.last(name);
    let weight = 1000.0 * 10.0 * 4.0;
    assert!(
        (column("reaction2_y") / weight - 1.0).abs() < 1e-3,
        "{}",
        column("reaction2_y")
    );
    let thrust = 0.3 / 0.7 * 1000.0 * 10.0 * 16.0 / 2.0;
    assert!(
        (column("reaction0_x") / thrust - 1.0).abs() < 0.05,
        "{}",
        column("reaction0_x")
    );
    // The two side walls push back equally (to round-off: the column is symmetric).
    let (left, right) = (column("reaction0_x"), column("reaction1_x"));
    assert!((left + right).abs() < 1e-9 * left, "{left} vs {right}");
}

/// A mesh kernel on the turned scene solves the same problem: with mass-proportional
/// damping (which does not depend on the axes) the metrics of the column turned by 30°
/// equal the upright ones to round-off. Local damping acts per world axis, so it differs
/// slightly, but it must still bring the turned column to rest: it used to damp the
/// wall's reaction along the inclined walls, and the column crept down them.
#[test]
fn turned_column_on_its_mesh_is_the_upright_column() {
    let metrics = |scene: &Scene, name: &str| {
        let report = run(scene, &options(name, Some(KernelKind::LinearFe), None)).unwrap();
        report.summary.to_json()["metrics"].clone()
    };
    let keys = ["stress_rms", "bottom_row_ratio", "k0", "settlement_ratio"];
    let mass = "[damping]\nmass = 100.0";
    let upright = metrics(
        &variant("hydrostatic-column", &[("[damping]\nlocal = 0.5", mass)]),
        "column-upright",
    );
    let turned = metrics(
        &variant(
            "hydrostatic-column-tilted",
            &[("[damping]\nlocal = 0.5", mass)],
        ),
        "column-turned",
    );
    for key in keys {
        let (a, b) = (
            upright[key].as_f64().unwrap(),
            turned[key].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-7 * a.abs(), "{key}: {a} vs {b}");
    }
    let local = metrics(
        &Scene::load("hydrostatic-column-tilted").unwrap(),
        "column-turned-local",
    );
    let upright_local = metrics(
        &Scene::load("hydrostatic-column").unwrap(),
        "column-upright-local",
    );
    for key in keys {
        let (a, b) = (
            upright_local[key].as_f64().unwrap(),
            local[key].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-3 * a.abs(), "{key}: {a} vs {b}");
    }
}

/// The wide support the incident-edge support replaced misses the column's base (bottom
/// row 1.74 × exact; the default meets it, `integration_correction_meets_every_column_target`
/// below), which shows the scene-file names select what they say.
#[test]
fn the_wide_support_overloads_the_column_base() {
    let wide = column_with(KernelKind::UmlsWide, "column-umls-wide");
    assert_eq!(wide["kernel"], "umls-wide");
    assert!(metric(&wide, "bottom_row_ratio") > 1.5, "{wide}");
}

/// The consistent mass matrix solved for the forces as well keeps the walls' reactions
/// where they belong: its iterations are projected on the boundary conditions, so the
/// force a fixed or slip node carries into its wall is not spread to the free nodes
/// beside it (unprojected, the base carried 0.58 of the exact stress). The column then
/// settles where the lumped one does (measured: interior RMS 0.0185, bottom row 1.011,
/// K0 0.4286 for both).
#[test]
fn consistent_mass_keeps_the_column_on_its_walls() {
    let settle = |mass: &str| {
        let scene = variant(
            "hydrostatic-column",
            &[("[time]", &format!("{mass}\n[time]"))],
        );
        let report = run(
            &scene,
            &options(&format!("column-umls-mass-{}", mass.len()), None, None),
        )
        .unwrap();
        let s = report.summary.to_json();
        (
            metric(&s, "stress_rms"),
            metric(&s, "bottom_row_ratio"),
            metric(&s, "k0"),
            s["transfer"].as_str().unwrap().to_owned(),
        )
    };
    let lumped = settle("");
    let consistent = settle("mass = { iterations = 2, forces = true }");
    assert!(
        consistent
            .3
            .contains("consistent mass (2 iterations, forces too)")
    );
    assert!(consistent.0 <= 0.02, "{consistent:?}");
    assert!(
        (consistent.1 - lumped.1).abs() < 0.01,
        "{consistent:?} {lumped:?}"
    );
    assert!(
        (consistent.2 - lumped.2).abs() < 0.005,
        "{consistent:?} {lumped:?}"
    );
}

/// `[kernel] support_factor` overrides the name's preset (a narrower support carries the
/// wall better still), and a factor that is not positive is an error naming the key.
#[test]
fn kernel_support_keys_override_the_preset() {
    let narrow = variant(
        "hydrostatic-column",
        &[("kind = \"umls\"", "kind = \"umls\"\nsupport_factor = 0.6")],
    );
    let report = run(&narrow, &options("column-umls-narrow", None, None)).unwrap();
    // Measured 0.0046 (0.0046 without the integration correction too).
    assert!(
        metric(&report.summary.to_json(), "stress_rms") < 0.01,
        "{}",
        report.summary.to_json()
    );
    let bad = variant(
        "hydrostatic-column",
        &[("kind = \"umls\"", "kind = \"umls\"\nsupport_factor = -1.0")],
    );
    let error = run(&bad, &options("column-umls-bad", None, Some(0.01)))
        .unwrap_err()
        .to_string();
    assert!(error.contains("kernel.support_factor"), "{error}");
    let bad = variant(
        "hydrostatic-column",
        &[(
            "kind = \"umls\"",
            "kind = \"umls\"\nweight = \"sharpened\"\nsharpening = 0.0",
        )],
    );
    let error = run(
        &bad,
        &options("column-umls-bad-sharpening", None, Some(0.01)),
    )
    .unwrap_err()
    .to_string();
    assert!(error.contains("kernel.sharpening"), "{error}");
}

/// `[kernel] diminishing_exponent` with `support_factor` on `umls` is `umls-eta4`
/// bit for bit, and an exponent of 0 (every ring vertex weighted alike, weights that jump
/// across facets) is an error naming the key.
#[test]
fn the_diminishing_exponent_key_gives_the_eta4_kernel() {
    let end = Some(0.3);
    let keyed = variant(
        "hydrostatic-column",
        &[(
            "kind = \"umls\"",
            "kind = \"umls\"\nsupport_factor = 1.4\ndiminishing_exponent = 4",
        )],
    );
    let keyed = run(&keyed, &options("column-eta4-key", None, end)).unwrap();
    let named = run(
        &Scene::load("hydrostatic-column").unwrap(),
        &options("column-eta4-name", Some(KernelKind::UmlsEta4), end),
    )
    .unwrap();
    assert_eq!(named.summary.to_json()["kernel"], "umls-eta4");
    let rms = |r: &umls_runner::run::RunReport| metric(&r.summary.to_json(), "stress_rms");
    assert_eq!(rms(&keyed).to_bits(), rms(&named).to_bits());
    let plain = run(
        &Scene::load("hydrostatic-column").unwrap(),
        &options("column-eta4-plain", None, end),
    )
    .unwrap();
    assert_ne!(rms(&plain).to_bits(), rms(&named).to_bits());
    let bad = variant(
        "hydrostatic-column",
        &[(
            "kind = \"umls\"",
            "kind = \"umls\"\ndiminishing_exponent = 0",
        )],
    );
    let error = run(&bad, &options("column-eta4-bad", None, Some(0.01)))
        .unwrap_err()
        .to_string();
    assert!(error.contains("kernel.diminishing_exponent"), "{error}");
}

/// Sharpened weights (`umls-sharp`) concentrate the fit on the nearest vertices and carry
/// the column's walls better than the plain profile without the integration correction
/// (measured: interior RMS 0.0058 against `umls-uncorrected`'s 0.019, bottom row 1.010).
#[test]
fn sharpened_weights_carry_the_column() {
    let s = &column_with(KernelKind::UmlsSharp, "column-umls-sharp");
    assert_eq!(s["kernel"], "umls-sharp");
    assert!(metric(s, "stress_rms") < 0.01, "{s}");
    assert!((metric(s, "bottom_row_ratio") - 1.0).abs() < 0.03, "{s}");
}

/// On unstructured tetrahedra the reconstructed gradient is not divergence-consistent
/// (docs/umls-kernel.md), and `umls-full-gradient` brings the 3D Gmsh column within the
/// issue's target (measured 0.035, bottom row 1.058, K0 0.420 against 0.429; the uncorrected
/// reconstructed gradient gives 0.081, the default `umls` with its integration correction
/// 0.0165). On the 2D lattice the same choice loses (measured
/// settlement 1.15 × the closed form against 1.004), and `[kernel] gradient` selects the
/// gradient whatever the name: `umls-uncorrected` with `gradient = "full"` is
/// `umls-full-gradient` bit for bit, and the reverse override gives `umls-uncorrected`
/// back.
#[test]
fn full_gradient_meets_the_gmsh_tetrahedra_column_and_the_gradient_key_selects_it() {
    let scene = Scene::load("hydrostatic-column-3d-gmsh").unwrap();
    let report = run(
        &scene,
        &options(
            "column-3d-gmsh-full",
            Some(KernelKind::UmlsFullGradient),
            None,
        ),
    )
    .unwrap();
    let s = &report.summary.to_json();
    assert_eq!(s["kernel"], "umls-full-gradient");
    assert!(metric(s, "stress_rms") <= 0.05, "{s}");
    assert!((metric(s, "bottom_row_ratio") - 1.0).abs() < 0.1, "{s}");
    assert!(
        (metric(s, "k0") / metric(s, "k0_exact") - 1.0).abs() < 0.05,
        "{s}"
    );

    let keyed = same_with_key_as_name("full", KernelKind::UmlsFullGradient);
    let (reverted, plain) = short_rms(
        "hydrostatic-column",
        "kind = \"umls-full-gradient\"\ngradient = \"reconstructed\"",
        KernelKind::UmlsUncorrected,
    );
    assert_eq!(reverted.to_bits(), plain.to_bits());
    assert_ne!(
        metric(&keyed.summary.to_json(), "stress_rms").to_bits(),
        plain.to_bits()
    );
}

/// The interior stress error after 0.3 s of column `name` with its `kind = "umls"` line
/// replaced by `kernel_lines`, and of the scene as it is with the kernel `kind`.
fn short_rms(name: &str, kernel_lines: &str, kind: KernelKind) -> (f64, f64) {
    let end = Some(0.3);
    let edited = variant(name, &[("kind = \"umls\"", kernel_lines)]);
    let tag = format!("{name}-{}", kind.name());
    let edited = run(&edited, &options(&format!("{tag}-edited"), None, end)).unwrap();
    let named = run(&Scene::load(name).unwrap(), &options(&tag, Some(kind), end)).unwrap();
    let rms = |r: &umls_runner::run::RunReport| metric(&r.summary.to_json(), "stress_rms");
    (rms(&edited), rms(&named))
}

/// The derivative at frozen η (`umls-frozen-eta`, docs/umls-kernel.md) keeps the
/// reconstructed gradient's continuity and adds the smooth distance weights' share of the
/// full derivative. On the 2D columns it is more accurate than quadratic B-splines
/// (measured interior RMS 0.0018 on the lattice and turned by 30°, 0.0024 on Gmsh
/// triangles, against bspline2's 0.0069, 0.048 and 0.0070), with the bottom row within
/// 2 % and K0 within 0.1 %; `gradient = "frozen-eta"` selects it on any UMLS name.
#[test]
fn frozen_eta_gradient_beats_bspline2_on_the_2d_columns() {
    for name in [
        "hydrostatic-column",
        "hydrostatic-column-tilted",
        "hydrostatic-column-gmsh",
    ] {
        let scene = Scene::load(name).unwrap();
        let frozen = run(
            &scene,
            &options(
                &format!("{name}-frozen-eta"),
                Some(KernelKind::UmlsFrozenEta),
                None,
            ),
        )
        .unwrap();
        let grid = run(
            &scene,
            &options(
                &format!("{name}-frozen-eta-bspline2"),
                Some(KernelKind::Bspline2),
                None,
            ),
        )
        .unwrap();
        let (s, b) = (&frozen.summary.to_json(), &grid.summary.to_json());
        assert_eq!(s["kernel"], "umls-frozen-eta");
        assert!(
            metric(s, "stress_rms") < metric(b, "stress_rms"),
            "{name}: {s} against {b}"
        );
        assert!(metric(s, "stress_rms") < 0.005, "{name}: {s}");
        assert!(
            (metric(s, "bottom_row_ratio") - 1.0).abs() < 0.02,
            "{name}: {s}"
        );
        assert!(
            (metric(s, "k0") / metric(s, "k0_exact") - 1.0).abs() < 0.001,
            "{name}: {s}"
        );
    }
    same_with_key_as_name("frozen-eta", KernelKind::UmlsFrozenEta);
}

/// Runs the 2D column for 0.3 s with `[kernel] gradient = key` on `umls-uncorrected` (the
/// kernel the other names vary) and with the kernel name `kind`, asserts the same bits,
/// and returns the keyed run.
fn same_with_key_as_name(key: &str, kind: KernelKind) -> umls_runner::run::RunReport {
    let end = Some(0.3);
    let by_key = variant(
        "hydrostatic-column",
        &[(
            "kind = \"umls\"",
            &format!("kind = \"umls-uncorrected\"\ngradient = \"{key}\""),
        )],
    );
    let keyed = run(
        &by_key,
        &options(&format!("column-umls-{key}-key"), None, end),
    )
    .unwrap();
    let named = run(
        &Scene::load("hydrostatic-column").unwrap(),
        &options(&format!("column-umls-{key}-name"), Some(kind), end),
    )
    .unwrap();
    let rms = |r: &umls_runner::run::RunReport| metric(&r.summary.to_json(), "stress_rms");
    assert_eq!(rms(&keyed).to_bits(), rms(&named).to_bits(), "{key}");
    keyed
}

/// The default `umls`, with the integration correction, meets the targets on
/// every column, the 3D Gmsh tetrahedra included, which the uncorrected kernel misses
/// (measured 0.081): interior RMS ≤ 0.02 in 2D and ≤ 0.05 in 3D, bottom row within 10 %,
/// K0 within 5 % (measured 0.0185 / 0.0041 / 0.0052 / 0.0165 on the 2D lattice, 2D
/// Gmsh, 3D Kuhn and 3D Gmsh columns). On the Gmsh meshes it is also at least twice as
/// accurate as `umls-uncorrected`. `[kernel] integration_correction = true` on
/// `umls-uncorrected` is `umls` bit for bit.
#[test]
fn integration_correction_meets_every_column_target() {
    for (name, target) in [
        ("hydrostatic-column", 0.02),
        ("hydrostatic-column-gmsh", 0.02),
        ("hydrostatic-column-3d", 0.05),
        ("hydrostatic-column-3d-gmsh", 0.05),
    ] {
        let scene = Scene::load(name).unwrap();
        let corrected = run(&scene, &options(&format!("{name}-umls"), None, None)).unwrap();
        let s = &corrected.summary.to_json();
        assert_eq!(s["kernel"], "umls");
        assert!(metric(s, "stress_rms") <= target, "{name}: {s}");
        assert!(
            (metric(s, "bottom_row_ratio") - 1.0).abs() < 0.1,
            "{name}: {s}"
        );
        assert!(
            (metric(s, "k0") / metric(s, "k0_exact") - 1.0).abs() < 0.05,
            "{name}: {s}"
        );
        if name.ends_with("gmsh") {
            let plain = run(
                &scene,
                &options(
                    &format!("{name}-uncorrected"),
                    Some(KernelKind::UmlsUncorrected),
                    None,
                ),
            )
            .unwrap();
            assert!(
                metric(s, "stress_rms") < 0.5 * metric(&plain.summary.to_json(), "stress_rms"),
                "{name}: {s} against {}",
                plain.summary.to_json()
            );
        }
    }
    let name = "hydrostatic-column-gmsh";
    let key = "kind = \"umls-uncorrected\"\nintegration_correction = true";
    let (keyed, named) = short_rms(name, key, KernelKind::Umls);
    let (_, plain) = short_rms(name, key, KernelKind::UmlsUncorrected);
    assert_eq!(keyed.to_bits(), named.to_bits());
    assert_ne!(keyed.to_bits(), plain.to_bits());
}
