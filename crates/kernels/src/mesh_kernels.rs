//! Kernels on simplicial meshes: UMLS and linear finite elements.

use std::sync::Arc;

use nalgebra::SVector;
use std::marker::PhantomData;
use umls_mesh::{Barycentric, Located, SimplexMesh};

use umls_mls::{
    CubicBSpline, GradientKind, Linear, PolynomialBasis, UmlsFit, UmlsKernel, WeightFunction,
};
use umls_transfer::{DomainExit, FactorLayout, Kernel, KernelError, Stencil};

/// The node methods of a kernel whose nodes are the vertices of `self.mesh`.
macro_rules! mesh_nodes {
    () => {
        fn node_count(&self) -> usize {
            self.mesh.vertex_count()
        }

        // Inlined: the transfers of stored entries take each entry's offset from it.
        #[inline]
        fn node_position(&self, node: usize) -> SVector<f64, D> {
            *self.mesh.vertex(node)
        }

        /// The shortest simplex height: P1 elements' explicit stability limit scales with
        /// it (a right triangle of legs h has height h/√2 across its hypotenuse).
        fn spacing(&self) -> f64 {
            self.mesh.min_height()
        }

        fn domain_exit(
            &self,
            x: &SVector<f64, D>,
            cache: &mut HostCache<D>,
        ) -> Option<DomainExit<D>> {
            exit(&self.mesh, x, cache)
        }
    };
}

/// Where `x` left the mesh, seen from the cached host: a walk towards `x` from the host
/// until it would cross a boundary facet; that facet, and the last simplex's point on it
/// (negative barycentric coordinates clamped to zero). `None` inside the mesh (or behind
/// a concavity, where the walk is not the way out), and before the first location.
///
/// The walk is [`SimplexMesh::walk`]'s, so where it finds `x` inside a simplex, that
/// simplex and its coordinates are what the next location of `x` from the cached host
/// computes: they go into `cache` for it ([`HostCache`]).
fn exit<const D: usize>(
    mesh: &SimplexMesh<D>,
    x: &SVector<f64, D>,
    cache: &mut HostCache<D>,
) -> Option<DomainExit<D>> {
    /// A particle moves at most about a cell per step: a few simplices of walk.
    const MAX_STEPS: usize = 64;
    let mut host = cache.host? as usize;
    let mut found = None;
    for _ in 0..MAX_STEPS {
        let lambda = mesh.barycentric(host, x);
        let crossed = lambda.argmin();
        if lambda.as_slice()[crossed] >= -umls_mesh::INSIDE_TOLERANCE {
            cache.remember(
                x,
                Located {
                    simplex: host as u32,
                    barycentric: lambda,
                },
            );
            return None;
        }
        match mesh.topology().neighbor(host, crossed) {
            Some(next) => host = next as usize,
            None => {
                found = Some((lambda, crossed));
                break;
            }
        }
    }
    let (lambda, crossed) = found?;
    if mesh.locate(x).is_some() {
        return None;
    }
    let gradient = mesh.barycentric_gradients(host).as_slice()[crossed];
    let mut coords = [0.0; 4];
    for (c, l) in coords.iter_mut().zip(lambda.as_slice()) {
        *c = l.max(0.0);
    }
    let total: f64 = coords.iter().sum();
    coords.iter_mut().for_each(|c| *c /= total);
    let clamped = Barycentric::<D>::from_slice(&coords[..=D])?;
    let mut facet = [0u32; 3];
    for (slot, &v) in facet.iter_mut().zip(
        mesh.simplex(host)
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != crossed)
            .map(|(_, v)| v),
    ) {
        *slot = v;
    }
    Some(DomainExit {
        facet,
        facet_len: D,
        normal: -gradient / gradient.norm(),
        inside: mesh.point_at(host, &clamped),
    })
}

