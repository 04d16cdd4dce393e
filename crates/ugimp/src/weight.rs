//! The uGIMP weight along one axis: the linear hat of node spacing h averaged over a
//! particle's box of half-width l (Bardenhagen & Kober 2004), and its derivative.

/// S(r) and dS/dr for a particle at distance r = x_p − x_i from the node, with the
/// hat's spacing `h` and the box's half-width `l` (0 < l ≤ h/2):
///
/// - |r| < l: S = 1 − (r² + l²) / (2hl);
/// - l ≤ |r| < h − l: S = 1 − |r| / h;
/// - h − l ≤ |r| < h + l: S = (h + l − |r|)² / (4hl);
/// - otherwise 0.
///
/// S and dS/dr are continuous in r (C¹), so the stencil has no cell-crossing jump.
#[inline(always)]
pub fn weight(r: f64, h: f64, l: f64) -> (f64, f64) {
    let a = r.abs();
    let sign = if r < 0.0 { -1.0 } else { 1.0 };
    if a < l {
        (1.0 - (r * r + l * l) / (2.0 * h * l), -r / (h * l))
    } else if a < h - l {
        (1.0 - a / h, -sign / h)
    } else if a < h + l {
        let t = h + l - a;
        (t * t / (4.0 * h * l), -sign * t / (2.0 * h * l))
    } else {
        (0.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::weight;

    /// The hat averaged over the box by the midpoint rule with n points.
    fn averaged_hat(r: f64, h: f64, l: f64, n: usize) -> f64 {
        (0..n)
            .map(|k| {
                let y = r - l + (k as f64 + 0.5) * 2.0 * l / n as f64;
                (1.0 - y.abs() / h).max(0.0)
            })
            .sum::<f64>()
            / n as f64
    }

    #[test]
    fn the_weight_is_the_hat_averaged_over_the_box() {
        for (h, l) in [(1.0, 0.25), (0.5, 0.25), (2.0, 0.3)] {
            for k in -40..=40 {
                let r = k as f64 * (h + l) / 36.0;
                let exact = averaged_hat(r, h, l, 20_000);
                let (s, _) = weight(r, h, l);
                // The midpoint rule's error on the kinks is O(1/n²) per kink.
                assert!(
                    (s - exact).abs() < 1e-7,
                    "h {h} l {l} r {r}: {s} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn the_derivative_is_the_weight_s_slope_and_continuous() {
        let (h, l) = (1.0, 0.3);
        let eps = 1e-6;
        for k in -52..=52 {
            let r = k as f64 * 0.025 + 0.0123;
            let (_, d) = weight(r, h, l);
            let fd = (weight(r + eps, h, l).0 - weight(r - eps, h, l).0) / (2.0 * eps);
            assert!((d - fd).abs() < 1e-6, "r {r}: {d} vs {fd}");
        }
        // Continuity of S and dS/dr at the breakpoints l, h − l, h + l.
        for b in [l, h - l, h + l] {
            let (below, above) = (weight(b - 1e-12, h, l), weight(b + 1e-12, h, l));
            assert!((below.0 - above.0).abs() < 1e-10, "S jumps at {b}");
            assert!((below.1 - above.1).abs() < 1e-10, "dS jumps at {b}");
        }
    }
}
