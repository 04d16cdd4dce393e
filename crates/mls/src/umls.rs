//! The UMLS kernel: MLS over the 1-ring of the host simplex with diminishing weights
//! w_v = η_v · d_v (Cao et al., arXiv 2312.10338).

use nalgebra::SVector;
use umls_mesh::{Barycentric, INSIDE_TOLERANCE, Located, SimplexMesh};

use crate::basis::PolynomialBasis;
use crate::diminishing::{
    diminishing_factor, diminishing_gradient, powered_diminishing, powered_diminishing_slope,
};
use crate::error::MlsError;
use crate::point_cloud::radial_weight;
use crate::solve::{
    Conditioning, Samples, moment_inverse, shape_functions, shape_functions_in_place,
};
use crate::stencil::{GradientKind, MAX_STENCIL, Stencil};
use crate::umls_fit::UmlsFit;
use crate::weight::{CubicBSpline, WeightFunction};

/// How the support radius h_v of each vertex's distance weight d_v = W(|x − x_v| / h_v)
/// is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SupportRadius {
    /// h_v = factor · (largest distance from x_v to a vertex of any simplex whose 1-ring
    /// contains v). With factor ≥ 1, r = |x − x_v| / h_v ≤ 1 for every point where v is in
    /// the stencil, so d_v ≥ W(1) > 0 everywhere it is used (the theory's positivity
    /// requirement) and the radius adapts to graded meshes. h_v belongs to the vertex,
    /// not to the host, so d_v stays smooth across facets. Wide: every ring vertex
    /// weighs at least W(1)/W(0) = 1/4 of the nearest, which smooths transfers and
    /// boundary stress (the `umls-wide` kernel of the CLI).
    PerVertex {
        /// Multiplier, ≥ 1 keeps d_v > 0 on the whole stencil.
        factor: f64,
    },
    /// h_v = factor · (longest edge incident to v): the vertex's own mesh size. Every
    /// host vertex v has η_v = 1 (it is adjacent to the whole host), and with factor > 1/2
    /// its distance weight is positive on every simplex containing it (the profile's
    /// support 2h_v exceeds the longest edge from v), so the D + 1 host vertices alone
    /// keep the moment matrix regular; farther 1-ring vertices fade out with distance
    /// instead of all getting d_v ≥ W(1). Narrower than [`SupportRadius::PerVertex`]:
    /// less smoothing of PIC/APIC transfers and boundary stress (docs/umls-kernel.md).
    IncidentEdge {
        /// Multiplier, > 1/2 keeps every host vertex weighted.
        factor: f64,
    },
    /// h_v = factor · (D! · mean volume of the simplices containing v)^(1/D): the edge of
    /// the right-angled simplex (legs of length h, volume h^D / D!) of the same volume,
    /// so h on a lattice of cells h split into simplices (alternating, one-way or Kuhn),
    /// however the cells are split, and h/√2 at every vertex of the crossed lattice. It
    /// follows a graded mesh like [`SupportRadius::IncidentEdge`] but does not grow where
    /// a vertex carries a cell's diagonal or a jittered long edge, so a uniform lattice
    /// gets one radius (docs/umls-kernel.md, *Element-size radii*). The profile's
    /// support 2h_v must exceed the longest edge from v for every host vertex to stay
    /// weighted: on right-angled lattices factor > √D / 2.
    ElementSize {
        /// Multiplier.
        factor: f64,
    },
    /// One h = factor · (longest edge in the mesh) for all vertices, as in the paper
    /// (factor 1). Distances on a 1-ring reach 2h only in degenerate configurations,
    /// so d_v > 0 except there.
    Global {
        /// Multiplier.
        factor: f64,
    },
}

/// Vertex `v`'s element size (D! · mean volume of its simplices)^(1/D)
/// ([`SupportRadius::ElementSize`]); 0 for a vertex in no simplex.
fn element_size<const D: usize>(mesh: &SimplexMesh<D>, v: usize) -> f64 {
    let simplices = mesh.topology().vertex_simplices(v);
    if simplices.is_empty() {
        return 0.0;
    }
    let volume: f64 = simplices
        .iter()
        .map(|&s| mesh.volume(s as usize).abs())
        .sum();
    let factorial = (1..=D).product::<usize>() as f64;
    (factorial * volume / simplices.len() as f64).powf(1.0 / D as f64)
}

/// The factor of the default support radius, [`SupportRadius::IncidentEdge`]: chosen by
/// the study in docs/umls-kernel.md (accurate walls without linear FE's cell crossing).
pub const DEFAULT_SUPPORT_FACTOR: f64 = 0.9;

