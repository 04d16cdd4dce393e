//! The built-in scenes: the TOML files of the repository's `scenes/` directory, embedded
//! so that `umls run NAME` works from any directory.

/// A built-in scene.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    /// Name on the command line.
    pub name: &'static str,
    /// One line on what it shows.
    pub summary: &'static str,
    /// The scene file.
    pub toml: &'static str,
}

/// Every built-in scene.
pub const BUILTIN: [Builtin; 18] = [
    Builtin {
        name: "colliding-disks",
        summary: "two elastic disks collide and rebound (Sulsky et al. 1994) on a jittered triangle mesh",
        toml: include_str!("../../../scenes/colliding-disks.toml"),
    },
    Builtin {
        name: "vibrating-bar",
        summary: "1D bar fixed at one end (by antisymmetry), mode-1 vibration against the analytic solution",
        toml: include_str!("../../../scenes/vibrating-bar.toml"),
    },
    Builtin {
        name: "steel-cantilever",
        summary: "elastic cantilever on an unstructured Gmsh mesh, clamped at the mesh's `wall` group, sagging under gravity",
        toml: include_str!("../../../scenes/steel-cantilever.toml"),
    },
    Builtin {
        name: "hydrostatic-column",
        summary: "elastic column at rest under gravity between slip walls (plane strain), against the closed-form stress and settlement",
        toml: include_str!("../../../scenes/hydrostatic-column.toml"),
    },
    Builtin {
        name: "sliding-block",
        summary: "an elastic block slides down a 30° incline with Coulomb friction, against the closed-form velocity",
        toml: include_str!("../../../scenes/sliding-block.toml"),
    },
    Builtin {
        name: "hydrostatic-column-tilted",
        summary: "the hydrostatic column turned by 30°: the mesh conforms to the inclined walls, a B-spline grid cannot",
        toml: include_str!("../../../scenes/hydrostatic-column-tilted.toml"),
    },
    Builtin {
        name: "hydrostatic-column-gmsh",
        summary: "the hydrostatic column on unstructured Gmsh triangles",
        toml: include_str!("../../../scenes/hydrostatic-column-gmsh.toml"),
    },
    Builtin {
        name: "hydrostatic-column-3d-gmsh",
        summary: "the 3D hydrostatic column on unstructured Gmsh tetrahedra",
        toml: include_str!("../../../scenes/hydrostatic-column-3d-gmsh.toml"),
    },
    Builtin {
        name: "hydrostatic-column-3d",
        summary: "3D elastic column at rest under gravity in a box of slip walls, against the closed form",
        toml: include_str!("../../../scenes/hydrostatic-column-3d.toml"),
    },
    Builtin {
        name: "fluid-box-3d",
        summary: "Taichi's mpm3d scene: a fluid block falls and splashes in a box (bspline2 on a 64³ grid, 64,000 particles)",
        toml: include_str!("../../../scenes/fluid-box-3d.toml"),
    },
    Builtin {
        name: "cantilever",
        summary: "the UMLS paper's cantilever (4 × 1 neo-Hookean beam, embedded clamp) on a lattice the scene can turn, against a converged tip history",
        toml: include_str!("../../../scenes/cantilever.toml"),
    },
    Builtin {
        name: "cantilever-3d",
        summary: "a 3 × 0.5 × 0.5 neo-Hookean beam held on the face of an embedded clamp, on Kuhn tetrahedra, over its first swing",
        toml: include_str!("../../../scenes/cantilever-3d.toml"),
    },
    Builtin {
        name: "cantilever-unstructured",
        summary: "the cantilever on an unstructured Gmsh mesh of the same room, which the scene can turn",
        toml: include_str!("../../../scenes/cantilever-unstructured.toml"),
    },
    Builtin {
        name: "vortex",
        summary: "generalized vortex manufactured solution: an annulus twisted by a body force, against the exact displacement",
        toml: include_str!("../../../scenes/vortex.toml"),
    },
    Builtin {
        name: "sphere-expansion-3d",
        summary: "an elastic ball expands against a spherical container the mesh conforms to; wall pressure from reaction forces",
        toml: include_str!("../../../scenes/sphere-expansion-3d.toml"),
    },
    Builtin {
        name: "slope-3d",
        summary: "a 45° Drucker–Prager slope collapses and runs out on a fixed floor (Gmsh tetrahedra)",
        toml: include_str!("../../../scenes/slope-3d.toml"),
    },
    Builtin {
        name: "fluid-bowl",
        summary: "a fluid at rest in a curved container the mesh conforms to, against the hydrostatic pressure (Gmsh triangles)",
        toml: include_str!("../../../scenes/fluid-bowl.toml"),
    },
    Builtin {
        name: "fluid-bowl-3d",
        summary: "the fluid at rest in a 3D curved container (Gmsh tetrahedra), against the hydrostatic pressure",
        toml: include_str!("../../../scenes/fluid-bowl-3d.toml"),
    },
];

/// Files the built-in scenes refer to (meshes, reference data), by the name the scene
/// uses.
pub const FILES: [(&str, &[u8]); 12] = [
    (
        "meshes/cantilever.msh",
        include_bytes!("../../../scenes/meshes/cantilever.msh"),
    ),
    (
        "meshes/cantilever-room.msh",
        include_bytes!("../../../scenes/meshes/cantilever-room.msh"),
    ),
    (
        "meshes/sphere-container.msh",
        include_bytes!("../../../scenes/meshes/sphere-container.msh"),
    ),
    (
        "meshes/slope-box.msh",
        include_bytes!("../../../scenes/meshes/slope-box.msh"),
    ),
    (
        "meshes/column.msh",
        include_bytes!("../../../scenes/meshes/column.msh"),
    ),
    (
        "meshes/column-3d.msh",
        include_bytes!("../../../scenes/meshes/column-3d.msh"),
    ),
    (
        "meshes/bowl.msh",
        include_bytes!("../../../scenes/meshes/bowl.msh"),
    ),
    (
        "meshes/bowl-h2.msh",
        include_bytes!("../../../scenes/meshes/bowl-h2.msh"),
    ),
    (
        "meshes/bowl-3d.msh",
        include_bytes!("../../../scenes/meshes/bowl-3d.msh"),
    ),
    (
        "meshes/bowl-3d-h2.msh",
        include_bytes!("../../../scenes/meshes/bowl-3d-h2.msh"),
    ),
    (
        "data/cantilever-tip.csv",
        include_bytes!("../../../scenes/data/cantilever-tip.csv"),
    ),
    (
        "data/cantilever-3d-tip.csv",
        include_bytes!("../../../scenes/data/cantilever-3d-tip.csv"),
    ),
];