/// Where a particle was last found in a mesh: its host simplex (`None` before the first
/// location), and possibly a location found ahead of time.
///
/// G2P's domain-exit walk ([`Kernel::domain_exit`]) evaluates the moved particle's
/// barycentric coordinates in its host, the walk the next step's location repeats. Each
/// evaluation loads the host's inverse map, which the step's other traffic has evicted
/// by then (a cache miss per particle, about 5 % of a UMLS step on the fluid box). So
/// the walk leaves its result here, keyed by the position it was found for (bit for
/// bit), and the next location of that same position takes it instead of walking again:
/// the same simplex and coordinates, so the same bits.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HostCache<const D: usize> {
    /// The simplex the particle was last found in.
    pub host: Option<u32>,
    /// A position found inside `host` by a walk, with its barycentric coordinates there.
    ahead: Option<(SVector<f64, D>, Barycentric<D>)>,
}

impl<const D: usize> HostCache<D> {
    /// Keeps `located`, the walk's result for `x`, for the next location of `x`.
    fn remember(&mut self, x: &SVector<f64, D>, located: Located<D>) {
        self.host = Some(located.simplex);
        self.ahead = Some((*x, located.barycentric));
    }

    /// The location kept for exactly `x`, if any; the kept location is used up either
    /// way, since the host it was found in is about to change.
    fn take_ahead(&mut self, x: &SVector<f64, D>) -> Option<Located<D>> {
        let (at, barycentric) = self.ahead.take()?;
        let same = at
            .iter()
            .zip(x.iter())
            .all(|(a, b)| a.to_bits() == b.to_bits());
        Some(Located {
            simplex: self.host.filter(|_| same)?,
            barycentric,
        })
    }
}

/// Locates `x` walking from the cached host (BVH on the first call) and updates the cache.
fn locate<const D: usize>(
    mesh: &SimplexMesh<D>,
    x: &SVector<f64, D>,
    cache: &mut HostCache<D>,
) -> Result<u32, KernelError> {
    locate_with_coordinates(mesh, x, cache).map(|located| located.simplex)
}

/// [`locate`] with the barycentric coordinates the location computed anyway.
fn locate_with_coordinates<const D: usize>(
    mesh: &SimplexMesh<D>,
    x: &SVector<f64, D>,
    cache: &mut HostCache<D>,
) -> Result<Located<D>, KernelError> {
    if let Some(located) = cache.take_ahead(x) {
        return Ok(located);
    }
    let found = match cache.host {
        Some(host) => mesh.locate_from(x, host),
        None => mesh.locate(x),
    }
    .ok_or_else(|| KernelError::OutsideDomain {
        point: x.iter().copied().collect(),
    })?;
    cache.host = Some(found.simplex);
    Ok(found)
}

/// The smallest and largest vertex of `simplex`'s 1-ring: a UMLS stencil's node range.
fn ring_range<const D: usize>(mesh: &SimplexMesh<D>, simplex: u32) -> (u32, u32) {
    mesh.topology()
        .one_ring(simplex as usize)
        .vertices
        .iter()
        .fold((u32::MAX, 0), |(l, h), &v| (l.min(v), h.max(v)))
}

/// The UMLS kernel (C¹ diminishing-weight MLS over the host's 1-ring) as an MPM kernel.
/// Nodes are the mesh vertices.
///
/// The shape-function gradient is the MLS fit's reconstructed ("diffuse") gradient by
/// default, which is continuous across facets; [`Self::with_gradient`] selects the full
/// derivative instead, which differentiates the weights too: it is divergence-consistent
/// on unstructured tetrahedra where the reconstructed one is not, but it jumps across
/// facets with the diminishing factor's gradient; or the derivative at frozen
/// diminishing factors, continuous again (docs/umls-kernel.md has all three measured).
/// [`Self::with_integration_correction`] corrects the internal force's gradients so that
/// they integrate like the derivative (the command line's default `umls` kernel is the
/// reconstructed gradient with it).
///
/// `N` is the size of the polynomial basis `B` (D + 1 for [`Linear`], the default;
/// (D + 1)(D + 2)/2 for [`umls_mls::Quadratic`]) and `W` the distance-weight profile.
/// Use the aliases [`Umls1`], [`Umls2`], [`Umls3`] for the linear fit and
/// [`UmlsQuadratic2`], [`UmlsQuadratic3`] for the quadratic one.
#[derive(Debug, Clone)]
pub struct UmlsMeshKernel<const D: usize, const N: usize, B = Linear, W = CubicBSpline>
where
    W: WeightFunction,
{
    mesh: Arc<SimplexMesh<D>>,
    kernel: UmlsKernel<D, W>,
    gradient: GradientKind,
    /// The force's integration correction ξ_i per vertex, if asked for
    /// ([`Self::with_integration_correction`]).
    correction: Option<Arc<[SVector<f64, D>]>>,
    basis: PhantomData<fn() -> B>,
}

