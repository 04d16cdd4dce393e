//! The uGIMP kernel (the generalized interpolation material point method with fixed
//! particle boxes, Bardenhagen & Kober 2004) on a Cartesian grid, in 1D, 2D and 3D.
//!
//! Each particle is a box of half-width l per axis; the weight of node i is the linear
//! hat N_i averaged over the box, S_ip = (1/V_p) ∫_box N_i dx, a tensor product of
//! one-dimensional averages ([`weight`]). S and its gradient are continuous, so a
//! particle crossing a cell face carries no jump in its force: the grid's own remedy for
//! the cell-crossing error, as in CB-Geo, Uintah and Karamelo. With l ≤ h/2 the stencil
//! is three nodes per axis; S reproduces constant and linear fields exactly.
//!
//! The kernel depends only on the port (`umls-transfer`), not on the kernels of
//! `umls-kernels`: a kernel from outside enters the comparisons through the same door.
//! uGIMP keeps l fixed (it does not follow the deformation of the particle's box, as
//! cpGIMP and CPDI do), so boxes can gap in extension.
//!
//! ```
//! use nalgebra::SVector;
//! use umls_transfer::{Kernel, Stencil};
//! use umls_ugimp::UgimpKernel;
//!
//! // A 1 × 1 box, cells of 0.1, particles 0.05 apart (l = 0.025).
//! let grid = UgimpKernel::covering(SVector::from([0.0, 0.0]), SVector::from([1.0, 1.0]), 0.1, 0.025)?;
//! let mut stencil = Stencil::new();
//! let x = SVector::from([0.437, 0.61]);
//! grid.stencil(&x, &mut (), &mut stencil)?;
//! let sum: f64 = stencil.values().iter().sum();
//! assert!((sum - 1.0).abs() < 1e-14);
//! let reproduced: SVector<f64, 2> = stencil.iter().map(|(n, v, _)| grid.node_position(n as usize) * v).sum();
//! assert!((reproduced - x).norm() < 1e-14);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod weight;

use nalgebra::SVector;
use thiserror::Error;
use umls_transfer::{Kernel, KernelError, Stencil, TensorStencil};

pub use weight::weight;

/// Why a uGIMP grid could not be built; each names the parameter.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum UgimpError {
    /// The node spacing is not finite and positive.
    #[error("grid spacing h = {0} must be finite and positive")]
    Spacing(f64),
    /// The box half-width is not in (0, h/2]: beyond h/2 a particle reaches four nodes
    /// per axis, which this kernel's three-node stencil does not hold.
    #[error("particle half-width l = {half_width} must be in (0, h/2] (h = {h})")]
    HalfWidth {
        /// The half-width given.
        half_width: f64,
        /// The grid spacing.
        h: f64,
    },
    /// The box corners are not finite.
    #[error("the box to cover has a non-finite corner")]
    Box,
    /// Too few cells for one stencil, or more nodes than u32 indices address.
    #[error("{cells:?} cells: at least 2 per axis and at most 2^32 nodes")]
    Cells {
        /// Cells per axis.
        cells: Vec<usize>,
    },
}

/// Nodes per axis of a stencil.
const WIDTH: usize = 3;

/// The uGIMP kernel on a grid of `cells` cells of size h from `origin`, for particle
/// boxes of half-width l.
#[derive(Debug, Clone, PartialEq)]
pub struct UgimpKernel<const D: usize> {
    origin: SVector<f64, D>,
    h: f64,
    half_width: f64,
    cells: [usize; D],
}

impl<const D: usize> UgimpKernel<D> {
    /// Cells added on each side of the box by [`Self::covering`]: a particle on the
    /// box's boundary keeps its stencil, and walls there get their node layers.
    pub const COVER_MARGIN: usize = 2;

