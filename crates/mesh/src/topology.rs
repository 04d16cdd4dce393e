//! Mesh topology, computed once at construction: adjacency, incidence, face
//! neighbours, boundary facets and the 1-rings the UMLS kernel needs.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use nalgebra::{SMatrix, SVector};

use crate::csr::Csr;
use crate::error::MeshError;
use crate::mesh::{NO_NEIGHBOR, SimplexMesh};

/// A facet on the boundary of the mesh (a facet with exactly one incident simplex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryFacet<const D: usize> {
    /// The simplex the facet belongs to.
    pub simplex: u32,
    /// Local index (in that simplex) of the vertex opposite the facet.
    pub opposite: u8,
    /// Unit outward normal.
    pub normal: SVector<f64, D>,
    /// Measure of the facet (1 for a point, length for an edge, area for a triangle).
    pub measure: f64,
}

/// The 1-ring of a host simplex: every vertex equal or edge-adjacent to one of its vertices,
/// with a bitmask saying which host vertices each one is adjacent to.
#[derive(Debug, Clone, Copy)]
pub struct OneRing<'a> {
    /// Ring vertex indices: the host's own D+1 vertices first (local order), then the rest ascending.
    pub vertices: &'a [u32],
    /// Per ring vertex, bit n set iff A_{v,n} = 1 (v equals or shares an edge with host vertex n).
    pub masks: &'a [u8],
}

impl OneRing<'_> {
    /// Number of vertices in the ring.
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Whether the ring is empty (never, for a valid mesh).
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }
}

/// The precomputed topology of a [`SimplexMesh`].
#[derive(Debug, Clone)]
pub struct Topology<const D: usize> {
    /// Vertex-to-vertex adjacency (edges), each row ascending, no self loops.
    pub(crate) adjacency: Csr<u32>,
    /// Vertex-to-simplex incidence, each row ascending.
    pub(crate) vertex_simplices: Csr<u32>,
    /// Per simplex, D+1 entries: the neighbour across the facet opposite each local vertex.
    pub(crate) neighbors: Vec<u32>,
    pub(crate) boundary_facets: Vec<BoundaryFacet<D>>,
    pub(crate) boundary_vertices: Vec<u32>,
    pub(crate) vertex_normals: Vec<SVector<f64, D>>,
    pub(crate) one_ring_vertices: Csr<u32>,
    pub(crate) one_ring_masks: Csr<u8>,
}

impl<const D: usize> Topology<D> {
    pub(crate) fn build(
        vertex_count: usize,
        simplices: &[u32],
        inverse_maps: &[SMatrix<f64, D, D>],
        volumes: &[f64],
    ) -> Result<Self, MeshError> {
        let stride = D + 1;
        let n_simplices = simplices.len() / stride;

        // Incidence and adjacency from the simplices' vertex lists.
        let mut incidence: Vec<Vec<u32>> = vec![Vec::new(); vertex_count];
        let mut adjacent: Vec<Vec<u32>> = vec![Vec::new(); vertex_count];
        for (s, verts) in simplices.chunks_exact(stride).enumerate() {
            for &a in verts {
                incidence[a as usize].push(s as u32);
                adjacent[a as usize].extend(verts.iter().copied().filter(|&b| b != a));
            }
        }
        for row in &mut adjacent {
            row.sort_unstable();
            row.dedup();
        }
        let vertex_simplices = Csr::from_rows(incidence);
        let adjacency = Csr::from_rows(adjacent);

        // Face neighbours by matching facet keys; a third holder of a facet is an error.
        let mut neighbors = vec![NO_NEIGHBOR; simplices.len()];
        let mut facets: HashMap<[u32; 3], (u32, u8, bool)> =
            HashMap::with_capacity(n_simplices * stride);
        for (s, verts) in simplices.chunks_exact(stride).enumerate() {
            for local in 0..stride {
                let key = SimplexMesh::<D>::facet_key(verts, local);
                match facets.entry(key) {
                    Entry::Vacant(slot) => {
                        slot.insert((s as u32, local as u8, false));
                    }
                    Entry::Occupied(mut slot) => {
                        let (t, t_local, paired) = *slot.get();
                        let t_slot = t as usize * stride + t_local as usize;
                        if paired {
                            return Err(non_manifold(key, t, neighbors[t_slot], s));
                        }
                        neighbors[t_slot] = s as u32;
                        neighbors[s * stride + local] = t;
                        slot.get_mut().2 = true;
                    }
                }
            }
        }

        // Boundary facets: outward normal is −∇λ_opposite / |∇λ_opposite|, and the facet
        // measure is D · vol · |∇λ_opposite| (vol = measure · height / D, height = 1/|∇λ|).
        let mut boundary_facets = Vec::new();
        let mut on_boundary = vec![false; vertex_count];
        let mut vertex_normals = vec![SVector::<f64, D>::zeros(); vertex_count];
        for (s, verts) in simplices.chunks_exact(stride).enumerate() {
            for local in 0..stride {
                if neighbors[s * stride + local] != NO_NEIGHBOR {
                    continue;
                }
                let grad = barycentric_gradient(&inverse_maps[s], local);
                let norm = grad.norm();
                let normal = -grad / norm;
                let measure = if D == 1 {
                    1.0
                } else {
                    D as f64 * volumes[s] * norm
                };
                for (i, &v) in verts.iter().enumerate() {
                    if i != local {
                        on_boundary[v as usize] = true;
                        vertex_normals[v as usize] += normal * measure;
                    }
                }
                boundary_facets.push(BoundaryFacet {
                    simplex: s as u32,
                    opposite: local as u8,
                    normal,
                    measure,
                });
            }
        }
        for n in &mut vertex_normals {
            let len = n.norm();
            if len > 0.0 {
                *n /= len;
            }
        }
        let boundary_vertices = (0..vertex_count as u32)
            .filter(|&v| on_boundary[v as usize])
            .collect();

        // 1-rings with adjacency bitmasks.
        let mut ring_rows: Vec<Vec<u32>> = Vec::with_capacity(n_simplices);
        let mut mask_rows: Vec<Vec<u8>> = Vec::with_capacity(n_simplices);
        for verts in simplices.chunks_exact(stride) {
            let mut others: Vec<u32> = verts
                .iter()
                .flat_map(|&h| adjacency.row(h as usize).iter().copied())
                .filter(|v| !verts.contains(v))
                .collect();
            others.sort_unstable();
            others.dedup();
            let ring: Vec<u32> = verts.iter().copied().chain(others).collect();
            let masks = ring
                .iter()
                .map(|&v| {
                    verts.iter().enumerate().fold(0u8, |mask, (n, &h)| {
                        let adjacent_to_h =
                            v == h || adjacency.row(h as usize).binary_search(&v).is_ok();
                        mask | (u8::from(adjacent_to_h) << n)
                    })
                })
                .collect();
            ring_rows.push(ring);
            mask_rows.push(masks);
        }

        Ok(Self {
            adjacency,
            vertex_simplices,
            neighbors,
            boundary_facets,
            boundary_vertices,
            vertex_normals,
            one_ring_vertices: Csr::from_rows(ring_rows),
            one_ring_masks: Csr::from_rows(mask_rows),
        })
    }