/// UMLS on segments.
pub type Umls1 = UmlsMeshKernel<1, 2>;
/// UMLS on triangles.
pub type Umls2 = UmlsMeshKernel<2, 3>;
/// UMLS on tetrahedra.
pub type Umls3 = UmlsMeshKernel<3, 4>;
/// UMLS with the quadratic basis on triangles (6 monomials).
pub type UmlsQuadratic2 = UmlsMeshKernel<2, 6, umls_mls::Quadratic>;
/// UMLS with the quadratic basis on tetrahedra (10 monomials).
pub type UmlsQuadratic3 = UmlsMeshKernel<3, 10, umls_mls::Quadratic>;

impl<const D: usize, const N: usize, B> UmlsMeshKernel<D, N, B, CubicBSpline> {
    /// The default kernel on `mesh` ([`UmlsKernel::new`]: the paper's cubic B-spline
    /// distance weights with the incident-edge support radius).
    pub fn new(mesh: Arc<SimplexMesh<D>>) -> Self {
        let kernel = UmlsKernel::new(&mesh);
        Self::with_kernel(mesh, kernel)
    }
}

impl<const D: usize, const N: usize, B, W: WeightFunction> UmlsMeshKernel<D, N, B, W> {
    /// A kernel with custom MLS settings (weights, radii, conditioning) built for `mesh`.
    pub fn with_kernel(mesh: Arc<SimplexMesh<D>>, kernel: UmlsKernel<D, W>) -> Self {
        Self {
            mesh,
            kernel,
            gradient: GradientKind::Reconstructed,
            correction: None,
            basis: PhantomData,
        }
    }

    /// The same kernel with shape-function gradients of the given kind.
    #[must_use]
    pub fn with_gradient(mut self, gradient: GradientKind) -> Self {
        self.gradient = gradient;
        // A correction fitted for another gradient no longer applies.
        self.correction = None;
        self
    }

    /// The same kernel with the force's gradients corrected to ∇N_i + N_i (ξ_i − ξ̄_p)
    /// ([`Kernel::force_gradient_correction`] hands the engine ξ), with ξ_i
    /// fitted over the mesh so that every vertex's corrected gradient integrates like the
    /// derivative of N_i (integration correction; the velocity gradient keeps the
    /// stencils' own). Costs one fit at 3^D points of every simplex (2^D in 3D) and a few
    /// of every boundary facet, once, in parallel. The full derivative needs no
    /// correction: with it the kernel stays uncorrected. Fails where a fit fails.
    pub fn with_integration_correction(mut self) -> Result<Self, KernelError>
    where
        B: PolynomialBasis<D, N>,
    {
        self.correction = if self.gradient == GradientKind::Full {
            None
        } else {
            Some(
                crate::integration_correction::node_corrections(
                    &self,
                    crate::integration_correction::points_per_axis(D),
                )?
                .into(),
            )
        };
        Ok(self)
    }

    /// Which gradient the stencils carry.
    pub fn gradient(&self) -> GradientKind {
        self.gradient
    }

    /// The mesh.
    pub fn mesh(&self) -> &Arc<SimplexMesh<D>> {
        &self.mesh
    }

    /// The MLS settings.
    pub fn kernel(&self) -> &UmlsKernel<D, W> {
        &self.kernel
    }

