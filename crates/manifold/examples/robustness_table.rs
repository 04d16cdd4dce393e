//! The robustness tables of docs/manifold-mls.md:
//! - `noise`: S² with Gaussian noise s on positions and values, N ∈ {4k, 16k, 64k},
//!   s ∈ {0.01 … 0.05}, m = 1…3, 400 queries: failures, max error, mean chart
//!   iterations, time per query, largest condition number and widening;
//! - `torus`: the flat torus in R⁶ sampled 11× coarser in v (grid `TORUS=ku,kv`, default
//!   440,40), bandwidth factors 3–30, 200 queries: failures (the first one's reason),
//!   max error, errors > 0.1; `WIDENING=4,16` compares limits of the widening;
//! - `offset`: projection of queries 0.05 off S², N = 8k/32k/128k, with observed orders.
//!
//! `cargo run --release -p umls-manifold --example robustness_table [noise|torus|offset]`
use std::time::Instant;

use umls_manifold::{Bandwidth, ManifoldMls, PointCloud, Settings};

// The samplings and test functions of the crate's tests, so the tables and the tests
// measure the same cases.
#[path = "../tests/common/mod.rs"]
mod common;

use common::{Torus, fibonacci_sphere as fib, noisy_sphere, sphere_function as f};

fn main() {
    let arg = std::env::args().nth(1).unwrap_or_default();
    println!(
        "{}",
        std::env::args()
            .nth(1)
            .map_or("all tables".into(), |a| format!("table {a}"))
    );
    if arg.is_empty() || arg == "noise" {
        let mut total = 0;
        for n in [4000usize, 16000, 64000] {
            for s in [0.01, 0.02, 0.03, 0.05] {
                let cloud = noisy_sphere(n, s, n as u64 + (s * 1000.0) as u64);
                for m in 1..=3 {
                    let mls = ManifoldMls::new(cloud.clone(), Settings::new(2, m)).unwrap();
                    let mut fails = 0;
                    let mut err: f64 = 0.0;
                    let mut its = 0usize;
                    let mut cmax: f64 = 0.0;
                    let mut wid: f64 = 0.0;
                    let t = Instant::now();
                    for q in fib(400) {
                        let r = [q[0] * 0.8 - q[1] * 0.6, q[0] * 0.6 + q[1] * 0.8, q[2]];
                        match mls.evaluate(&r) {
                            Ok(e) => {
                                err = err.max((e.value[0] - f(&r)).abs());
                                its += e.chart.iterations;
                                cmax = cmax.max(e.quality.condition);
                                wid = wid.max(e.quality.widening);
                            }
                            Err(_) => fails += 1,
                        }
                    }
                    total += fails;
                    println!(
                        "noise N={n} s={s} m={m}: fails {fails}, max err {err:.3e}, mean its {:.1}, {:.0} us/q cond max {cmax:.1} widening max {wid:.2}",
                        its as f64 / (400 - fails).max(1) as f64,
                        t.elapsed().as_secs_f64() * 1e6 / 400.0
                    );
                }
            }
        }
        println!("noise total failures {total}");
    }
    if arg.is_empty() || arg == "torus" {
        // Flat torus (cos u, sin u, cos v, sin v) isometrically in R⁶, v 11× coarser.
        let torus = Torus::new();
        let (ku, kv): (usize, usize) = std::env::var("TORUS")
            .ok()
            .map(|s| {
                let v: Vec<usize> = s.split(",").map(|x| x.parse().unwrap()).collect();
                (v[0], v[1])
            })
            .unwrap_or((440, 40));
        let cloud = torus.cloud(ku, kv);
        let widenings: Vec<f64> = std::env::var("WIDENING")
            .ok()
            .map(|s| s.split(',').map(|x| x.parse().unwrap()).collect())
            .unwrap_or(vec![Settings::new(2, 1).max_widening]);
        for factor in [3.0, 10.0, 20.0, 30.0] {
            for (m, max_widening) in [1usize, 2]
                .into_iter()
                .flat_map(|m| widenings.iter().map(move |w| (m, *w)))
            {
                if widenings.len() > 1 {
                    print!("max_widening {max_widening}: ");
                }
                let settings = Settings {
                    bandwidth: Bandwidth::Neighbours { factor, scale: 2.0 },
                    max_widening,
                    ..Settings::new(2, m)
                };
                let mls = ManifoldMls::new(cloud.clone(), settings).unwrap();
                let mut fails = 0;
                let mut errs = Vec::new();
                let mut conds: Vec<f64> = Vec::new();
                for (u, v) in torus.queries(200) {
                    match mls.evaluate(&torus.point(u, v)) {
                        Ok(e) => {
                            let er = (e.value[0] - Torus::value(u, v)).abs();
                            conds.push(e.quality.condition);
                            errs.push(er)
                        }
                        Err(e) => {
                            if fails == 0 {
                                eprintln!("first failure: {e}");
                            }
                            fails += 1
                        }
                    }
                }
                let bad = errs.iter().filter(|&&e| e > 0.1).count();
                conds.sort_by(f64::total_cmp);
                println!(
                    "torus factor {factor} m={m}: fails {fails}, max err {:.3e}, err>0.1: {bad}, cond median {:.1} max {:.1}",
                    errs.iter().fold(0.0f64, |a, &b| a.max(b)),
                    conds.get(conds.len() / 2).copied().unwrap_or(f64::NAN),
                    conds.last().copied().unwrap_or(f64::NAN)
                );
            }
        }
    }
    if arg.is_empty() || arg == "offset" {
        for m in 1..=3 {
            let mut prev = f64::NAN;
            for n in [8000usize, 32000, 128000] {
                let pts = fib(n);
                let mls = ManifoldMls::new(
                    PointCloud::from_points(3, pts.iter().flatten().copied().collect()).unwrap(),
                    Settings::new(2, m),
                )
                .unwrap();
                let mut err: f64 = 0.0;
                for q in fib(97) {
                    let r = [
                        1.05 * (q[0] * 0.8 - q[1] * 0.6),
                        1.05 * (q[0] * 0.6 + q[1] * 0.8),
                        1.05 * q[2],
                    ];
                    let p = mls.project(&r).unwrap();
                    err = err.max(((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs());
                }
                println!(
                    "offset 0.05 m={m} N={n}: err {err:.3e} order {:.2}",
                    (prev / err).log2()
                );
                prev = err;
            }
        }
    }
}
