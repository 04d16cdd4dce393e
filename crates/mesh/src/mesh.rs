//! The simplicial mesh: validated vertices and simplices with precomputed geometry.

use std::collections::HashMap;

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use crate::barycentric::{Barycentric, BarycentricGradients, MAX_SIMPLEX_VERTICES};
use crate::error::MeshError;
use crate::geometry::{edge_matrix, longest_edge, signed_volume};
use crate::locate::SpatialIndex;
use crate::topology::Topology;

/// A point in D dimensions.
pub type Point<const D: usize> = SVector<f64, D>;

/// Index value meaning "no neighbour" (a boundary facet).
pub(crate) const NO_NEIGHBOR: u32 = u32::MAX;

/// Relative volume below which a simplex counts as degenerate: |vol| ≤ tol · (longest edge)^D.
pub const DEGENERACY_TOLERANCE: f64 = 1e-12;

/// What to do with simplices whose vertex order gives a negative signed volume.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Orientation {
    /// Swap the last two vertices of inverted simplices so every simplex is positively oriented.
    #[default]
    Fix,
    /// Return [`MeshError::InvertedSimplex`] for the first inverted simplex.
    Reject,
}

/// A conforming simplicial mesh of segments (D = 1), triangles (D = 2) or tetrahedra (D = 3).
///
/// Construction validates the input and precomputes everything the MPM
/// kernels query per particle: the affine inverse of every simplex (for
/// barycentric coordinates), the topology (adjacency, incidence, face
/// neighbours, boundary, 1-rings with adjacency bitmasks) and a spatial
/// index for point location.
#[derive(Debug, Clone)]
pub struct SimplexMesh<const D: usize> {
    pub(crate) vertices: Vec<Point<D>>,
    /// Flat connectivity, D+1 entries per simplex, positively oriented.
    pub(crate) simplices: Vec<u32>,
    /// Per simplex: T⁻¹ with T = [x₁ − x₀, …, x_D − x₀]; rows are ∇λ₁ … ∇λ_D.
    pub(crate) inverse_maps: Vec<SMatrix<f64, D, D>>,
    pub(crate) volumes: Vec<f64>,
    pub(crate) topology: Topology<D>,
    pub(crate) index: SpatialIndex,
    pub(crate) max_edge: f64,
    pub(crate) min_edge: f64,
    pub(crate) min_height: f64,
}

/// Simplices per parallel work item of the validation.
const VALIDATION_CHUNK: usize = 4096;

/// What validating one simplex yields.
struct SimplexGeometry<const D: usize> {
    inverse: SMatrix<f64, D, D>,
    volume: f64,
    longest: f64,
    shortest: f64,
}

/// Validates simplex `simplex` (vertex indices in range and distinct, not degenerate,
/// oriented per `orientation`, swapping its last two vertices to fix it) and computes
/// its inverse edge map and volume.
fn simplex_geometry<const D: usize>(
    simplex: usize,
    verts: &mut [u32],
    vertices: &[Point<D>],
    orientation: Orientation,
) -> Result<SimplexGeometry<D>, MeshError> {
    let stride = D + 1;
    for (local, &index) in verts.iter().enumerate() {
        if index as usize >= vertices.len() {
            return Err(MeshError::VertexIndexOutOfRange {
                simplex,
                local,
                index,
                vertex_count: vertices.len(),
            });
        }
        if verts[..local].contains(&index) {
            return Err(MeshError::RepeatedVertex {
                simplex,
                vertex: index,
            });
        }
    }
    let mut corners = [Point::<D>::zeros(); MAX_SIMPLEX_VERTICES];
    for (c, &v) in corners.iter_mut().zip(verts.iter()) {
        *c = vertices[v as usize];
    }
    let corners = &corners[..stride];
    let longest = longest_edge(corners);
    let shortest = crate::geometry::shortest_edge(corners);
    let mut volume = signed_volume(corners);
    let tolerance = DEGENERACY_TOLERANCE * longest.powi(D as i32);
    if volume.abs() <= tolerance {
        return Err(MeshError::DegenerateSimplex {
            simplex,
            volume,
            tolerance,
        });
    }
    if volume < 0.0 {
        match orientation {
            Orientation::Reject => {
                return Err(MeshError::InvertedSimplex { simplex, volume });
            }
            Orientation::Fix => {
                // Swapping two vertices flips the sign of the determinant.
                verts.swap(D - 1, D);
                volume = -volume;
            }
        }
    }
    let mut fixed = [Point::<D>::zeros(); MAX_SIMPLEX_VERTICES];
    for (c, &v) in fixed.iter_mut().zip(verts.iter()) {
        *c = vertices[v as usize];
    }
    let inverse =
        edge_matrix(&fixed[..stride])
            .try_inverse()
            .ok_or(MeshError::DegenerateSimplex {
                simplex,
                volume,
                tolerance,
            })?;
    Ok(SimplexGeometry {
        inverse,
        volume,
        longest,
        shortest,
    })
}

