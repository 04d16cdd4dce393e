//! The port between MPM particle-grid transfers and shape-function kernels.
//!
//! A [`Kernel`] owns a set of grid nodes (mesh vertices or Cartesian grid nodes) and, for
//! a particle position, fills a [`Stencil`]: node indices, shape function values N_i and
//! gradients ∇N_i. Each particle keeps a small [`Kernel::Cache`] (its host simplex or
//! cell) so that relocating a particle that moved a little costs O(1). Transfers (P2G,
//! G2P) and the engine see only this trait, so swapping UMLS for linear FE or B-splines
//! changes one type. A kernel whose stencils are tensor products of per-axis factors
//! (B-splines) may also hand those over ([`Kernel::tensor_stencil`], a
//! [`TensorStencil`]), so that transfers can sum a stencil row by row.
//!
//! ```
//! use nalgebra::SVector;
//! use umls_transfer::{Kernel, KernelError, Stencil};
//!
//! /// Linear hat functions on the unit interval with two nodes: the smallest kernel.
//! struct Hat;
//! impl Kernel<1> for Hat {
//!     type Cache = ();
//!     fn node_count(&self) -> usize { 2 }
//!     fn node_position(&self, node: usize) -> SVector<f64, 1> { SVector::from([node as f64]) }
//!     fn spacing(&self) -> f64 { 1.0 }
//!     fn stencil(&self, x: &SVector<f64, 1>, _: &mut (), out: &mut Stencil<1>) -> Result<(), KernelError> {
//!         if !(0.0..=1.0).contains(&x[0]) { return Err(KernelError::OutsideDomain { point: vec![x[0]] }); }
//!         out.clear();
//!         out.push(0, 1.0 - x[0], SVector::from([-1.0]), SVector::from([-x[0]]));
//!         out.push(1, x[0], SVector::from([1.0]), SVector::from([1.0 - x[0]]));
//!         Ok(())
//!     }
//! }
//! let mut st = Stencil::new();
//! Hat.stencil(&SVector::from([0.25]), &mut (), &mut st)?;
//! assert_eq!(st.values(), &[0.75, 0.25]);
//! # Ok::<(), KernelError>(())
//! ```

mod second_moment;
mod stencil;
mod tensor;

use std::sync::Arc;

use nalgebra::SVector;
use thiserror::Error;

pub use second_moment::regular_inverse;
pub use stencil::{EntriesMut, Stencil, node_range};
pub use tensor::TensorStencil;

/// Why a kernel could not produce a stencil.
#[derive(Debug, Clone, Error)]
pub enum KernelError {
    /// The point lies outside the kernel's domain (mesh or grid).
    #[error("point {point:?} is outside the kernel's domain")]
    OutsideDomain {
        /// Coordinates of the point.
        point: Vec<f64>,
    },
    /// The engine asked for a kernel's factored stencil ([`Kernel::factor_stencil`])
    /// although the kernel has no [`Kernel::factor_layout`].
    #[error("{kernel} kernel has no factored stencils")]
    NotFactored {
        /// The kernel's name (its type).
        kernel: &'static str,
    },
    /// The engine asked for a kernel's stencil as per-axis factors of a width
    /// ([`Kernel::tensor_stencil`]) other than its [`Kernel::tensor_width`].
    #[error("{kernel} kernel has no tensor-product stencils {width} nodes wide")]
    NotTensorProduct {
        /// The kernel's name (its type).
        kernel: &'static str,
        /// The width asked for.
        width: usize,
    },
    /// The kernel's own evaluation failed (an MLS moment matrix that is ill-conditioned,
    /// …): the kernel names itself, and the cause is its own error type, which
    /// `std::error::Error::source` and `downcast_ref` reach.
    #[error("{kernel} kernel: {source}")]
    Evaluation {
        /// The kernel's name.
        kernel: &'static str,
        /// The kernel's error.
        source: Arc<dyn std::error::Error + Send + Sync>,
    },
}

impl KernelError {
    /// A kernel's own error, as [`KernelError::Evaluation`].
    pub fn evaluation(
        kernel: &'static str,
        error: impl std::error::Error + Send + Sync + 'static,
    ) -> Self {
        Self::Evaluation {
            kernel,
            source: Arc::new(error),
        }
    }
}