impl Default for SupportRadius {
    fn default() -> Self {
        Self::IncidentEdge {
            factor: DEFAULT_SUPPORT_FACTOR,
        }
    }
}

/// Tolerance on the smallest barycentric coordinate for a point to count as inside its host.
pub const HOST_TOLERANCE: f64 = 1e3 * INSIDE_TOLERANCE;

/// The C¹ diminishing-weight MLS kernel on a simplicial mesh.
///
/// Holds the per-vertex support radii of one mesh; every evaluation takes that mesh (the
/// kernel checks the vertex count matches).
#[derive(Debug, Clone, PartialEq)]
pub struct UmlsKernel<const D: usize, W: WeightFunction = CubicBSpline> {
    radii: Vec<f64>,
    weight: W,
    /// p of the weights η^p · d (1: the paper's η · d).
    diminishing_exponent: u32,
    /// Conditioning limit and policy of the moment matrix.
    pub conditioning: Conditioning,
}

impl<const D: usize> UmlsKernel<D, CubicBSpline> {
    /// The default kernel: the paper's cubic B-spline distance weights with the
    /// incident-edge radius of [`SupportRadius::default`].
    pub fn new(mesh: &SimplexMesh<D>) -> Self {
        Self::with_weight(mesh, CubicBSpline, SupportRadius::default())
            .expect("the default factor is valid")
    }
}

impl<const D: usize, W: WeightFunction> UmlsKernel<D, W> {
    /// A kernel with the given distance-weight profile and support radius rule.
    pub fn with_weight(
        mesh: &SimplexMesh<D>,
        weight: W,
        support: SupportRadius,
    ) -> Result<Self, MlsError> {
        let factor = match support {
            SupportRadius::PerVertex { factor }
            | SupportRadius::IncidentEdge { factor }
            | SupportRadius::ElementSize { factor }
            | SupportRadius::Global { factor } => factor,
        };
        if !(factor.is_finite() && factor > 0.0) {
            return Err(MlsError::InvalidParameter {
                parameter: "support radius factor",
                value: factor,
                reason: "must be finite and positive",
            });
        }
        let radii = match support {
            SupportRadius::Global { .. } => {
                vec![factor * mesh.max_edge_length(); mesh.vertex_count()]
            }
            SupportRadius::IncidentEdge { .. } => {
                let topology = mesh.topology();
                (0..mesh.vertex_count())
                    .map(|v| {
                        let xv = mesh.vertex(v);
                        let longest = topology
                            .adjacent_vertices(v)
                            .iter()
                            .map(|&u| (mesh.vertex(u as usize) - xv).norm())
                            .fold(0.0, f64::max);
                        factor * longest
                    })
                    .collect()
            }
            SupportRadius::ElementSize { .. } => (0..mesh.vertex_count())
                .map(|v| factor * element_size(mesh, v))
                .collect(),
            SupportRadius::PerVertex { .. } => {
                let mut reach = vec![0.0f64; mesh.vertex_count()];
                for s in 0..mesh.simplex_count() {
                    let host = mesh.simplex(s);
                    for &v in mesh.topology().one_ring(s).vertices {
                        let xv = mesh.vertex(v as usize);
                        for &n in host {
                            reach[v as usize] =
                                reach[v as usize].max((mesh.vertex(n as usize) - xv).norm());
                        }
                    }
                }
                reach.iter().map(|r| factor * r).collect()
            }
        };
        Ok(Self {
            radii,
            weight,
            diminishing_exponent: 1,
            conditioning: Conditioning::default(),
        })
    }

    /// The same kernel with weights w_v = η_v^p · d_v instead of η_v · d_v
    /// ([`crate::powered_diminishing`]): p = 1 is the paper's kernel. Value and
    /// reconstructed gradient stay continuous and linear fields stay reproduced for any
    /// p ≥ 1 (the weights stay continuous, and vanish where a vertex leaves the ring);
    /// larger p narrows the stencil onto the host's vertices (docs/umls-kernel.md,
    /// *Powered diminishing factor*).
    ///
    /// # Errors
    /// [`MlsError::InvalidParameter`] for p = 0, which would weight every ring vertex
    /// alike and make the weights jump across facets.
    pub fn with_diminishing_exponent(mut self, exponent: u32) -> Result<Self, MlsError> {
        if exponent == 0 {
            return Err(MlsError::InvalidParameter {
                parameter: "diminishing exponent",
                value: 0.0,
                reason: "must be at least 1 (0 makes the weights jump across facets)",
            });
        }
        self.diminishing_exponent = exponent;
        Ok(self)
    }