impl<const D: usize> SimplexMesh<D> {
    /// Builds a mesh from vertex coordinates and flat connectivity (D+1 indices per simplex).
    ///
    /// Validates: non-empty, finite coordinates, indices in range, no repeated
    /// vertex in a simplex, no degenerate simplex (|vol| ≤
    /// [`DEGENERACY_TOLERANCE`] · longest edge^D), orientation per `orientation`,
    /// and that no facet is shared by more than two simplices.
    pub fn new(
        vertices: Vec<Point<D>>,
        mut simplices: Vec<u32>,
        orientation: Orientation,
    ) -> Result<Self, MeshError> {
        const { assert!(D >= 1 && D <= 3, "SimplexMesh supports D = 1, 2, 3") };
        let stride = D + 1;
        if simplices.len() % stride != 0 {
            return Err(MeshError::ConnectivityLength {
                len: simplices.len(),
                stride,
            });
        }
        let n_simplices = simplices.len() / stride;
        if vertices.is_empty() || n_simplices == 0 {
            return Err(MeshError::Empty {
                vertices: vertices.len(),
                simplices: n_simplices,
            });
        }
        for (what, count) in [("vertices", vertices.len()), ("simplices", n_simplices)] {
            if u32::try_from(count).is_err() || count == u32::MAX as usize {
                return Err(MeshError::TooLarge { what, count });
            }
        }
        for (vertex, x) in vertices.iter().enumerate() {
            if let Some(axis) = x.iter().position(|c| !c.is_finite()) {
                return Err(MeshError::NonFiniteCoordinate { vertex, axis });
            }
        }

        // Validation and the per-simplex geometry run in parallel over chunks; each chunk
        // stops at its first invalid simplex and the lowest one is reported, so the error
        // is the one a serial loop would give.
        let mut inverse_maps = vec![SMatrix::<f64, D, D>::zeros(); n_simplices];
        let mut volumes = vec![0.0; n_simplices];
        let extremes = simplices
            .par_chunks_mut(VALIDATION_CHUNK * stride)
            .zip(inverse_maps.par_chunks_mut(VALIDATION_CHUNK))
            .zip(volumes.par_chunks_mut(VALIDATION_CHUNK))
            .enumerate()
            .map(|(chunk, ((verts, inverses), vols))| {
                let first = chunk * VALIDATION_CHUNK;
                let mut extremes = (0.0_f64, f64::INFINITY);
                for (k, ((verts, inverse), volume)) in verts
                    .chunks_exact_mut(stride)
                    .zip(inverses.iter_mut())
                    .zip(vols.iter_mut())
                    .enumerate()
                {
                    let geometry = simplex_geometry(first + k, verts, &vertices, orientation)?;
                    *inverse = geometry.inverse;
                    *volume = geometry.volume;
                    extremes.0 = extremes.0.max(geometry.longest);
                    extremes.1 = extremes.1.min(geometry.shortest);
                }
                Ok(extremes)
            })
            .collect::<Vec<Result<(f64, f64), MeshError>>>();
        let (mut max_edge, mut min_edge) = (0.0_f64, f64::INFINITY);
        for chunk in extremes {
            let (longest, shortest) = chunk?;
            max_edge = max_edge.max(longest);
            min_edge = min_edge.min(shortest);
        }

        // The BVH is built serially by parry; it runs beside the (parallel) topology.
        let (topology, index) = rayon::join(
            || Topology::build(vertices.len(), &simplices, &inverse_maps, &volumes),
            || SpatialIndex::build::<D>(&vertices, &simplices, max_edge),
        );
        let mut mesh = Self {
            vertices,
            simplices,
            inverse_maps,
            volumes,
            topology: topology?,
            index: index?,
            max_edge,
            min_edge,
            min_height: 0.0,
        };
        mesh.min_height = (0..mesh.simplex_count())
            .into_par_iter()
            .map(|s| mesh.height(s))
            .reduce(|| f64::INFINITY, f64::min);
        Ok(mesh)
    }