    /// The fit at `x`, located with its barycentric coordinates in `located`, written
    /// into `out`'s nodes, values and gradients (offsets left as they are); `out` is
    /// cleared when the fit fails. The stencils and the integration correction's
    /// quadrature both evaluate the kernel through it.
    pub(crate) fn fit_into(
        &self,
        located: &Located<D>,
        x: &SVector<f64, D>,
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError>
    where
        B: PolynomialBasis<D, N>,
    {
        // Written in place: no fixed-capacity stencil between the fit and `out`.
        let entries = out.entries_mut(self.ring_len(located));
        let evaluated =
            self.fit_slices(located, x, entries.nodes, entries.values, entries.gradients);
        if evaluated.is_err() {
            out.clear();
        }
        evaluated
    }

    /// The size of the 1-ring of `located`'s host: the length of its stencil.
    fn ring_len(&self, located: &Located<D>) -> usize {
        self.mesh
            .topology()
            .one_ring(located.simplex as usize)
            .len()
    }

    /// The fit at `x` written into slices of the ring's length ([`Self::ring_len`]),
    /// with the fit's error as the port's.
    fn fit_slices(
        &self,
        located: &Located<D>,
        x: &SVector<f64, D>,
        nodes: &mut [u32],
        values: &mut [f64],
        gradients: &mut [SVector<f64, D>],
    ) -> Result<(), KernelError>
    where
        B: PolynomialBasis<D, N>,
    {
        self.kernel
            .evaluate_into::<N, B>(
                &self.mesh,
                located,
                x,
                self.gradient,
                nodes,
                values,
                gradients,
            )
            .map(|_| ())
            .map_err(|e| KernelError::evaluation("UMLS", e))
    }
}

impl<const D: usize, const N: usize, B, W> Kernel<D> for UmlsMeshKernel<D, N, B, W>
where
    B: PolynomialBasis<D, N>,
    W: WeightFunction,
{
    type Cache = HostCache<D>;
    const MAY_BE_TENSOR_PRODUCT: bool = false;

    mesh_nodes!();

    fn stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut HostCache<D>,
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError> {
        let located = locate_with_coordinates(&self.mesh, x, cache)?;
        self.fit_into(&located, x, out)?;
        let entries = out.entries_mut(out.len());
        for (offset, &v) in entries.offsets.iter_mut().zip(entries.nodes.iter()) {
            *offset = self.mesh.vertex(v as usize) - x;
        }
        Ok(())
    }

    /// The fit written straight onto the ends of the engine's arrays: no stencil in
    /// between to copy from, and no offsets, which stored entries do not keep (a copy and
    /// the offsets were a tenth of the stencil stage on the 3D column).
    fn append_stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut HostCache<D>,
        _scratch: &mut Stencil<D>,
        nodes: &mut Vec<u32>,
        values: &mut Vec<f64>,
        gradients: &mut Vec<SVector<f64, D>>,
    ) -> Result<(), KernelError> {
        let located = locate_with_coordinates(&self.mesh, x, cache)?;
        let (start, end) = (nodes.len(), nodes.len() + self.ring_len(&located));
        nodes.resize(end, 0);
        values.resize(end, 0.0);
        gradients.resize(end, SVector::zeros());
        let evaluated = self.fit_slices(
            &located,
            x,
            &mut nodes[start..],
            &mut values[start..],
            &mut gradients[start..],
        );
        if evaluated.is_err() {
            nodes.truncate(start);
            values.truncate(start);
            gradients.truncate(start);
        }
        evaluated
    }

    /// The host's 1-ring's smallest and largest vertex, without the fit: the engine's
    /// ordering pass needs only this, so a step with recomputed stencils fits twice
    /// (P2G and G2P), not three times. A fit that fails (an ill-conditioned moment
    /// matrix, a ring beyond the full gradient's cap) is reported by the evaluation
    /// that first makes it, naming the particle
    /// (`crates/engine/tests/stencil_storage_errors.rs`).
    fn node_range(
        &self,
        x: &SVector<f64, D>,
        cache: &mut HostCache<D>,
        _scratch: &mut Stencil<D>,
    ) -> Result<(u32, u32), KernelError> {
        let host = locate(&self.mesh, x, cache)?;
        Ok(ring_range(&self.mesh, host))
    }

