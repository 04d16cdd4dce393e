//! The cantilever held on its clamp's face (`imposed = "face"`): the paper's rotation
//! test. Turning the mesh under the beam moves the node clamp's last row of nodes inside
//! the clamp and lengthens the free beam; held on the face x = 0, the tip history is the
//! same at every angle within the paper's 5 %. In 3D the built-in `cantilever-3d` beam on
//! Kuhn tetrahedra swings alike wherever the lattice lies under it, and converges to its
//! reference history under refinement.

use umls_runner::edit::refine;
use umls_runner::run::run;
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;

#[path = "common/runs.rs"]
mod runs;
use runs::{History, metric, options, variant};

/// The largest |u| of the reference tip history over t ≤ `end`.
fn reference_scale(end: f64) -> f64 {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/data/cantilever-tip.csv"
    );
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            v
        })
        .filter(|v| v[0] <= end)
        .map(|v| v[1].hypot(v[2]))
        .fold(0.0, f64::max)
}

/// The probe's displacement history (t, u_x, u_y) of `scene` turned by `angle` degrees,
/// with the clamp imposed as `imposed`, to t = 1.
fn tip_history(scene: &str, angle: f64, imposed: &str) -> Vec<[f64; 3]> {
    let edited = variant(
        scene,
        &[
            ("rotation = 0.0", &format!("rotation = {angle:.1}")),
            (
                "upper = [0.0, 10.0] } }",
                &format!("upper = [0.0, 10.0] }} }}\nimposed = \"{imposed}\""),
            ),
        ],
    );
    let name = format!("face-clamp-{scene}-{angle}-{imposed}");
    let out = options(&name, Some(KernelKind::Umls), Some(1.0));
    run(&edited, &out).unwrap();
    let history = History::read(out.out.as_deref().unwrap());
    let (t, ux, uy) = (
        history.column("time"),
        history.column("probe0_ux"),
        history.column("probe0_uy"),
    );
    history.rows.iter().map(|r| [r[t], r[ux], r[uy]]).collect()
}

/// The largest difference between the turned runs' tip histories and the aligned run's,
/// over the reference's largest deflection, at 15, 30 and 45°.
fn differences_to_aligned(scene: &str, imposed: &str) -> [f64; 3] {
    let scale = reference_scale(1.0);
    let aligned = tip_history(scene, 0.0, imposed);
    [15.0, 30.0, 45.0].map(|angle| {
        let turned = tip_history(scene, angle, imposed);
        aligned
            .iter()
            .zip(&turned)
            .map(|(a, b)| {
                // The mesh turns rigidly, so every angle takes the same steps.
                assert_eq!(a[0], b[0]);
                (a[1] - b[1]).hypot(a[2] - b[2])
            })
            .fold(0.0, f64::max)
            / scale
    })
}

/// UMLS on the scene's lattice (h = 0.25, the beam four cells thick): held on the face
/// the turned runs are within 5 % of the aligned one (measured 4.3 / 3.0 / 2.5 % at 15 /
/// 30 / 45°); on the node clamp they are not (14.0 / 20.1 / 20.0 %).
#[test]
fn on_the_lattice_the_face_clamp_turns_with_the_mesh_within_five_percent() {
    let face = differences_to_aligned("cantilever", "face");
    assert!(face.iter().all(|&d| d < 0.05), "face {face:?}");
    let nodes = differences_to_aligned("cantilever", "nodes");
    assert!(nodes.iter().all(|&d| d > 0.1), "nodes {nodes:?}");
}

/// UMLS on the unstructured Gmsh room (triangles of size 0.25): held on the face the
/// turned runs are within 5 % of the aligned one (measured 1.2 / 1.4 / 0.9 %); on the
/// node clamp the 45° run is not (7.7 / 0.2 / 18.6 %).
#[test]
fn on_the_unstructured_mesh_the_face_clamp_turns_with_the_mesh_within_five_percent() {
    let face = differences_to_aligned("cantilever-unstructured", "face");
    assert!(face.iter().all(|&d| d < 0.05), "face {face:?}");
    let nodes = differences_to_aligned("cantilever-unstructured", "nodes");
    assert!(nodes[2] > 0.1, "nodes {nodes:?}");
}