    /// Builds a mesh from per-simplex vertex arrays; `N` must equal D+1.
    pub fn from_arrays<const N: usize>(
        vertices: Vec<Point<D>>,
        simplices: &[[u32; N]],
        orientation: Orientation,
    ) -> Result<Self, MeshError> {
        if N != D + 1 {
            return Err(MeshError::ConnectivityLength {
                len: N,
                stride: D + 1,
            });
        }
        Self::new(
            vertices,
            simplices.iter().flatten().copied().collect(),
            orientation,
        )
    }

    /// Number of vertices.
    #[inline]
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// Number of simplices.
    #[inline]
    pub fn simplex_count(&self) -> usize {
        self.volumes.len()
    }

    /// All vertex coordinates.
    #[inline]
    pub fn vertices(&self) -> &[Point<D>] {
        &self.vertices
    }

    /// Coordinates of vertex `v`.
    #[inline]
    pub fn vertex(&self, v: usize) -> &Point<D> {
        &self.vertices[v]
    }

    /// The D+1 vertex indices of simplex `s`, positively oriented.
    #[inline]
    pub fn simplex(&self, s: usize) -> &[u32] {
        &self.simplices[s * (D + 1)..(s + 1) * (D + 1)]
    }

    /// Iterator over all simplices' vertex lists.
    pub fn simplices(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.simplices.chunks_exact(D + 1)
    }

    /// The flat connectivity array (D+1 indices per simplex).
    pub fn connectivity(&self) -> &[u32] {
        &self.simplices
    }

    /// Coordinates of the D+1 vertices of simplex `s`, padded to the fixed capacity.
    #[inline]
    pub fn corners(&self, s: usize) -> [Point<D>; MAX_SIMPLEX_VERTICES] {
        let mut corners = [Point::<D>::zeros(); MAX_SIMPLEX_VERTICES];
        for (c, &v) in corners.iter_mut().zip(self.simplex(s)) {
            *c = self.vertices[v as usize];
        }
        corners
    }

    /// Volume (length, area) of simplex `s`; positive.
    #[inline]
    pub fn volume(&self, s: usize) -> f64 {
        self.volumes[s]
    }

    /// Total volume of the mesh.
    pub fn total_volume(&self) -> f64 {
        self.volumes.iter().sum()
    }

    /// The mean element size (D! · V / n)^(1/D), with V the mesh's volume and n its
    /// simplex count: the edge of the right-angled simplex (legs h, volume h^D / D!) of
    /// the mean volume. On a lattice of cells h it is h however the cells are split and
    /// however the interior vertices are jittered (jitter moves volume between
    /// simplices, not out of the mesh), where the longest edge grows with the jitter.
    pub fn mean_element_size(&self) -> f64 {
        let factorial = (1..=D).product::<usize>() as f64;
        let count = self.simplex_count().max(1) as f64;
        (factorial * self.total_volume() / count).powf(1.0 / D as f64)
    }

    /// Longest edge in the mesh.
    pub fn max_edge_length(&self) -> f64 {
        self.max_edge
    }

    /// Shortest edge in the mesh.
    pub fn min_edge_length(&self) -> f64 {
        self.min_edge
    }

    /// Shortest height (vertex-to-opposite-facet distance) of simplex `s`: 1 / max‖∇λ_n‖.
    /// The explicit stability limit of P1 elements scales with it, not with the
    /// shortest edge (a flat triangle has long edges and a short height).
    pub fn height(&self, s: usize) -> f64 {
        let largest = self
            .barycentric_gradients(s)
            .as_slice()
            .iter()
            .map(|g| g.norm())
            .fold(0.0, f64::max);
        1.0 / largest
    }

    /// Shortest simplex height in the mesh (see [`Self::height`]).
    pub fn min_height(&self) -> f64 {
        self.min_height
    }