    fn force_gradient_correction(&self) -> Option<&[SVector<f64, D>]> {
        self.correction.as_deref()
    }

    /// The fit's stencil is the host's whole 1-ring, whose vertices surround the point
    /// wherever the host is not on the mesh's boundary, so D_p keeps the order of h²
    /// there (linear elements' D_p vanishes at the vertices). At a corner of the mesh
    /// the fit is one-sided and D_p can be indefinite; the engine reports a particle
    /// whose D_p it cannot invert.
    fn regular_second_moment(&self) -> bool {
        true
    }

    /// With the reconstructed gradient: the fit's M⁻¹ and 1/s per particle and its
    /// weight per ring vertex ([`UmlsFit`]). The full and frozen-η gradients also need
    /// the weights' gradients and are not factored.
    fn factor_layout(&self) -> Option<FactorLayout> {
        (self.gradient == GradientKind::Reconstructed).then_some(FactorLayout {
            per_particle: UmlsFit::<N>::LEN,
            per_entry: 1,
        })
    }

    fn factor_stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut HostCache<D>,
        scratch: &mut Stencil<D>,
        particle: &mut [f64],
        entries: &mut Vec<f64>,
    ) -> Result<(u32, u32), KernelError> {
        if self.factor_layout().is_none() {
            return Err(KernelError::NotFactored {
                kernel: "UMLS with the full or frozen-η gradient",
            });
        }
        let located = locate_with_coordinates(&self.mesh, x, cache)?;
        let ring = self.mesh.topology().one_ring(located.simplex as usize);
        let start = entries.len();
        entries.resize(start + ring.len(), 0.0);
        let scaled_offsets = scratch.entries_mut(ring.len()).gradients;
        let fit = self
            .kernel
            .fit_into::<N, B>(
                &self.mesh,
                &located,
                x,
                &mut entries[start..],
                scaled_offsets,
            )
            .and_then(|fit| fit.write(particle));
        if let Err(e) = fit {
            entries.truncate(start);
            return Err(KernelError::evaluation("UMLS", e));
        }
        Ok(ring_range(&self.mesh, located.simplex))
    }

    #[inline(always)]
    fn visit_factored<F>(
        &self,
        x: &SVector<f64, D>,
        cache: &HostCache<D>,
        particle: &[f64],
        entries: &[f64],
        visit: F,
    ) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        let host = cache.host.ok_or_else(|| KernelError::OutsideDomain {
            point: x.iter().copied().collect(),
        })?;
        // No closure around `visit` (an `and_then`): it would keep `visit` from being
        // inlined into the loop, and the caller's sums from staying in registers.
        let fit = UmlsFit::<N>::read(particle).map_err(|e| KernelError::evaluation("UMLS", e))?;
        fit.visit::<D, B>(&self.mesh, host, x, entries, visit)
            .map_err(|e| KernelError::evaluation("UMLS", e))
    }
}

/// Linear (P1) finite-element shape functions on the host simplex: the classic
/// unstructured MPM, whose gradients jump across facets (cell-crossing error).
#[derive(Debug, Clone)]
pub struct LinearFeKernel<const D: usize> {
    mesh: Arc<SimplexMesh<D>>,
}

impl<const D: usize> LinearFeKernel<D> {
    /// P1 shape functions on `mesh`.
    pub fn new(mesh: Arc<SimplexMesh<D>>) -> Self {
        Self { mesh }
    }

    /// The mesh.
    pub fn mesh(&self) -> &Arc<SimplexMesh<D>> {
        &self.mesh
    }
}

impl<const D: usize> Kernel<D> for LinearFeKernel<D> {
    type Cache = HostCache<D>;
    const MAY_BE_TENSOR_PRODUCT: bool = false;
    const MAY_CORRECT_FORCE_GRADIENTS: bool = false;

