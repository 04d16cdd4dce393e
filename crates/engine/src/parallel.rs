//! Reductions of parallel per-particle passes whose outcome does not depend on the
//! thread count.

/// Joins two partial results of a parallel pass: values with `join`, and among failures
/// the one with the lowest particle index, so the same failure is reported whatever the
/// thread count.
pub(crate) fn lowest_failure<T, E>(
    a: Result<T, (usize, E)>,
    b: Result<T, (usize, E)>,
    join: impl FnOnce(T, T) -> T,
) -> Result<T, (usize, E)> {
    match (a, b) {
        (Ok(x), Ok(y)) => Ok(join(x, y)),
        (Err(e), Ok(_)) | (Ok(_), Err(e)) => Err(e),
        (Err(e1), Err(e2)) => Err(if e1.0 <= e2.0 { e1 } else { e2 }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lowest_index_wins_in_either_order() {
        let (low, high): (Result<f64, _>, Result<f64, _>) = (Err((3, "low")), Err((7, "high")));
        assert_eq!(lowest_failure(low, high, f64::min), Err((3, "low")));
        assert_eq!(
            lowest_failure(Err((7, "high")), Err((3, "low")), f64::min),
            Err((3, "low"))
        );
        assert_eq!(
            lowest_failure(Ok(2.0), Err((9, "e")), f64::min),
            Err((9, "e"))
        );
        assert_eq!(
            lowest_failure::<f64, &str>(Ok(2.0), Ok(1.0), f64::min),
            Ok(1.0)
        );
    }
}
