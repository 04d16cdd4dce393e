//! Mesh topology, computed once at construction: adjacency, incidence, face
//! neighbours, boundary facets and the 1-rings the UMLS kernel needs.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use crate::csr::Csr;
use crate::error::MeshError;
use crate::mesh::{NO_NEIGHBOR, SimplexMesh};

/// Vertices (or simplices) per parallel work item of the construction.
const ROW_CHUNK: usize = 2048;

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

        // Incidence and adjacency as sorted (vertex, other) pairs: sorting in parallel
        // and cutting into rows replaces a vector per vertex.
        let mut incidence: Vec<(u32, u32)> = simplices
            .par_chunks_exact(stride)
            .enumerate()
            .flat_map_iter(|(s, verts)| verts.iter().map(move |&v| (v, s as u32)))
            .collect();
        incidence.par_sort_unstable();
        let vertex_simplices =
            Csr::from_sorted_pairs(vertex_count, &incidence, "vertex-simplex incidences")?;
        drop(incidence);
        // Each vertex's neighbours: the other vertices of its simplices, per vertex in
        // parallel chunks.
        let adjacency = {
            let chunks: Vec<(Vec<usize>, Vec<u32>)> = (0..vertex_count.div_ceil(ROW_CHUNK))
                .into_par_iter()
                .map(|c| {
                    let chunk = c * ROW_CHUNK..((c + 1) * ROW_CHUNK).min(vertex_count);
                    let (mut lengths, mut values) = (Vec::with_capacity(chunk.len()), Vec::new());
                    let mut row = Vec::new();
                    for v in chunk {
                        row.clear();
                        for &s in vertex_simplices.row(v) {
                            let verts = &simplices[s as usize * stride..][..stride];
                            row.extend(verts.iter().copied().filter(|&w| w as usize != v));
                        }
                        row.sort_unstable();
                        row.dedup();
                        lengths.push(row.len());
                        values.extend_from_slice(&row);
                    }
                    (lengths, values)
                })
                .collect();
            joined(
                chunks.iter().map(|c| &c.0[..]),
                chunks.iter().map(|c| &c.1[..]),
                "vertex adjacencies",
            )?
        };

        // Face neighbours: every facet's key with its slot (simplex · stride + local),
        // sorted, so the holders of one facet are neighbours in the list. A third holder
        // is an error; of several, the one a pass in simplex order meets first (the
        // smallest third slot) is reported, whatever the thread count.
        let mut facets: Vec<([u32; 3], u32)> = (0..n_simplices * stride)
            .into_par_iter()
            .map(|slot| {
                let verts = &simplices[slot / stride * stride..][..stride];
                (
                    SimplexMesh::<D>::facet_key(verts, slot % stride),
                    slot as u32,
                )
            })
            .collect();
        facets.par_sort_unstable();
        let mut neighbors = vec![NO_NEIGHBOR; simplices.len()];
        let mut non_manifold_at: Option<(u32, MeshError)> = None;
        let mut i = 0;
        while i < facets.len() {
            let key = facets[i].0;
            let mut j = i + 1;
            while j < facets.len() && facets[j].0 == key {
                j += 1;
            }
            match j - i {
                1 => {}
                2 => {
                    let (a, b) = (facets[i].1 as usize, facets[i + 1].1 as usize);
                    neighbors[a] = (b / stride) as u32;
                    neighbors[b] = (a / stride) as u32;
                }
                _ => {
                    let third = facets[i + 2].1;
                    if non_manifold_at.as_ref().is_none_or(|(t, _)| third < *t) {
                        let holder = |k: usize| facets[i + k].1 / stride as u32;
                        let error = non_manifold(key, holder(0), holder(1), holder(2) as usize);
                        non_manifold_at = Some((third, error));
                    }
                }
            }
            i = j;
        }
        if let Some((_, error)) = non_manifold_at {
            return Err(error);
        }
        drop(facets);

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

        // 1-rings with adjacency bitmasks, per chunk of simplices in parallel: the
        // pairs (v, n) for every host vertex n and every v equal or adjacent to it,
        // sorted, give each ring vertex once with its mask as the OR of its pairs' bits.
        let (one_ring_vertices, one_ring_masks) = {
            let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<u8>)> = simplices
                .par_chunks(ROW_CHUNK * stride)
                .map(|chunk| {
                    let (mut lengths, mut ring, mut masks) = (Vec::new(), Vec::new(), Vec::new());
                    let mut pairs: Vec<(u32, u8)> = Vec::new();
                    for verts in chunk.chunks_exact(stride) {
                        pairs.clear();
                        for (n, &h) in verts.iter().enumerate() {
                            pairs.push((h, 1 << n));
                            pairs.extend(adjacency.row(h as usize).iter().map(|&v| (v, 1u8 << n)));
                        }
                        pairs.sort_unstable_by_key(|p| p.0);
                        let start = ring.len();
                        // The hosts first, in local order.
                        for &h in verts {
                            ring.push(h);
                            masks.push(0);
                        }
                        for &(v, bit) in &pairs {
                            if let Some(n) = verts.iter().position(|&h| h == v) {
                                masks[start + n] |= bit;
                            } else if ring.len() > start + stride
                                && *ring.last().expect("not empty") == v
                            {
                                *masks.last_mut().expect("not empty") |= bit;
                            } else {
                                ring.push(v);
                                masks.push(bit);
                            }
                        }
                        lengths.push(ring.len() - start);
                    }
                    (lengths, ring, masks)
                })
                .collect();
            let lengths = || chunks.iter().map(|c| &c.0[..]);
            (
                joined(lengths(), chunks.iter().map(|c| &c.1[..]), "1-ring entries")?,
                joined(lengths(), chunks.iter().map(|c| &c.2[..]), "1-ring entries")?,
            )
        };

        Ok(Self {
            adjacency,
            vertex_simplices,
            neighbors,
            boundary_facets,
            boundary_vertices,
            vertex_normals,
            one_ring_vertices,
            one_ring_masks,
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

/// The rows that parallel chunks built (each chunk's row lengths and values back to
/// back), joined in chunk order into one CSR.
fn joined<'a, T: Copy + Default + Send + Sync + 'a>(
    lengths: impl Iterator<Item = &'a [usize]>,
    values: impl Iterator<Item = &'a [T]>,
    what: &'static str,
) -> Result<Csr<T>, MeshError> {
    // The chunks are copied into their places in parallel: for the 1-rings of a large
    // mesh this is hundreds of megabytes, and a serial copy was a third of the build.
    let values: Vec<&[T]> = values.collect();
    let mut joined = vec![T::default(); values.iter().map(|v| v.len()).sum()];
    let mut places = Vec::with_capacity(values.len());
    let mut rest = &mut joined[..];
    for v in &values {
        let (place, tail) = rest.split_at_mut(v.len());
        places.push(place);
        rest = tail;
    }
    places
        .into_par_iter()
        .zip(values)
        .for_each(|(place, v)| place.copy_from_slice(v));
    Csr::from_lengths(lengths.flatten().copied(), joined, what)
}

fn non_manifold(key: [u32; 3], first: u32, second: u32, third: usize) -> MeshError {
    MeshError::NonManifoldFacet {
        facet: key.iter().copied().filter(|&v| v != u32::MAX).collect(),
        first: first as usize,
        second: second as usize,
        third,
    }
}
