//! How lattice cells are split into simplices, per dimension.

use super::lattice::Lattice;
use crate::barycentric::MAX_SIMPLEX_VERTICES;
use crate::error::MeshError;
use crate::geometry::signed_volume;
use crate::mesh::{Orientation, Point, SimplexMesh};

/// How each rectangle cell is split into triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Diagonal {
    /// Two triangles per cell along the lower-left to upper-right diagonal.
    #[default]
    Right,
    /// Two triangles per cell along the lower-right to upper-left diagonal.
    Left,
    /// Right and left alternating in a checkerboard ("union jack" when paired).
    Alternating,
    /// Four triangles per cell around an added centre vertex.
    Crossed,
}

impl<const D: usize> Lattice<D> {
    /// Orients `connectivity` positively on the reference lattice, then builds the mesh on the
    /// final (jittered, rotated) coordinates rejecting any simplex the jitter inverted.
    fn assemble(
        &self,
        reference: Vec<Point<D>>,
        final_coordinates: Vec<Point<D>>,
        extra: &[Point<D>],
        mut connectivity: Vec<u32>,
    ) -> Result<SimplexMesh<D>, MeshError> {
        let mut all_reference = reference;
        all_reference.extend_from_slice(extra);
        for verts in connectivity.chunks_exact_mut(D + 1) {
            let mut corners = [Point::<D>::zeros(); MAX_SIMPLEX_VERTICES];
            for (c, &v) in corners.iter_mut().zip(verts.iter()) {
                *c = all_reference[v as usize];
            }
            if signed_volume(&corners[..=D]) < 0.0 {
                verts.swap(D - 1, D);
            }
        }
        SimplexMesh::new(final_coordinates, connectivity, Orientation::Reject)
    }
}

impl Lattice<1> {
    /// Segments between consecutive lattice vertices.
    pub fn segments(&self) -> Result<SimplexMesh<1>, MeshError> {
        let reference = self.reference_coordinates()?;
        let coordinates = self.coordinates(&reference);
        let connectivity = (0..self.cells[0] as u32).flat_map(|i| [i, i + 1]).collect();
        self.assemble(reference, coordinates, &[], connectivity)
    }
}

impl Lattice<2> {
    /// Triangles, split per `diagonal`; a jittered cell whose chosen diagonal would invert
    /// a triangle takes the other one.
    pub fn triangles(&self, diagonal: Diagonal) -> Result<SimplexMesh<2>, MeshError> {
        let reference = self.reference_coordinates()?;
        let mut coordinates = self.coordinates(&reference);
        let mut reference_centres = Vec::new();
        let mut connectivity = Vec::new();
        for [i, j] in self.cell_indices().collect::<Vec<_>>() {
            let v00 = self.vertex_index([i, j]);
            let v10 = self.vertex_index([i + 1, j]);
            let v01 = self.vertex_index([i, j + 1]);
            let v11 = self.vertex_index([i + 1, j + 1]);
            let right = match diagonal {
                Diagonal::Right => true,
                Diagonal::Left => false,
                Diagonal::Alternating => (i + j) % 2 == 0,
                Diagonal::Crossed => {
                    // Centre vertex at the mean of the (final) cell corners keeps every triangle valid.
                    let corners = [v00, v10, v11, v01];
                    let mean = |xs: &[Point<2>]| {
                        corners.iter().map(|&v| xs[v as usize]).sum::<Point<2>>() / 4.0
                    };
                    reference_centres.push(mean(&reference));
                    let centre_final = mean(&coordinates);
                    let c = (reference.len() + reference_centres.len() - 1) as u32;
                    coordinates.push(centre_final);
                    for k in 0..4 {
                        connectivity.extend([corners[k], corners[(k + 1) % 4], c]);
                    }
                    continue;
                }
            };
            // A jittered cell is a simple quadrilateral (the jitter stays below ½), so one
            // diagonal at least lies inside it: keep the chosen one unless it would invert a
            // triangle. Up to the 3D bound no cell flips, so those meshes are unchanged.
            let positive = |t: [u32; 3]| signed_volume(&t.map(|v| coordinates[v as usize])) > 0.0;
            let along_right = [[v00, v10, v11], [v00, v11, v01]];
            let along_left = [[v00, v10, v01], [v10, v11, v01]];
            let (chosen, other) = if right {
                (along_right, along_left)
            } else {
                (along_left, along_right)
            };
            let keep = chosen.iter().all(|&t| positive(t)) || !other.iter().all(|&t| positive(t));
            for triangle in if keep { chosen } else { other } {
                connectivity.extend(triangle);
            }
        }
        self.assemble(reference, coordinates, &reference_centres, connectivity)
    }
}

impl Lattice<3> {
    /// Six tetrahedra per cell (Kuhn/Freudenthal split along the main diagonal), conforming
    /// across cells because every cell uses the same diagonal.
    pub fn tetrahedra(&self) -> Result<SimplexMesh<3>, MeshError> {
        const PERMUTATIONS: [[usize; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let reference = self.reference_coordinates()?;
        let coordinates = self.coordinates(&reference);
        let mut connectivity = Vec::with_capacity(self.cells.iter().product::<usize>() * 24);
        for cell in self.cell_indices().collect::<Vec<_>>() {
            for perm in PERMUTATIONS {
                let mut ijk = cell;
                connectivity.push(self.vertex_index(ijk));
                for axis in perm {
                    ijk[axis] += 1;
                    connectivity.push(self.vertex_index(ijk));
                }
            }
        }
        self.assemble(reference, coordinates, &[], connectivity)
    }
}
