//! Radial weight profiles W(r), r = distance / support radius h.

use crate::error::MlsError;

/// A smooth, compactly supported radial weight profile.
///
/// The provided profiles vanish for r ≥ 2 so they are interchangeable with the same
/// support radii.
pub trait WeightFunction: Copy + Send + Sync + 'static {
    /// The profile vanishes for r ≥ `SUPPORT`.
    const SUPPORT: f64;
    /// W(r) and dW/dr for r ≥ 0.
    fn evaluate(&self, r: f64) -> (f64, f64);
}

/// The cubic B-spline N(r) = 2/3 − r² + r³/2 on [0, 1), (2 − r)³/6 on [1, 2): C², as in
/// the UMLS-MPM paper.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CubicBSpline;

impl WeightFunction for CubicBSpline {
    const SUPPORT: f64 = 2.0;

    /// Both pieces are evaluated and one is selected, without branches: which piece a
    /// ring vertex falls in varies from vertex to vertex, so a branch on r was
    /// mispredicted often (the MLS fit's weights were a fifth of a UMLS step). The
    /// selected piece's arithmetic is the same, so are its bits.
    #[inline]
    fn evaluate(&self, r: f64) -> (f64, f64) {
        let inner = (2.0 / 3.0 - r * r + 0.5 * r * r * r, -2.0 * r + 1.5 * r * r);
        let t = 2.0 - r;
        let outer = (t * t * t / 6.0, -0.5 * t * t);
        let near = r < 1.0;
        let inside = r < 2.0;
        let pick = |a: f64, b: f64| {
            let piece = if near { a } else { b };
            if inside { piece } else { 0.0 }
        };
        (pick(inner.0, outer.0), pick(inner.1, outer.1))
    }
}

/// Wendland's C² function ψ(s) = (1 − s)⁴ (4s + 1) with s = r / 2 (support 2, like the
/// cubic B-spline): positive definite, smooth, a common alternative in meshfree methods.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WendlandC2;

impl WeightFunction for WendlandC2 {
    const SUPPORT: f64 = 2.0;

    #[inline]
    fn evaluate(&self, r: f64) -> (f64, f64) {
        let s = 0.5 * r;
        if s < 1.0 {
            let t = 1.0 - s;
            let t3 = t * t * t;
            // dψ/ds = −20 s (1 − s)³, and ds/dr = 1/2.
            (t3 * t * (4.0 * s + 1.0), -10.0 * s * t3)
        } else {
            (0.0, 0.0)
        }
    }
}

/// The cubic B-spline divided by 1 + (r/ε)²: d(r) = B(r) / (1 + (r/ε)²), with the
/// B-spline's support 2 and smoothness (the factor is smooth in r², so d is smooth in x
/// at r = 0 too). The divisor concentrates the weight on the samples nearest the point,
/// the more the smaller ε (with ε = 0.4 it is 7.25 at r = 1, about where a host's
/// farther ring vertices lie), which brings an MLS fit closer to interpolating its
/// nearest samples: what a particle-grid round trip filters shrinks with the stencil's
/// effective width (docs/umls-kernel.md, *Sharpened weights*). ε → ∞ gives back
/// [`CubicBSpline`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharpenedBSpline {
    /// ε, in units of the support radius h_v, > 0.
    pub epsilon: f64,
}

/// The ε of the `umls-sharp` kernel, chosen by the study in docs/umls-kernel.md: the
/// smallest of those measured whose APIC runs gain no energy.
pub const DEFAULT_SHARPENING: f64 = 0.4;

impl SharpenedBSpline {
    /// The profile with `epsilon`.
    ///
    /// # Errors
    /// [`MlsError::InvalidParameter`] unless `epsilon` is finite and positive.
    pub fn new(epsilon: f64) -> Result<Self, MlsError> {
        if epsilon.is_finite() && epsilon > 0.0 {
            return Ok(Self { epsilon });
        }
        Err(MlsError::InvalidParameter {
            parameter: "sharpening epsilon",
            value: epsilon,
            reason: "must be finite and positive",
        })
    }
}

impl WeightFunction for SharpenedBSpline {
    const SUPPORT: f64 = 2.0;

    #[inline]
    fn evaluate(&self, r: f64) -> (f64, f64) {
        let (b, db) = CubicBSpline.evaluate(r);
        let e2 = self.epsilon * self.epsilon;
        let divisor = 1.0 + r * r / e2;
        // d' = B'/q − B · (2r/ε²)/q² with q = 1 + r²/ε².
        (
            b / divisor,
            db / divisor - b * (2.0 * r / e2) / (divisor * divisor),
        )
    }
}

/// A weight profile chosen at run time (a scene file names it): one of the provided
/// profiles, behind one type so a kernel's type does not change with the choice.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum Profile {
    /// [`CubicBSpline`], the paper's.
    #[default]
    CubicBSpline,
    /// [`WendlandC2`].
    WendlandC2,
    /// [`SharpenedBSpline`] with its ε.
    Sharpened(SharpenedBSpline),
}

impl WeightFunction for Profile {
    const SUPPORT: f64 = 2.0;

    #[inline]
    fn evaluate(&self, r: f64) -> (f64, f64) {
        match self {
            Profile::CubicBSpline => CubicBSpline.evaluate(r),
            Profile::WendlandC2 => WendlandC2.evaluate(r),
            Profile::Sharpened(profile) => profile.evaluate(r),
        }
    }
}