/// The built-in `cantilever-3d`: the beam [−0.5, 2.5] × [0, 0.5] × [0, 0.5] (E = 10⁷,
/// ρ = 1000, particles 0.125 apart) embedded in the clamp x ≤ 0, imposed as `imposed`,
/// on a Kuhn lattice of cells 0.25 moved by `shift` cells along −x. The deepest probe
/// u_y at the free end over its first swing (t ≤ 0.45).
fn deepest_3d_tip(shift: f64, imposed: &str) -> f64 {
    let dx = shift * 0.25;
    // Edited by key, as `--set` does: a text match could hit the header's comments.
    let edits = [
        ("mesh.lattice.lower", format!("[{}, -2.0, -0.5]", -1.5 - dx)),
        ("mesh.lattice.upper", format!("[{}, 1.5, 1.0]", 3.5 - dx)),
        ("boundaries.0.imposed", format!("\"{imposed}\"")),
    ]
    .map(|(key, value)| (key.to_string(), value));
    let scene = Scene::load_with("cantilever-3d", &edits).unwrap();
    let out = options(&format!("face-clamp-3d-{shift}-{imposed}"), None, None);
    run(&scene, &out).unwrap();
    let history = History::read(out.out.as_deref().unwrap());
    let uy = history.column("probe0_uy");
    history.rows.iter().map(|r| r[uy]).fold(0.0, f64::min)
}

/// The 3D beam on the lattice moved by half a cell along it: held on the
/// face its deepest swing moves by under 3 % (measured −0.371 to −0.366, 1.4 %), on the
/// node clamp by over 10 % (−0.444 to −0.526, 18.5 %): the half cell of free beam the
/// node clamp's last layer of nodes adds. The same as the engine's 3D test, from the
/// built-in scene.
#[test]
fn in_3d_the_face_clamp_holds_wherever_the_tetrahedra_lie() {
    let change = |imposed| {
        let (unmoved, moved) = (deepest_3d_tip(0.0, imposed), deepest_3d_tip(0.5, imposed));
        (moved - unmoved).abs() / unmoved.abs()
    };
    let face = change("face");
    let nodes = change("nodes");
    assert!(face < 0.03, "face clamp: {face}");
    assert!(nodes > 0.1, "node clamp: {nodes}");
}

/// `cantilever-3d` with `umls` refined `k` times: the largest difference between the
/// probe's displacement and the scene's reference history (the scene refined 9 times with
/// quadratic B-splines), over the reference's deepest swing.
fn error_against_3d_reference(k: f64) -> f64 {
    let mut scene = Scene::load("cantilever-3d").unwrap();
    refine(&mut scene, k).unwrap();
    let out = options(&format!("cantilever-3d-refined-{k}"), None, None);
    let report = run(&scene, &out).unwrap();
    assert_eq!(
        report.summary.to_json()["status"],
        "completed",
        "{}",
        report.summary.to_json()
    );
    metric(&report.summary.to_json(), "probe_error_max")
}

/// Held on its face, the 3D beam's probe converges to the reference history: `umls`
/// misses it by 0.208 of the deepest swing at the scene's resolution (the beam two cells
/// thick) and by 0.047 refined three times, an order of 1.36 in h; asserted: below 0.06
/// at k = 3 and an order above 1.
#[test]
fn the_3d_beam_held_on_its_face_converges_to_its_reference_history() {
    let coarse = error_against_3d_reference(1.0);
    let fine = error_against_3d_reference(3.0);
    assert!(fine < 0.06, "refined 3 times: {fine}");
    assert!(coarse / fine > 3.0, "h: {coarse}, h/3: {fine}");
}
