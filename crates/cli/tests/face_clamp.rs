//! The cantilever held on its clamp's face (`imposed = "face"`): the paper's rotation
//! test. Turning the mesh under the beam moves the node clamp's last row of nodes inside
//! the clamp and lengthens the free beam; held on the face x = 0, the tip history is the
//! same at every angle within the paper's 5 %.

use umls_cli::run::run;
use umls_cli::schema::KernelKind;

#[path = "common/runs.rs"]
mod runs;
use runs::{History, options, variant};

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
    let history = History::read(&out.out);
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