    /// Barycentric coordinates of `x` with respect to simplex `s` (any point, inside or not).
    #[inline]
    pub fn barycentric(&self, s: usize, x: &Point<D>) -> Barycentric<D> {
        let x0 = &self.vertices[self.simplices[s * (D + 1)] as usize];
        let tail = self.inverse_maps[s] * (x - x0);
        let mut coords = [0.0; MAX_SIMPLEX_VERTICES];
        coords[1..=D].copy_from_slice(tail.as_slice());
        coords[0] = 1.0 - tail.sum();
        Barycentric(coords)
    }

    /// Gradients of the barycentric coordinates of simplex `s` (constant on the simplex).
    #[inline]
    pub fn barycentric_gradients(&self, s: usize) -> BarycentricGradients<D> {
        let inverse = &self.inverse_maps[s];
        let mut grads = [SVector::<f64, D>::zeros(); MAX_SIMPLEX_VERTICES];
        let mut sum = SVector::<f64, D>::zeros();
        for k in 0..D {
            grads[k + 1] = inverse.row(k).transpose();
            sum += grads[k + 1];
        }
        grads[0] = -sum;
        BarycentricGradients(grads)
    }

    /// The point with barycentric coordinates `lambda` in simplex `s`.
    pub fn point_at(&self, s: usize, lambda: &Barycentric<D>) -> Point<D> {
        self.simplex(s)
            .iter()
            .zip(lambda.as_slice())
            .fold(Point::<D>::zeros(), |acc, (&v, &l)| {
                acc + self.vertices[v as usize] * l
            })
    }

    /// Centroid of simplex `s`.
    pub fn centroid(&self, s: usize) -> Point<D> {
        let sum = self.simplex(s).iter().fold(Point::<D>::zeros(), |acc, &v| {
            acc + self.vertices[v as usize]
        });
        sum / (D + 1) as f64
    }

    /// Axis-aligned bounding box of all vertices: (min, max).
    pub fn bounding_box(&self) -> (Point<D>, Point<D>) {
        let mut lo = Point::<D>::repeat(f64::INFINITY);
        let mut hi = Point::<D>::repeat(f64::NEG_INFINITY);
        for x in &self.vertices {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        (lo, hi)
    }

    /// The precomputed topology.
    #[inline]
    pub fn topology(&self) -> &Topology<D> {
        &self.topology
    }

    /// A key identifying the facet of simplex `s` opposite local vertex `local`: its sorted vertices.
    pub(crate) fn facet_key(verts: &[u32], local: usize) -> [u32; 3] {
        let mut key = [u32::MAX; 3];
        let mut k = 0;
        for (i, &v) in verts.iter().enumerate() {
            if i != local {
                key[k] = v;
                k += 1;
            }
        }
        key[..k].sort_unstable();
        key
    }
}

/// Counts of each kind of sub-simplex; used for Euler characteristics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EntityCounts {
    /// Vertices used by at least one simplex.
    pub vertices: usize,
    /// Distinct edges.
    pub edges: usize,
    /// Distinct triangles (0 for D = 1).
    pub triangles: usize,
    /// Tetrahedra (0 for D < 3).
    pub tetrahedra: usize,
}

impl EntityCounts {
    /// Euler characteristic V − E + F − T.
    pub fn euler_characteristic(&self) -> i64 {
        self.vertices as i64 - self.edges as i64 + self.triangles as i64 - self.tetrahedra as i64
    }
}

impl<const D: usize> SimplexMesh<D> {
    /// Counts distinct vertices, edges, triangles and tetrahedra of the complex.
    pub fn entity_counts(&self) -> EntityCounts {
        let used = (0..self.vertex_count())
            .filter(|&v| !self.topology.vertex_simplices.row(v).is_empty())
            .count();
        let edges = self.topology.adjacency.nnz() / 2;
        let triangles = match D {
            1 => 0,
            2 => self.simplex_count(),
            _ => {
                let mut faces: HashMap<[u32; 3], ()> = HashMap::new();
                for verts in self.simplices() {
                    for local in 0..=D {
                        faces.insert(Self::facet_key(verts, local), ());
                    }
                }
                faces.len()
            }
        };
        let tetrahedra = if D == 3 { self.simplex_count() } else { 0 };
        EntityCounts {
            vertices: used,
            edges,
            triangles,
            tetrahedra,
        }
    }
}