    /// The grid of `cells` cells of size `h` from `origin`, for boxes of half-width
    /// `half_width`.
    pub fn new(
        origin: SVector<f64, D>,
        h: f64,
        cells: [usize; D],
        half_width: f64,
    ) -> Result<Self, UgimpError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(UgimpError::Spacing(h));
        }
        // A relative tolerance: one particle per cell gives l = h/2 up to round-off.
        if !(half_width > 0.0 && half_width <= 0.5 * h * (1.0 + 1e-12)) {
            return Err(UgimpError::HalfWidth { half_width, h });
        }
        if origin.iter().any(|x| !x.is_finite()) {
            return Err(UgimpError::Box);
        }
        let nodes = cells
            .iter()
            .try_fold(1usize, |count, &n| count.checked_mul(n.checked_add(1)?));
        let addressable = nodes.is_some_and(|count| count - 1 <= u32::MAX as usize);
        if !addressable || cells.iter().any(|&n| n + 1 < WIDTH) {
            return Err(UgimpError::Cells {
                cells: cells.to_vec(),
            });
        }
        Ok(Self {
            origin,
            h,
            half_width: half_width.min(0.5 * h),
            cells,
        })
    }

    /// The grid of spacing `h` covering [lower, upper] with [`Self::COVER_MARGIN`] cells
    /// more on every side.
    pub fn covering(
        lower: SVector<f64, D>,
        upper: SVector<f64, D>,
        h: f64,
        half_width: f64,
    ) -> Result<Self, UgimpError> {
        if lower.iter().chain(upper.iter()).any(|x| !x.is_finite()) {
            return Err(UgimpError::Box);
        }
        if !(h.is_finite() && h > 0.0) {
            return Err(UgimpError::Spacing(h));
        }
        let margin = Self::COVER_MARGIN;
        // `as usize` saturates: an absurd ratio gives a count `new` refuses.
        let cells: [usize; D] = std::array::from_fn(|k| {
            (((upper[k] - lower[k]) / h - 1e-9).ceil().max(1.0) as usize).saturating_add(2 * margin)
        });
        Self::new(lower.add_scalar(-(margin as f64) * h), h, cells, half_width)
    }

    /// Cells per axis.
    pub fn cells(&self) -> [usize; D] {
        self.cells
    }

    /// The particles' box half-width l.
    pub fn half_width(&self) -> f64 {
        self.half_width
    }

    /// The stencil's lowest node per axis (the node nearest x, less one), or the error
    /// where the stencil leaves the grid.
    fn base_nodes(&self, x: &SVector<f64, D>) -> Result<[usize; D], KernelError> {
        let mut base = [0usize; D];
        for k in 0..D {
            let nearest = ((x[k] - self.origin[k]) / self.h).round();
            // NaN fails both comparisons.
            if !(nearest >= 1.0 && nearest + 1.0 <= self.cells[k] as f64) {
                return Err(KernelError::OutsideDomain {
                    point: x.iter().copied().collect(),
                });
            }
            base[k] = nearest as usize - 1;
        }
        Ok(base)
    }

    fn strides(&self) -> [usize; D] {
        let mut strides = [1usize; D];
        for k in 1..D {
            strides[k] = strides[k - 1] * (self.cells[k - 1] + 1);
        }
        strides
    }

    /// The stencil at `x` as per-axis factors; offsets are computed as
    /// `node_position(i) − x` is, so both agree bit for bit.
    fn tensor(&self, x: &SVector<f64, D>) -> Result<TensorStencil<D, WIDTH>, KernelError> {
        let base = self.base_nodes(x)?;
        let strides = self.strides();
        let mut tensor = TensorStencil {
            first: (0..D).map(|k| base[k] * strides[k]).sum(),
            corner: base,
            strides,
            values: [[0.0; WIDTH]; D],
            derivatives: [[0.0; WIDTH]; D],
            offsets: [[0.0; WIDTH]; D],
        };
        for k in 0..D {
            for a in 0..WIDTH {
                let node = self.origin[k] + self.h * (base[k] + a) as f64;
                let (value, derivative) = weight(x[k] - node, self.h, self.half_width);
                tensor.values[k][a] = value;
                tensor.derivatives[k][a] = derivative;
                tensor.offsets[k][a] = node - x[k];
            }
        }
        Ok(tensor)
    }
}

impl<const D: usize> Kernel<D> for UgimpKernel<D> {
    type Cache = ();
    const MAY_CORRECT_FORCE_GRADIENTS: bool = false;

    fn node_count(&self) -> usize {
        self.cells.iter().map(|n| n + 1).product()
    }

    fn node_position(&self, node: usize) -> SVector<f64, D> {
        let mut rest = node;
        SVector::<f64, D>::from_fn(|k, _| {
            let i = rest % (self.cells[k] + 1);
            rest /= self.cells[k] + 1;
            self.origin[k] + self.h * i as f64
        })
    }

    fn spacing(&self) -> f64 {
        self.h
    }

    /// Per axis, Σ_i S_i (x_i − x)² is the box average of the hat's second moment plus
    /// the box's own variance l²/3 (the hats reproduce linear fields), so D_p is
    /// diagonal (the first moments vanish) with entries ≥ l²/3: regular everywhere.
    fn regular_second_moment(&self) -> bool {
        true
    }

    fn nonnegative_values(&self) -> bool {
        true
    }

    fn recompute_stencils(&self) -> bool {
        // 3^D products of per-axis weights, as for quadratic B-splines.
        true
    }

    fn tensor_width(&self) -> Option<usize> {
        Some(WIDTH)
    }

    fn node_lattice(&self) -> Option<[usize; D]> {
        Some(std::array::from_fn(|k| self.cells[k] + 1))
    }

    fn tensor_stencil<const W: usize>(
        &self,
        x: &SVector<f64, D>,
    ) -> Result<TensorStencil<D, W>, KernelError> {
        if W != WIDTH {
            return Err(KernelError::NotTensorProduct {
                kernel: std::any::type_name::<Self>(),
                width: W,
            });
        }
        // W is WIDTH here; the copy through arrays of W is how a const generic of the
        // caller's meets the kernel's own.
        let tensor = self.tensor(x)?;
        let resize =
            |t: &[[f64; WIDTH]; D]| std::array::from_fn(|k| std::array::from_fn(|a| t[k][a]));
        Ok(TensorStencil {
            first: tensor.first,
            corner: tensor.corner,
            strides: tensor.strides,
            values: resize(&tensor.values),
            derivatives: resize(&tensor.derivatives),
            offsets: resize(&tensor.offsets),
        })
    }

    fn node_range(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        _: &mut Stencil<D>,
    ) -> Result<(u32, u32), KernelError> {
        let base = self.base_nodes(x)?;
        let strides = self.strides();
        let first: usize = (0..D).map(|k| base[k] * strides[k]).sum();
        let last: usize = (0..D).map(|k| (base[k] + WIDTH - 1) * strides[k]).sum();
        Ok((first as u32, last as u32))
    }

    fn stencil(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError> {
        let tensor = self.tensor(x)?;
        out.clear();
        tensor.for_each_entry(|node, value, gradient, offset| {
            out.push(node, value, *gradient, *offset);
        });
        Ok(())
    }

    fn visit_stencil<F>(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        _: &mut Stencil<D>,
        visit: F,
    ) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        self.tensor(x)?.for_each_entry(visit);
        Ok(())
    }
}
