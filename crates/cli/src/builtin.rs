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
pub const BUILTIN: [Builtin; 7] = [
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
        name: "cantilever",
        summary: "elastic cantilever on an unstructured Gmsh mesh, clamped at the mesh's `wall` group, sagging under gravity",
        toml: include_str!("../../../scenes/cantilever.toml"),
    },
    Builtin {
        name: "hydrostatic-column",
        summary: "elastic column at rest under gravity between slip walls (plane strain), against the closed-form stress and settlement",
        toml: include_str!("../../../scenes/hydrostatic-column.toml"),
    },
    Builtin {
        name: "hydrostatic-column-tilted",
        summary: "the hydrostatic column turned by 30°: the mesh conforms to the inclined walls, a B-spline grid cannot",
        toml: include_str!("../../../scenes/hydrostatic-column-tilted.toml"),
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
];

/// Mesh files the built-in scenes refer to, by the name used in `[mesh] file`.
pub const MESHES: [(&str, &[u8]); 1] = [(
    "meshes/cantilever.msh",
    include_bytes!("../../../scenes/meshes/cantilever.msh"),
)];