    mesh_nodes!();

    fn stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut HostCache<D>,
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError> {
        // The location's coordinates are `barycentric(host, x)` itself (every locating
        // path computes them so), so they are not computed again.
        let located = locate_with_coordinates(&self.mesh, x, cache)?;
        let (host, lambda) = (located.simplex as usize, located.barycentric);
        let gradients = self.mesh.barycentric_gradients(host);
        out.clear();
        for ((&v, &l), g) in self
            .mesh
            .simplex(host)
            .iter()
            .zip(lambda.as_slice())
            .zip(gradients.as_slice())
        {
            out.push(v, l, *g, self.mesh.vertex(v as usize) - x);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::SVector;
    use umls_mesh::generate::{Diagonal, Lattice};
    use umls_transfer::{Kernel, Stencil};

    use super::{HostCache, LinearFeKernel, UmlsMeshKernel};

    type Umls2 = UmlsMeshKernel<2, 3>;

    fn mesh() -> Arc<umls_mesh::SimplexMesh<2>> {
        Arc::new(
            Lattice::new([0.0, 0.0], [1.0, 1.0], [8, 8])
                .jitter(0.2, 7)
                .triangles(Diagonal::Alternating)
                .expect("mesh"),
        )
    }

    /// The exit walk keeps the location of the position it was given, in the simplex
    /// and with the coordinates a walk from the old host finds; only that exact
    /// position takes it, once.
    #[test]
    fn the_exit_walk_keeps_the_location_of_exactly_its_position() {
        let kernel = Umls2::new(mesh());
        let (a, b) = (SVector::from([0.31, 0.42]), SVector::from([0.37, 0.47]));
        let mut cache = HostCache::default();
        let mut st = Stencil::new();
        kernel.stencil(&a, &mut cache, &mut st).expect("inside");
        let old = cache.host.expect("located");
        assert!(kernel.domain_exit(&b, &mut cache).is_none());
        let walked = kernel.mesh().locate_from(&b, old).expect("inside");
        let kept = cache.ahead.expect("kept").1;
        assert_eq!(kept, walked.barycentric);
        assert_eq!(cache.host, Some(walked.simplex));
        // Another position (by one ulp) does not take it, and uses it up.
        let mut other = cache;
        let nudged = SVector::from([b[0], b[1] + f64::EPSILON * b[1]]);
        assert!(other.take_ahead(&nudged).is_none());
        assert!(other.ahead.is_none());
        assert_eq!(cache.take_ahead(&b), Some(walked));
        assert!(cache.take_ahead(&b).is_none());
    }

    /// After the exit walk, a stencil at the walked position and one elsewhere are both
    /// those of a fresh cache, for UMLS and linear FE.
    #[test]
    fn stencils_after_the_exit_walk_are_those_of_a_fresh_cache() {
        /// Located at `a`, walked to `b`, then the stencil at `target` against a fresh one.
        fn check<K: Kernel<2, Cache = HostCache<2>>>(
            kernel: &K,
            a: SVector<f64, 2>,
            b: SVector<f64, 2>,
            target: SVector<f64, 2>,
        ) {
            let (mut st, mut fresh) = (Stencil::new(), Stencil::new());
            let mut cache = HostCache::default();
            kernel.stencil(&a, &mut cache, &mut st).expect("inside");
            assert!(kernel.domain_exit(&b, &mut cache).is_none());
            kernel
                .stencil(&target, &mut cache, &mut st)
                .expect("inside");
            kernel
                .stencil(&target, &mut HostCache::default(), &mut fresh)
                .expect("inside");
            assert_eq!(st, fresh);
        }
        let mesh = mesh();
        let umls = Umls2::new(mesh.clone());
        let fe = LinearFeKernel::new(mesh);
        let (a, b, c) = (
            SVector::from([0.31, 0.42]),
            SVector::from([0.37, 0.47]),
            SVector::from([0.52, 0.18]),
        );
        for target in [b, c] {
            check(&umls, a, b, target);
            check(&fe, a, b, target);
        }
    }
}