/// Equal when the variant, the point or the kernel name, and the cause's message match
/// (the cause is a trait object, compared by what it says).
impl PartialEq for KernelError {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Self::OutsideDomain { point: a }, Self::OutsideDomain { point: b }) => a == b,
            (Self::NotFactored { kernel: a }, Self::NotFactored { kernel: b }) => a == b,
            (
                Self::NotTensorProduct {
                    kernel: a,
                    width: w,
                },
                Self::NotTensorProduct {
                    kernel: b,
                    width: v,
                },
            ) => a == b && w == v,
            (
                Self::Evaluation {
                    kernel: a,
                    source: e,
                },
                Self::Evaluation {
                    kernel: b,
                    source: f,
                },
            ) => a == b && e.to_string() == f.to_string(),
            _ => false,
        }
    }
}

/// Where a point left a kernel's domain: the boundary facet it crossed (its nodes), the
/// facet's outward unit normal, and the nearest point of the last host cell on that side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomainExit<const D: usize> {
    /// The facet's nodes (the first `facet_len` entries are used).
    pub facet: [u32; 3],
    /// How many of `facet` are used (D for a simplex facet).
    pub facet_len: usize,
    /// Outward unit normal of the facet.
    pub normal: SVector<f64, D>,
    /// A point of the domain next to where the point left it (on the crossed facet).
    pub inside: SVector<f64, D>,
}

impl<const D: usize> DomainExit<D> {
    /// The crossed facet's nodes.
    pub fn facet(&self) -> &[u32] {
        &self.facet[..self.facet_len]
    }
}

/// How many numbers a kernel's factored stencil takes ([`Kernel::factor_layout`]): a
/// fixed block per particle and one number per stencil entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FactorLayout {
    /// `f64`s per particle (an MLS fit's inverse moment matrix and scale).
    pub per_particle: usize,
    /// `f64`s per stencil entry (an MLS fit's weight), 0 or 1.
    pub per_entry: usize,
}

/// A shape-function kernel over a fixed set of nodes.
pub trait Kernel<const D: usize>: Send + Sync {
    /// Per-particle location cache (host simplex, grid cell, or `()`).
    type Cache: Copy + Default + Send + Sync + std::fmt::Debug;

    /// Whether [`Self::tensor_width`] can be `Some` for a kernel of this type. `false`
    /// lets the engine leave out the row-by-row transfers it would never take (a smaller
    /// program, not a faster one); the default `true` is always correct.
    const MAY_BE_TENSOR_PRODUCT: bool = true;

    /// Whether [`Self::force_gradient_correction`] can be `Some` for a kernel of this
    /// type; `false` lets the engine leave out the corrected P2G. Default `true`.
    const MAY_CORRECT_FORCE_GRADIENTS: bool = true;

    /// Number of nodes.
    fn node_count(&self) -> usize;

    /// Position of node `node`.
    fn node_position(&self, node: usize) -> SVector<f64, D>;

    /// The effective node spacing h of the explicit stability limit: the stable time step
    /// of every kernel is Δt = C · h / (c + |v|_max) with the p-wave speed c (the
    /// grid spacing for grid kernels, the shortest simplex height for mesh kernels).
    fn spacing(&self) -> f64;

    /// Fills `out` with the stencil at `x`, using and updating `cache`. The same `x` and
    /// cache must give the same stencil, bit for bit: the engine may evaluate a stencil
    /// more than once in a step (see [`Self::recompute_stencils`]).
    fn stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut Self::Cache,
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError>;

