//! Numbers derived from the runs: convergence orders and the speed–accuracy Pareto front.

/// The least-squares slope of log(error) against log(h): the observed order of
/// convergence. `None` with fewer than two usable points (positive and finite).
pub fn fitted_order(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(h, e)| h.is_finite() && e.is_finite() && *h > 0.0 && *e > 0.0)
        .map(|(h, e)| (h.ln(), e.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (sxy, sxx) = logs.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Indices of the points on the Pareto front of (cost, error), both minimised: no other
/// point is at least as cheap and at least as accurate and better in one of them.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let usable = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    (0..points.len())
        .filter(|&i| usable(&points[i]))
        .filter(|&i| {
            let (c, e) = points[i];
            !points.iter().enumerate().any(|(j, &(cj, ej))| {
                j != i && usable(&points[j]) && cj <= c && ej <= e && (cj < c || ej < e)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_of_a_power_law_is_its_exponent() {
        let points: Vec<(f64, f64)> = [0.1, 0.05, 0.025]
            .iter()
            .map(|&h: &f64| (h, 3.0 * h.powf(1.7)))
            .collect();
        assert!((fitted_order(&points).unwrap() - 1.7).abs() < 1e-12);
        assert_eq!(fitted_order(&points[..1]), None);
        assert_eq!(fitted_order(&[(0.1, 1.0), (0.1, f64::NAN)]), None);
    }

    #[test]
    fn the_front_keeps_only_undominated_points() {
        let points = [
            (1.0, 5.0),
            (2.0, 2.0),
            (3.0, 3.0),
            (4.0, 1.0),
            (f64::NAN, 0.1),
        ];
        assert_eq!(pareto_front(&points), vec![0, 1, 3]);
    }
}
