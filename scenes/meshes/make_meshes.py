"""Regenerates the Gmsh meshes of the built-in scenes (needs `pip install gmsh`).

With `--cantilever-refined` it writes instead the cantilever room at h/2, h/3 and h/5
(cantilever-room-h2.msh, -h3, -h5: triangles of size 0.125, 0.0833, 0.05), the meshes
of the unstructured cantilever's refinement study (docs/scenes.md); they are not
committed (4 MB at h/5)."""
import sys

import gmsh



def mesh(name, build, binary=False):
    """Builds one mesh with `build()` (geometry, sizes, groups) and writes NAME.msh."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    build()
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(name + ".msh")
    gmsh.finalize()


def cantilever():
    """The room around the steel cantilever, [0, 2.4] x [-0.6, 0.4], unstructured
    triangles of size 0.05; physical groups "wall" (the edge x = 0) and "room"."""
    r = gmsh.model.occ.addRectangle(0, -0.6, 0, 2.4, 1.0)
    gmsh.model.occ.synchronize()
    gmsh.model.mesh.setSize(gmsh.model.getEntities(0), 0.05)
    wall = [c for _, c in gmsh.model.getBoundary([(2, r)], oriented=False)
            if abs(gmsh.model.occ.getCenterOfMass(1, c)[0]) < 1e-12]
    gmsh.model.addPhysicalGroup(1, wall, name="wall")
    gmsh.model.addPhysicalGroup(2, [r], name="room")
    gmsh.model.mesh.generate(2)


def cantilever_room(size=0.25):
    """The square room [-3, 7] x [-6, 4] the 4 x 1 cantilever of
    `cantilever-unstructured.toml` swings in, unstructured triangles of size 0.25 (the
    structured scene's lattice spacing); no groups (the clamp is a region of nodes).
    Other sizes make the refined meshes of the refinement study in docs/scenes.md."""
    gmsh.model.occ.addRectangle(-3, -6, 0, 10, 10)
    gmsh.model.occ.synchronize()
    gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
    gmsh.model.mesh.generate(2)


def sphere_container():
    """The spherical container of radius 1 of `sphere-expansion-3d.toml`, tetrahedra of
    size 0.15; physical groups "wall" (the sphere's surface) and "inside"."""
    ball = gmsh.model.occ.addSphere(0, 0, 0, 1.0)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.15)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
    surface = [c for _, c in gmsh.model.getBoundary([(3, ball)], oriented=False)]
    gmsh.model.addPhysicalGroup(2, surface, name="wall")
    gmsh.model.addPhysicalGroup(3, [ball], name="inside")
    gmsh.model.mesh.generate(3)


def box_of_tetrahedra(size, dimensions, group):
    """The box [0, dimensions] of tetrahedra of `size`, one physical group `group`."""
    box = gmsh.model.occ.addBox(0, 0, 0, *dimensions)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.addPhysicalGroup(3, [box], name=group)
    gmsh.model.mesh.generate(3)


def slope_box():
    """The box [0, 4] x [0, 0.4] x [0, 1.5] the slope of `slope-3d.toml` collapses in,
    tetrahedra of size 0.13 (the walls are planes of the scene file)."""
    box_of_tetrahedra(0.13, (4.0, 0.4, 1.5), "box")


def column():
    """The room [0, 1] x [0, 4.4] of the hydrostatic column, unstructured triangles of
    size 0.1 (the lattice scene's cell); the walls are planes of the scene file."""
    r = gmsh.model.occ.addRectangle(0, 0, 0, 1.0, 4.4)
    gmsh.model.occ.synchronize()
    gmsh.model.mesh.setSize(gmsh.model.getEntities(0), 0.1)
    gmsh.model.addPhysicalGroup(2, [r], name="room")
    gmsh.model.mesh.generate(2)


def column_3d():
    """The box [0, 1] x [0, 1] x [0, 4.4] of the 3D hydrostatic column, tetrahedra of
    size 0.2 (the lattice scene's cell)."""
    box_of_tetrahedra(0.2, (1.0, 1.0, 4.4), "box")


def bowl(size):
    """The curved container of `fluid-bowl.toml`: the disk of radius 1 about the origin
    cut at y = 0.3, triangles of `size`; physical groups "wall" (the arc) and "inside".
    The fluid fills it to y = 0."""
    disk = gmsh.model.occ.addDisk(0, 0, 0, 1.0, 1.0)
    cut = gmsh.model.occ.addRectangle(-1.5, -1.5, 0, 3.0, 1.8)
    (inside,), _ = gmsh.model.occ.intersect([(2, disk)], [(2, cut)])
    gmsh.model.occ.synchronize()
    gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
    arc = [c for _, c in gmsh.model.getBoundary([inside], oriented=False)
           if gmsh.model.occ.getCenterOfMass(1, c)[1] < 0.29]
    gmsh.model.addPhysicalGroup(1, arc, name="wall")
    gmsh.model.addPhysicalGroup(2, [inside[1]], name="inside")
    gmsh.model.mesh.generate(2)


def bowl_3d(size):
    """The 3D curved container of `fluid-bowl-3d.toml`: the ball of radius 1 cut at
    z = 0.3, tetrahedra of `size`; physical groups "wall" (the spherical surface) and
    "inside". The fluid fills it to z = 0."""
    ball = gmsh.model.occ.addSphere(0, 0, 0, 1.0)
    cut = gmsh.model.occ.addBox(-1.5, -1.5, -1.5, 3.0, 3.0, 1.8)
    (inside,), _ = gmsh.model.occ.intersect([(3, ball)], [(3, cut)])
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    wall = [c for _, c in gmsh.model.getBoundary([inside], oriented=False)
            if gmsh.model.occ.getCenterOfMass(2, c)[2] < 0.29]
    gmsh.model.addPhysicalGroup(2, wall, name="wall")
    gmsh.model.addPhysicalGroup(3, [inside[1]], name="inside")
    gmsh.model.mesh.generate(3)


if "--cantilever-refined" in sys.argv:
    for factor in (2, 3, 5):
        mesh(f"cantilever-room-h{factor}", lambda: cantilever_room(0.25 / factor))
    sys.exit()

mesh("cantilever", cantilever)
mesh("cantilever-room", cantilever_room)
mesh("sphere-container", sphere_container, binary=True)
mesh("slope-box", slope_box, binary=True)
mesh("column", column)
mesh("column-3d", column_3d, binary=True)
# The curved containers at two sizes each: the report's levels 1 and 2.
mesh("bowl", lambda: bowl(0.1))
mesh("bowl-h2", lambda: bowl(0.05))
mesh("bowl-3d", lambda: bowl_3d(0.2), binary=True)
mesh("bowl-3d-h2", lambda: bowl_3d(0.1), binary=True)