    /// p of the weights η^p · d.
    pub fn diminishing_exponent(&self) -> u32 {
        self.diminishing_exponent
    }

    /// Support radius h_v of every vertex.
    pub fn support_radii(&self) -> &[f64] {
        &self.radii
    }

    /// Shape functions and gradients at `x` inside simplex `host`, over the host's 1-ring.
    ///
    /// Stencil nodes are the 1-ring vertices (host vertices first). Errors name the host for
    /// an ill-conditioned moment matrix or an oversized ring, and reject a point outside the
    /// host (smallest barycentric coordinate below −[`HOST_TOLERANCE`]).
    pub fn evaluate<const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: &SimplexMesh<D>,
        host: u32,
        x: &SVector<f64, D>,
        gradient: GradientKind,
        out: &mut Stencil<D>,
    ) -> Result<(), MlsError> {
        let lambda = self.host_coordinates(mesh, host, x)?;
        let ring = mesh.topology().one_ring(host as usize);
        if ring.len() > MAX_STENCIL {
            return Err(MlsError::StencilOverflow {
                simplex: Some(host),
                samples: ring.len(),
                capacity: MAX_STENCIL,
            });
        }
        let n = ring.len();
        if gradient == GradientKind::Reconstructed {
            let filled = self.reconstructed::<N, B>(
                mesh,
                host,
                x,
                &lambda,
                &mut out.nodes[..n],
                &mut out.values[..n],
                &mut out.gradients[..n],
            );
            return match filled {
                Ok(condition) => {
                    out.len = n;
                    out.condition = condition;
                    out.gradient_kind = gradient;
                    Ok(())
                }
                Err(error) => {
                    out.clear();
                    Err(error)
                }
            };
        }
        let lambda_gradients = mesh.barycentric_gradients(host as usize);
        let mut positions = [SVector::<f64, D>::zeros(); MAX_STENCIL];
        let mut weights = [0.0; MAX_STENCIL];
        let mut weight_gradients = [SVector::<f64, D>::zeros(); MAX_STENCIL];
        let p = self.diminishing_exponent;
        for (i, (&v, &mask)) in ring.vertices.iter().zip(ring.masks).enumerate() {
            let xv = mesh.vertex(v as usize);
            let h = self.radii[v as usize];
            let (d, dd) = radial_weight(&self.weight, x, xv, h);
            let linear = diminishing_factor(mask, lambda.as_slice());
            let eta = powered_diminishing(linear, p);
            positions[i] = *xv;
            weights[i] = eta * d;
            weight_gradients[i] = match gradient {
                // η frozen at x: only the distance weight varies.
                GradientKind::FrozenEta => dd * eta,
                _ => {
                    diminishing_gradient(mask, lambda_gradients.as_slice())
                        * (d * powered_diminishing_slope(linear, p))
                        + dd * eta
                }
            };
        }
        let samples = Samples {
            nodes: ring.vertices,
            positions: &positions[..n],
            weights: &weights[..n],
            weight_gradients: &weight_gradients[..n],
        };
        shape_functions::<D, N, B>(
            x,
            &samples,
            self.scale(mesh, host),
            gradient,
            &self.conditioning,
            out,
        )
        .map_err(|e| with_host(e, host))
    }

    /// [`Self::evaluate`] written into the caller's slices, whose length must be the
    /// host's 1-ring size (`mesh.topology().one_ring(host).len()`), so that a caller
    /// with its own stencil storage (an MPM engine's) needs no intermediate copy.
    /// `located` is the host with the barycentric coordinates of `x` in it, as
    /// [`SimplexMesh::locate`] and [`SimplexMesh::locate_from`] give them (they are not
    /// computed again; a caller holding only the host builds them with
    /// [`SimplexMesh::barycentric`]). With the reconstructed gradient no array of the fit
    /// is bounded, so any ring size is accepted; the other gradients keep the
    /// [`MAX_STENCIL`] cap. Same values as [`Self::evaluate`], bit for bit; returns the
    /// moment matrix's condition number.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate_into<const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: &SimplexMesh<D>,
        located: &Located<D>,
        x: &SVector<f64, D>,
        gradient: GradientKind,
        nodes: &mut [u32],
        values: &mut [f64],
        gradients: &mut [SVector<f64, D>],
    ) -> Result<f64, MlsError> {
        let (host, ring) = self.check_located(mesh, located)?;
        let lambda = &located.barycentric;
        if nodes.len() != ring || values.len() != ring || gradients.len() != ring {
            return Err(MlsError::OutputLength {
                simplex: host,
                ring,
                nodes: nodes.len(),
                values: values.len(),
                gradients: gradients.len(),
            });
        }
        if gradient == GradientKind::Reconstructed {
            return self.reconstructed::<N, B>(mesh, host, x, lambda, nodes, values, gradients);
        }
        let mut stencil = Stencil::new();
        self.evaluate::<N, B>(mesh, host, x, gradient, &mut stencil)?;
        nodes.copy_from_slice(stencil.nodes());
        values.copy_from_slice(stencil.values());
        gradients.copy_from_slice(stencil.gradients());
        Ok(stencil.condition_number())
    }

    /// Checks a location as [`Self::evaluate_into`] and [`Self::fit_into`] take it: a host
    /// of `mesh`, which the kernel was built for, holding the point; returns the host and
    /// its 1-ring's size.
    fn check_located(
        &self,
        mesh: &SimplexMesh<D>,
        located: &Located<D>,
    ) -> Result<(u32, usize), MlsError> {
        let host = located.simplex;
        self.check_host(mesh, host)?;
        let lambda = &located.barycentric;
        if lambda.min() < -HOST_TOLERANCE {
            return Err(MlsError::OutsideHost {
                simplex: host,
                min_barycentric: lambda.min(),
            });
        }
        Ok((host, mesh.topology().one_ring(host as usize).len()))
    }

    /// Checks that `host` is a simplex of `mesh` and that the kernel was built for it.
    fn check_host(&self, mesh: &SimplexMesh<D>, host: u32) -> Result<(), MlsError> {
        if host as usize >= mesh.simplex_count() {
            return Err(MlsError::NoSuchSimplex {
                simplex: host,
                count: mesh.simplex_count(),
            });
        }
        if self.radii.len() != mesh.vertex_count() {
            return Err(MlsError::InvalidParameter {
                parameter: "mesh vertex count",
                value: mesh.vertex_count() as f64,
                reason: "differs from the mesh this kernel was built for",
            });
        }
        Ok(())
    }

    /// The host's barycentric coordinates of `x`, after checking the host, the mesh and
    /// that `x` lies in the host.
    fn host_coordinates(
        &self,
        mesh: &SimplexMesh<D>,
        host: u32,
        x: &SVector<f64, D>,
    ) -> Result<Barycentric<D>, MlsError> {
        self.check_host(mesh, host)?;
        let lambda = mesh.barycentric(host as usize, x);
        if lambda.min() < -HOST_TOLERANCE {
            return Err(MlsError::OutsideHost {
                simplex: host,
                min_barycentric: lambda.min(),
            });
        }
        Ok(lambda)
    }

    /// The length the coordinates are scaled by: any length of the order of the local
    /// spacing makes M O(1); the host's first vertex radius is at hand and constant on
    /// the host.
    fn scale(&self, mesh: &SimplexMesh<D>, host: u32) -> f64 {
        self.radii[mesh.simplex(host as usize)[0] as usize]
    }

    /// The reconstructed-gradient evaluation, written straight into slices of the ring's
    /// length: weights and scaled offsets first, then the in-place solve over them.
    #[allow(clippy::too_many_arguments)]
    fn reconstructed<const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: &SimplexMesh<D>,
        host: u32,
        x: &SVector<f64, D>,
        lambda: &Barycentric<D>,
        nodes: &mut [u32],
        values: &mut [f64],
        gradients: &mut [SVector<f64, D>],
    ) -> Result<f64, MlsError> {
        let ring = mesh.topology().one_ring(host as usize);
        nodes.copy_from_slice(ring.vertices);
        let inv_scale = self.ring_weights(mesh, host, x, lambda, values, gradients)?;
        shape_functions_in_place::<D, N, B>(values, gradients, inv_scale, &self.conditioning)
            .map(|(_, condition)| condition)
            .map_err(|e| with_host(e, host))
    }

    /// The weights w_v = η_v d_v of the host's 1-ring at `x` into `weights`, the scaled
    /// offsets (x_v − x)/s into `scaled_offsets` (both of the ring's length), and 1/s.
    fn ring_weights(
        &self,
        mesh: &SimplexMesh<D>,
        host: u32,
        x: &SVector<f64, D>,
        lambda: &Barycentric<D>,
        weights: &mut [f64],
        scaled_offsets: &mut [SVector<f64, D>],
    ) -> Result<f64, MlsError> {
        let inv_scale = crate::solve::inverse_scale(self.scale(mesh, host))?;
        let ring = mesh.topology().one_ring(host as usize);
        // Two passes: the loads of the ring's vertices and radii (scattered over the
        // mesh) first, then the arithmetic over the slices alone, which overlaps the
        // square roots and divisions of neighbouring vertices. The same operations as
        // `radial_weight` (|x_v − x| = |x − x_v| bit for bit), so the same bits.
        for ((&v, radius), offset) in ring
            .vertices
            .iter()
            .zip(weights.iter_mut())
            .zip(scaled_offsets.iter_mut())
        {
            *offset = mesh.vertex(v as usize) - x;
            *radius = self.radii[v as usize];
        }
        // The exponent is chosen outside the loop, so the paper's η · d keeps its loop
        // free of the power's branch.
        match self.diminishing_exponent {
            1 => self.weigh_ring(
                ring.masks,
                lambda,
                weights,
                scaled_offsets,
                inv_scale,
                |eta| eta,
            ),
            p => self.weigh_ring(
                ring.masks,
                lambda,
                weights,
                scaled_offsets,
                inv_scale,
                |eta| powered_diminishing(eta, p),
            ),
        }
        Ok(inv_scale)
    }

    /// The arithmetic pass of [`Self::ring_weights`]: `weights` holds the radii and
    /// `scaled_offsets` the offsets x_v − x on entry, the weights power(η_v) d_v and the
    /// offsets times `inv_scale` on return.
    #[inline(always)]
    fn weigh_ring(
        &self,
        masks: &[u8],
        lambda: &Barycentric<D>,
        weights: &mut [f64],
        scaled_offsets: &mut [SVector<f64, D>],
        inv_scale: f64,
        power: impl Fn(f64) -> f64,
    ) {
        for ((weight, xi), &mask) in weights.iter_mut().zip(scaled_offsets.iter_mut()).zip(masks) {
            let (d, _) = self.weight.evaluate(xi.norm() / *weight);
            *weight = power(diminishing_factor(mask, lambda.as_slice())) * d;
            *xi *= inv_scale;
        }
    }

    /// The reconstructed-gradient fit at `x` in factored form: the 1-ring's weights
    /// into `weights` (the ring's length), and M⁻¹ with 1/s returned, from which
    /// [`UmlsFit::visit`] rebuilds the entries of [`Self::evaluate_into`] bit for bit.
    /// `scaled_offsets`, of the ring's length too, is scratch. `located` as for
    /// [`Self::evaluate_into`]. An engine that stores fits instead of stencils keeps
    /// N² + 1 numbers per particle and one per ring vertex (the node indices are the
    /// host's ring).
    ///
    /// # Errors
    /// As [`Self::evaluate_into`]: a host outside the mesh or not holding `x`, slices
    /// of another length, or a moment matrix the conditioning policy rejects.
    pub fn fit_into<const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: &SimplexMesh<D>,
        located: &Located<D>,
        x: &SVector<f64, D>,
        weights: &mut [f64],
        scaled_offsets: &mut [SVector<f64, D>],
    ) -> Result<UmlsFit<N>, MlsError> {
        let (host, ring) = self.check_located(mesh, located)?;
        let lambda = &located.barycentric;
        if weights.len() != ring || scaled_offsets.len() != ring {
            return Err(MlsError::OutputLength {
                simplex: host,
                ring,
                nodes: ring,
                values: weights.len(),
                gradients: scaled_offsets.len(),
            });
        }
        let inv_scale = self.ring_weights(mesh, host, x, lambda, weights, scaled_offsets)?;
        let (inverse, _) = moment_inverse::<D, N, B>(weights, scaled_offsets, &self.conditioning)
            .map_err(|e| with_host(e, host))?;
        Ok(UmlsFit::new(&inverse, inv_scale))
    }

    /// Locates `x` (walking from `hint` when given) and evaluates there; returns the host.
    pub fn evaluate_at<const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: &SimplexMesh<D>,
        x: &SVector<f64, D>,
        hint: Option<u32>,
        gradient: GradientKind,
        out: &mut Stencil<D>,
    ) -> Result<u32, MlsError> {
        let located = match hint {
            Some(h) => mesh.locate_from(x, h),
            None => mesh.locate(x),
        }
        .ok_or_else(|| MlsError::OutsideMesh {
            point: x.iter().copied().collect(),
        })?;
        self.evaluate::<N, B>(mesh, located.simplex, x, gradient, out)?;
        Ok(located.simplex)
    }
}

fn with_host(error: MlsError, host: u32) -> MlsError {
    match error {
        MlsError::IllConditioned {
            condition,
            limit,
            samples,
            basis,
            ..
        } => MlsError::IllConditioned {
            simplex: Some(host),
            condition,
            limit,
            samples,
            basis,
        },
        MlsError::StencilOverflow {
            samples, capacity, ..
        } => MlsError::StencilOverflow {
            simplex: Some(host),
            samples,
            capacity,
        },
        other => other,
    }
}