    /// Appends the stencil at `x` to `nodes`, `values` and `gradients`, with the entries,
    /// order and bits of [`Self::stencil`], and without its offsets (an engine that stores
    /// stencils recovers them as [`Self::node_position`] − x). On failure the three
    /// vectors are left as they were. The default evaluates [`Self::stencil`] into
    /// `scratch` and copies it; a kernel that can write its entries in place (an MLS fit
    /// of known length) overrides it to save the copy and the offsets.
    #[inline]
    fn append_stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut Self::Cache,
        scratch: &mut Stencil<D>,
        nodes: &mut Vec<u32>,
        values: &mut Vec<f64>,
        gradients: &mut Vec<SVector<f64, D>>,
    ) -> Result<(), KernelError> {
        self.stencil(x, cache, scratch)?;
        nodes.extend_from_slice(scratch.nodes());
        values.extend_from_slice(scratch.values());
        gradients.extend_from_slice(scratch.gradients());
        Ok(())
    }

    /// Calls `visit(node, N, ∇N, x_node − x)` for every entry of the stencil at `x`, in
    /// the order and with the values [`Self::stencil`] gives, bit for bit, and fails
    /// where it fails. The default evaluates [`Self::stencil`] into `scratch` and walks
    /// it; a kernel with a closed form (a B-spline grid) overrides it to hand each entry
    /// over as it computes it, so that the transfers neither write nor read back the
    /// stencil's arrays (a quarter of a 3D B-spline step).
    fn visit_stencil<F>(
        &self,
        x: &SVector<f64, D>,
        cache: &mut Self::Cache,
        scratch: &mut Stencil<D>,
        mut visit: F,
    ) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        self.stencil(x, cache, scratch)?;
        let offsets = scratch.offsets();
        for (e, (node, value, gradient)) in scratch.iter().enumerate() {
            visit(node, value, gradient, &offsets[e]);
        }
        Ok(())
    }

    /// `Some(W)` if every stencil of the kernel is the tensor product of `W` nodes per
    /// axis that [`Self::tensor_stencil`] gives as per-axis factors (a B-spline grid), so
    /// that transfers may sum it row by row; `None` (the default) otherwise.
    fn tensor_width(&self) -> Option<usize> {
        None
    }

    /// The nodes per axis where the kernel numbers its nodes on a lattice, axis 0 fastest
    /// (node (i₀, i₁, …) is i₀ + n₀ (i₁ + n₁ (…)), and its [`Self::tensor_stencil`]s give
    /// the same numbering through `corner` and `strides`; `None` (the default) otherwise.
    /// With it, the engine's P2G sums each block of particles into a box of the lattice
    /// instead of a range of node indices, which in 3D spans whole planes of the grid.
    fn node_lattice(&self) -> Option<[usize; D]> {
        None
    }

    /// The stencil at `x` as per-axis factors, for a kernel whose [`Self::tensor_width`]
    /// is `Some(W)`: the entries of [`Self::stencil`] (N and ∇N as the factors' products
    /// in axis order give them), failing where it fails. The default, like a kernel asked
    /// for another width, fails with [`KernelError::NotTensorProduct`].
    fn tensor_stencil<const W: usize>(
        &self,
        x: &SVector<f64, D>,
    ) -> Result<TensorStencil<D, W>, KernelError> {
        let _ = x;
        Err(KernelError::NotTensorProduct {
            kernel: std::any::type_name::<Self>(),
            width: W,
        })
    }

    /// The smallest and largest node index of the stencil at `x` (the engine orders
    /// particles by them), updating `cache` as [`Self::stencil`] does and failing where
    /// it cannot locate `x`. The default evaluates the stencil into `scratch`, so it
    /// fails exactly where [`Self::stencil`] fails; a kernel that knows the range without
    /// the values (a grid: the corners of the node block; a mesh kernel: the host's
    /// nodes) overrides it, and may leave a failure of the evaluation itself to the
    /// evaluation (with recomputed stencils the engine then reports it from P2G, naming
    /// the particle whose stencil failed; where several fail, P2G's order decides which
    /// is named, still the same on any number of threads).
    fn node_range(
        &self,
        x: &SVector<f64, D>,
        cache: &mut Self::Cache,
        scratch: &mut Stencil<D>,
    ) -> Result<(u32, u32), KernelError> {
        self.stencil(x, cache, scratch)?;
        Ok(scratch.node_range().unwrap_or((0, 0)))
    }

    /// Whether a stencil costs less to evaluate where it is used (P2G and G2P, so twice a
    /// step besides [`Self::node_range`]) than to store for the step and read back: true
    /// for cheap closed forms (B-splines), whose stored stencils would be most of a
    /// particle's memory traffic. The engine follows it unless a setting overrides it. Default:
    /// false (store).
    fn recompute_stencils(&self) -> bool {
        false
    }

    /// Whether the kernel can keep a stencil as factors from which its entries are
    /// rebuilt cheaply ([`Self::factor_stencil`], [`Self::visit_factored`]), and their
    /// layout: for an MLS kernel the inverse moment matrix and the weights, a third of
    /// the entries' bytes, where the fit itself (weights, moment sums, inverse) is most
    /// of the cost. An engine may store factors instead of entries to save memory, at the
    /// price of rebuilding each entry where it is used. Default: `None`.
    fn factor_layout(&self) -> Option<FactorLayout> {
        None
    }

    /// Locates `x` (updating `cache`), writes the stencil's per-particle factors into
    /// `particle` (length [`FactorLayout::per_particle`]) and appends its per-entry
    /// factors to `entries`; returns the stencil's smallest and largest node. Fails
    /// exactly where [`Self::stencil`] fails. `scratch` is the kernel's to use. The
    /// default, for kernels without a [`Self::factor_layout`], fails with
    /// [`KernelError::NotFactored`].
    fn factor_stencil(
        &self,
        x: &SVector<f64, D>,
        cache: &mut Self::Cache,
        scratch: &mut Stencil<D>,
        particle: &mut [f64],
        entries: &mut Vec<f64>,
    ) -> Result<(u32, u32), KernelError> {
        let _ = (x, cache, scratch, particle, entries);
        Err(KernelError::NotFactored {
            kernel: std::any::type_name::<Self>(),
        })
    }

    /// Calls `visit(node, N, ∇N, x_node − x)` for every entry of the stencil that
    /// [`Self::factor_stencil`] factored at `x` with `cache` into `particle` and
    /// `entries`: the entries of [`Self::stencil`] at `x`, in its order and bit for bit.
    /// The default fails with [`KernelError::NotFactored`].
    fn visit_factored<F>(
        &self,
        x: &SVector<f64, D>,
        cache: &Self::Cache,
        particle: &[f64],
        entries: &[f64],
        visit: F,
    ) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        let _ = (x, cache, particle, entries, visit);
        Err(KernelError::NotFactored {
            kernel: std::any::type_name::<Self>(),
        })
    }

    /// The second moment Σ_i N_i(x) (x_i − x)(x_i − x)ᵀ where it is the same multiple
    /// s·I of the identity at every x (s = h²/4 for quadratic, h²/3 for cubic B-splines),
    /// so transfers can use it instead of summing it per particle; `None` (the default)
    /// where it varies with x, as for every mesh kernel.
    fn constant_second_moment(&self) -> Option<f64> {
        None
    }

    /// Whether the second moment D_p = Σ_i N_i(x) (x_i − x)(x_i − x)ᵀ stays positive
    /// definite and of the order of h² wherever the stencil's nodes surround the point,
    /// so that D_p⁻¹ N_i (x_i − x_p) is a usable gradient (MLS-MPM's). True where D_p is
    /// constant (B-splines, the default) and for MLS fits, whose stencils reach past
    /// the host cell; false for linear elements, whose D_p vanishes at every vertex. At
    /// the domain's boundary an MLS fit is one-sided and its D_p can be indefinite (at a
    /// corner of the mesh), so the engine checks each particle's D_p where it inverts it.
    fn regular_second_moment(&self) -> bool {
        self.constant_second_moment().is_some()
    }

    /// Whether N_i(x) ≥ 0 for every node and x, as for B-splines (not for MLS fits,
    /// whose values can be negative, nor for linear elements, whose barycentric
    /// coordinates round-off can make slightly negative at a facet). Then the engine
    /// takes Σ_p |N_ip| m_p to be the nodal mass, bit for bit, instead of summing it
    /// apart. Default `false`, which is always safe.
    fn nonnegative_values(&self) -> bool {
        false
    }

    /// Per-node vectors ξ_i with which the internal force's shape-function gradients
    /// become ∇N_i + N_i (ξ_i − ξ̄_p), ξ̄_p = Σ_j N_j(x_p) ξ_j (an integration correction
    /// the kernel computed over its domain, for a gradient that is not the derivative of
    /// N_i, such as an MLS fit's reconstructed gradient; subtracting ξ̄_p keeps the
    /// corrections summing to zero over a stencil, so momentum is conserved), indexed by
    /// node; `None` (the default) for none. The velocity gradient keeps ∇N_i, which
    /// reproduces affine fields.
    fn force_gradient_correction(&self) -> Option<&[SVector<f64, D>]> {
        None
    }

    /// If `x` lies outside the domain, where it left it, seen from the location in
    /// `cache` (`None` inside, or where the kernel cannot tell). Mesh kernels use it to
    /// hold particles at walls given as boundary node sets. The engine calls it with a
    /// particle's new position at the end of G2P, so a kernel may leave in `cache` what
    /// it found there for the next [`Self::stencil`] of that position (the mesh kernels
    /// keep the host and barycentric coordinates their walk computed), provided that
    /// stencil comes out the same. Default: `None`.
    fn domain_exit(&self, x: &SVector<f64, D>, cache: &mut Self::Cache) -> Option<DomainExit<D>> {
        let _ = (x, cache);
        None
    }
}
