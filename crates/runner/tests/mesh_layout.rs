//! The colliding disks on other triangle lattices: how the mesh's layout, and the UMLS
//! support radii it implies, move the energy each kernel loses (docs/umls-kernel.md,
//! *Mesh layout*).

use umls_runner::run::run;
use umls_runner::schema::KernelKind;

#[path = "common/runs.rs"]
mod runs;
use runs::{metric, options, variant};

/// The fraction of the disks' energy lost by t = 3 with `kernel`, transfer `kind` (α 0.99
/// where it blends) and the scene's text edited by `edits`, from a run that must
/// complete; `tag` names the output directory.
fn lost(kernel: KernelKind, kind: &str, tag: &str, edits: &[(&str, &str)]) -> f64 {
    refined_lost(kernel, kind, tag, edits, 1.0)
}

/// [`lost`] with cells, time step and particle spacing refined by `refine` (`umls run
/// --refine`).
fn refined_lost(
    kernel: KernelKind,
    kind: &str,
    tag: &str,
    edits: &[(&str, &str)],
    refine: f64,
) -> f64 {
    let kind_edit = format!("kind = \"{kind}\"");
    let mut all = vec![("kind = \"flip\"", kind_edit.as_str())];
    all.extend_from_slice(edits);
    let mut scene = variant("colliding-disks", &all);
    umls_runner::edit::refine(&mut scene, refine).unwrap();
    let name = format!("disks-layout-{tag}-{refine}-{}-{kind}", kernel.name());
    let summary = run(&scene, &options(&name, Some(kernel), None))
        .unwrap()
        .summary
        .to_json();
    assert_eq!(summary["status"], "completed", "{summary}");
    -metric(&summary, "energy_change_final")
}

/// On the crossed lattice (`[mesh.lattice] diagonal = "crossed"`: each cell split into
/// four triangles about its centre, as many cells and twice the vertices) UMLS meets the
/// accuracy issue's disks target at 20 cells against bspline2 on its grid of the same
/// cell size: no more than 5 points above it, at FLIP 0.99 and APIC (measured 0.190
/// against 0.186, 0.665 against 0.700). It is the layout and not the vertex count: the
/// scene's alternating lattice with as many vertices (28 cells) loses 0.248 and 0.742.
#[test]
fn umls_on_the_crossed_lattice_loses_within_five_points_of_bspline2_on_the_disks() {
    let crossed = [("diagonal = \"alternating\"", "diagonal = \"crossed\"")];
    let as_many_vertices = [("cells = [20, 20]", "cells = [28, 28]")];
    for kind in ["flip", "apic"] {
        let umls = lost(KernelKind::Umls, kind, "crossed", &crossed);
        let bspline2 = lost(KernelKind::Bspline2, kind, "scene", &[]);
        assert!(
            umls > 0.0 && umls < bspline2 + 0.05,
            "{kind}: umls {umls}, bspline2 {bspline2}"
        );
        let alternating = lost(KernelKind::Umls, kind, "28-cells", &as_many_vertices);
        assert!(
            alternating > umls + 0.03,
            "{kind}: crossed {umls}, alternating with as many vertices {alternating}"
        );
    }
}

/// The disks approach along (1, 1). On a lattice whose diagonals all run one way
/// (`right`: along the approach; `left`: along the contact line), mirroring the scene
/// about x = 1/2 swaps the two, so the mirrored disks on the `left` lattice must lose
/// what the disks lose on the `right` one (no jitter, so the meshes mirror exactly): the
/// engine has no preferred direction. The axis-aligned B-spline grid is its own mirror
/// image, so bspline2 loses the same whichever way the disks approach. UMLS does not:
/// with APIC it loses 0.853 with the diagonals along the approach and 0.719 with them
/// along the contact line, the stencil's anisotropy on a one-way lattice.
#[test]
fn the_disks_mirrored_with_their_lattice_lose_the_same_energy_but_not_turned_against_it() {
    let exact = ("jitter = 0.2", "jitter = 0.0");
    let right = ("diagonal = \"alternating\"", "diagonal = \"right\"");
    let left = ("diagonal = \"alternating\"", "diagonal = \"left\"");
    let mirrored = [
        ("centre = [0.2, 0.2]", "centre = [0.8, 0.2]"),
        ("velocity = [0.1, 0.1]", "velocity = [-0.1, 0.1]"),
        ("centre = [0.8, 0.8]", "centre = [0.2, 0.8]"),
        ("velocity = [-0.1, -0.1]", "velocity = [0.1, -0.1]"),
    ];
    let mut mirrored_left = vec![exact, left];
    mirrored_left.extend_from_slice(&mirrored);
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        let along = lost(kernel, "apic", "right", &[exact, right]);
        let mirror = lost(kernel, "apic", "mirrored-left", &mirrored_left);
        let across = lost(kernel, "apic", "left", &[exact, left]);
        assert!(
            (along - mirror).abs() < 1e-12,
            "{}: right {along}, mirrored on left {mirror}",
            kernel.name()
        );
        if kernel == KernelKind::Umls {
            assert!(along > across + 0.1, "umls: right {along}, left {across}");
        } else {
            assert!(
                (along - across).abs() < 1e-12,
                "bspline2: {along}, {across}"
            );
        }
    }
}

/// The incident-edge rule gives the vertices on the alternating lattice's diagonals √2
/// times the others' radius, and jitter widens it further (0.86 h to 1.69 h on the
/// scene's lattice). `umls-element-size` gives each vertex its cells' size instead, near
/// h everywhere, and meets the accuracy issue's disks target on the scene's own lattice:
/// no more than 5 points above bspline2 at 20 and 40 cells with FLIP 0.99 and APIC
/// (measured 0.217 / 0.152 against 0.186 / 0.135, and 0.719 / 0.458 against 0.700 /
/// 0.471), where `umls` is 13 / 8 and 16 / 18 points above.
#[test]
fn element_size_radii_bring_umls_within_five_points_of_bspline2_on_the_disks() {
    for refine in [1.0, 2.0] {
        for kind in ["flip", "apic"] {
            let element_size =
                refined_lost(KernelKind::UmlsElementSize, kind, "radii", &[], refine);
            let bspline2 = refined_lost(KernelKind::Bspline2, kind, "radii", &[], refine);
            let umls = refined_lost(KernelKind::Umls, kind, "radii", &[], refine);
            assert!(
                element_size > 0.0 && element_size < bspline2 + 0.05,
                "refine {refine}, {kind}: umls-element-size {element_size}, bspline2 {bspline2}"
            );
            assert!(
                umls > bspline2 + 0.05,
                "refine {refine}, {kind}: umls {umls}"
            );
        }
    }
}
