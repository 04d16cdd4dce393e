//! The leading principal directions of a large point cloud by a randomised range finder
//! with faer: O(N·n·p) instead of the O(n³) of a full covariance eigen-decomposition.

use faer::Mat;

/// Mean and up to `p` orthonormal principal directions (each of length n), largest first.
///
/// Halko–Martinsson–Tropp: Y = X Ω with a deterministic pseudo-random Ω (p + 6 columns),
/// two power iterations with re-orthonormalisation, then the SVD of the small Qᵀ X.
pub(crate) fn principal_directions(
    points: &[f64],
    ambient: usize,
    p: usize,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let samples = points.len() / ambient;
    let mut mean = vec![0.0; ambient];
    for row in points.chunks_exact(ambient) {
        for (m, x) in mean.iter_mut().zip(row) {
            *m += x;
        }
    }
    mean.iter_mut().for_each(|m| *m /= samples as f64);
    let x = Mat::<f64>::from_fn(samples, ambient, |i, j| points[i * ambient + j] - mean[j]);
    let width = (p + 6).min(ambient).min(samples);
    let mut state = 0x5DEE_CE66_D1CE_4E5Bu64;
    let omega = Mat::<f64>::from_fn(ambient, width, |_, _| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    });
    let mut q = (&x * &omega).qr().compute_thin_Q();
    for _ in 0..2 {
        let z = (x.transpose() * &q).qr().compute_thin_Q();
        q = (&x * &z).qr().compute_thin_Q();
    }
    let b = q.transpose() * &x;
    let directions = match b.thin_svd() {
        Ok(svd) => {
            let v = svd.V();
            (0..p.min(v.ncols()))
                .map(|k| (0..ambient).map(|j| v[(j, k)]).collect())
                .collect()
        }
        // The SVD of a small dense matrix only fails on non-finite input, which the point
        // cloud rejects; fall back to coordinate axes rather than panic.
        Err(_) => (0..p.min(ambient))
            .map(|k| (0..ambient).map(|j| f64::from(u8::from(j == k))).collect())
            .collect(),
    };
    (mean, directions)
}