    /// Vertices sharing an edge with `v`, ascending.
    #[inline]
    pub fn adjacent_vertices(&self, v: usize) -> &[u32] {
        self.adjacency.row(v)
    }

    /// The vertex adjacency as CSR.
    pub fn adjacency(&self) -> &Csr<u32> {
        &self.adjacency
    }

    /// Simplices containing vertex `v`, ascending.
    #[inline]
    pub fn vertex_simplices(&self, v: usize) -> &[u32] {
        self.vertex_simplices.row(v)
    }

    /// The neighbour of simplex `s` across the facet opposite its local vertex `local`.
    #[inline]
    pub fn neighbor(&self, s: usize, local: usize) -> Option<u32> {
        let n = self.neighbors[s * (D + 1) + local];
        (n != NO_NEIGHBOR).then_some(n)
    }

    /// All boundary facets.
    pub fn boundary_facets(&self) -> &[BoundaryFacet<D>] {
        &self.boundary_facets
    }

    /// Vertices on the boundary, ascending.
    pub fn boundary_vertices(&self) -> &[u32] {
        &self.boundary_vertices
    }

    /// Unit outward normal at a boundary vertex (facet-measure-weighted mean of its facets'
    /// normals); zero for interior vertices.
    #[inline]
    pub fn vertex_normal(&self, v: usize) -> SVector<f64, D> {
        self.vertex_normals[v]
    }

    /// The 1-ring of host simplex `s` with its adjacency bitmasks.
    #[inline]
    pub fn one_ring(&self, s: usize) -> OneRing<'_> {
        OneRing {
            vertices: self.one_ring_vertices.row(s),
            masks: self.one_ring_masks.row(s),
        }
    }

    /// Largest 1-ring over all simplices: the stencil capacity a kernel needs.
    pub fn max_one_ring_len(&self) -> usize {
        self.one_ring_vertices
            .rows()
            .map(<[u32]>::len)
            .max()
            .unwrap_or(0)
    }
}

/// ∇λ of local vertex `local` from the simplex's inverse edge matrix.
pub(crate) fn barycentric_gradient<const D: usize>(
    inverse: &SMatrix<f64, D, D>,
    local: usize,
) -> SVector<f64, D> {
    if local == 0 {
        -inverse.row_sum().transpose()
    } else {
        inverse.row(local - 1).transpose()
    }
}

fn non_manifold(key: [u32; 3], first: u32, second: u32, third: usize) -> MeshError {
    MeshError::NonManifoldFacet {
        facet: key.iter().copied().filter(|&v| v != u32::MAX).collect(),
        first: first as usize,
        second: second as usize,
        third,
    }
}
