//! Fits f = sin 2x + yz on Fibonacci samples of the unit sphere and prints the error
//! table: max error at 97 query points for m = 0…3 and N = 500 … 32000, with observed
//! orders against the spacing h ∝ N^(−1/2).
//!
//! `cargo run --release -p umls-manifold --example sphere_error_table`

use umls_manifold::{ManifoldError, ManifoldMls, PointCloud, Settings};

// The sampling and test function of the crate's convergence test.
#[path = "../tests/common/mod.rs"]
mod common;

use common::{fibonacci_sphere, sphere_function as f};

fn main() -> Result<(), ManifoldError> {
    let levels = [500usize, 2000, 8000, 32000];
    let queries: Vec<[f64; 3]> = fibonacci_sphere(97)
        .into_iter()
        .map(|q| [q[0] * 0.8 - q[1] * 0.6, q[0] * 0.6 + q[1] * 0.8, q[2]])
        .collect();
    println!("max |f̃ − f| on S², f = sin 2x + yz");
    print!("{:>8}", "N");
    for m in 0..=3 {
        print!("  {:>10} {:>5}", format!("m = {m}"), "order");
    }
    println!();
    let mut previous = [f64::NAN; 4];
    for &count in &levels {
        let samples = fibonacci_sphere(count);
        let values: Vec<f64> = samples.iter().map(|p| f(p)).collect();
        let coords: Vec<f64> = samples.iter().flatten().copied().collect();
        print!("{count:>8}");
        for (m, prev) in previous.iter_mut().enumerate() {
            let mls = ManifoldMls::new(
                PointCloud::new(3, coords.clone(), 1, values.clone())?,
                Settings::new(2, m),
            )?;
            let mut error: f64 = 0.0;
            for (estimate, q) in mls.evaluate_batch(&queries).into_iter().zip(&queries) {
                error = error.max((estimate?.value[0] - f(q)).abs());
            }
            // h ∝ N^(−1/2) and N grows 4× per level: order = log₂(e_prev / e).
            let order = (*prev / error).log2();
            if order.is_nan() {
                print!("  {error:>10.3e} {:>5}", "")
            } else {
                print!("  {error:>10.3e} {order:>5.2}")
            }
            *prev = error;
        }
        println!();
    }
    Ok(())
}
