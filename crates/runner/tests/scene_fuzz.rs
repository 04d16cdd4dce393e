//! Built-in scene files with numbers replaced by hostile values: building the scene
//! returns a setup or an error that starts with the file and names a key or a line,
//! never panics (random combinations, and every number with every hostile value). (Counts large enough to exhaust memory are
//! refused by explicit limits, tested in `scene_files.rs`; the largest count here is
//! 1000 so that the cases stay fast.)

use proptest::prelude::*;
use umls_runner::builtin::BUILTIN;
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;
use umls_runner::setup::{build_for, segments, tetrahedra, triangles};

/// Whether `umls run` would build this scene for a grid kernel (no simplices for a
/// lattice): the fuzz builds what a run builds.
fn grid(scene: &Scene) -> bool {
    matches!(
        scene.spec.kernel.kind,
        KernelKind::Bspline2 | KernelKind::Bspline3
    )
}

/// Byte ranges of the numeric literals of a scene text (outside comments and strings).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        let bytes = code.as_bytes();
        let mut i = 0;
        let mut in_string = false;
        while i < bytes.len() {
            let c = bytes[i];
            if c == b'"' {
                in_string = !in_string;
            }
            let starts = !in_string
                && (c.is_ascii_digit() || c == b'-')
                && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric() && bytes[i - 1] != b'_');
            if starts {
                let start = i;
                i += 1;
                while i < bytes.len()
                    && (bytes[i].is_ascii_alphanumeric() || matches!(bytes[i], b'.' | b'-' | b'+'))
                {
                    i += 1;
                }
                out.push((offset + start, offset + i));
            } else {
                i += 1;
            }
        }
        offset += line.len();
    }
    out
}

const HOSTILE: [&str; 14] = [
    "0", "-1", "1", "2", "0.0", "-0.5", "1e300", "-1e300", "1e-300", "nan", "inf", "1000", "3",
    "0.5",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn hostile_numbers_never_panic(
        scene in 0usize..BUILTIN.len(),
        picks in prop::collection::vec((any::<prop::sample::Index>(), 0usize..HOSTILE.len()), 1..4),
    ) {
        let mut text = BUILTIN[scene].toml.to_string();
        for (index, value) in picks {
            let spans = numbers(&text);
            let (a, b) = spans[index.index(spans.len())];
            text.replace_range(a..b, HOSTILE[value]);
        }
        if let Ok(scene) = Scene::parse(&text, "fuzz.toml", None) {
            // A scene whose dimension was changed builds for the dimension it claims.
            let _ = match scene.spec.scene.dimension {
                1 => build_for::<1>(&scene, segments, grid(&scene)).map(|s| s.seeds.position.len()),
                2 => build_for::<2>(&scene, triangles, grid(&scene)).map(|s| s.seeds.position.len()),
                3 => build_for::<3>(&scene, tetrahedra, grid(&scene)).map(|s| s.seeds.position.len()),
                _ => Ok(0),
            };
        }
    }
}

#[test]
fn the_number_finder_sees_the_scene_numbers() {
    let bar = BUILTIN
        .iter()
        .find(|b| b.name == "vibrating-bar")
        .unwrap()
        .toml;
    let found: Vec<&str> = numbers(bar).iter().map(|&(a, b)| &bar[a..b]).collect();
    for expected in [
        "1", "10.0", "-27.0", "27.0", "108", "0.005", "41", "100.0", "0.1",
    ] {
        assert!(found.contains(&expected), "{expected} not in {found:?}");
    }
    assert!(
        !found.iter().any(|n| n.contains("50")),
        "numbers inside strings are left alone"
    );
}

/// Every number of every built-in scene, replaced in turn by each hostile value: the
/// scene builds, or the error starts with the file and names a key or a line.
#[test]
fn every_number_of_every_scene_with_hostile_values() {
    let mut errors = 0;
    let mut cases = 0;
    for builtin in BUILTIN {
        for (a, b) in numbers(builtin.toml) {
            for value in ["-1", "0", "nan", "inf", "-inf", "1e300", "1e-300"] {
                let mut text = builtin.toml.to_string();
                text.replace_range(a..b, value);
                cases += 1;
                let result =
                    Scene::parse(&text, "edited.toml", None).and_then(|scene| {
                        match scene.spec.scene.dimension {
                            1 => build_for::<1>(&scene, segments, grid(&scene)).map(drop),
                            2 => build_for::<2>(&scene, triangles, grid(&scene)).map(drop),
                            3 => build_for::<3>(&scene, tetrahedra, grid(&scene)).map(drop),
                            _ => Ok(()),
                        }
                    });
                if let Err(e) = result {
                    errors += 1;
                    let m = e.to_string();
                    let context = &builtin.toml[a.saturating_sub(30)..b];
                    assert!(m.starts_with("edited.toml"), "`{context}` → {value}: {m}");
                    assert!(
                        m.contains('`') || m.contains("line"),
                        "`{context}` → {value}: no key or line in {m}"
                    );
                }
            }
        }
    }
    // The sweep must exercise the error paths, not only accept values.
    assert!(errors * 3 > cases, "{errors} errors of {cases} cases");
}
