//! Radial weight profiles W(r), r = distance / support radius h.

/// A smooth, compactly supported radial weight profile.
///
/// Both provided profiles vanish for r ≥ 2 so they are interchangeable with the same
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

/// A weight profile chosen at run time (a scene file names it): either of the two
/// provided profiles, behind one type so a kernel's type does not change with the choice.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Profile {
    /// [`CubicBSpline`], the paper's.
    #[default]
    CubicBSpline,
    /// [`WendlandC2`].
    WendlandC2,
}

impl WeightFunction for Profile {
    const SUPPORT: f64 = 2.0;

    #[inline]
    fn evaluate(&self, r: f64) -> (f64, f64) {
        match self {
            Profile::CubicBSpline => CubicBSpline.evaluate(r),
            Profile::WendlandC2 => WendlandC2.evaluate(r),
        }
    }
}
