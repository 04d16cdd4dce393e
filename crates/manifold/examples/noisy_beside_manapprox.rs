//! The noisy-data table of docs/manifold-mls.md: answers the cases that
//! `peers/noisy_cases.py` wrote (and answered with manapprox) and prints both side by
//! side: value RMS and worst value error against the true function, the worst
//! displacement of an on-manifold query by its projection, failures, flagged fits and
//! time per query.
//!
//! `cargo run --release -p umls-manifold --example noisy_beside_manapprox -- DIR [Bandwidth]`
//! where DIR is the script's output folder; an optional second argument `neighbours=C,S`
//! replaces the default bandwidth by `Bandwidth::Neighbours { factor: C, scale: S }`.
use std::fs;
use std::path::Path;
use std::time::Instant;

use umls_manifold::{Bandwidth, ManifoldMls, PointCloud, Settings};

fn rows(path: &Path) -> Vec<Vec<f64>> {
    fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .filter(|line| !line.trim().is_empty())
        .map(|line| {
            line.split_whitespace()
                .map(|x| x.parse::<f64>().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

/// RMS, max of |error|, and the count of non-finite answers.
struct Errors {
    squares: f64,
    worst: f64,
    worst_projection: f64,
    failures: usize,
    count: usize,
}

impl Errors {
    fn new() -> Self {
        Self {
            squares: 0.0,
            worst: 0.0,
            worst_projection: 0.0,
            failures: 0,
            count: 0,
        }
    }

    fn add(&mut self, value: f64, truth: f64, projection: &[f64], query: &[f64]) {
        if !value.is_finite() {
            self.failures += 1;
            return;
        }
        let e = (value - truth).abs();
        self.squares += e * e;
        self.worst = self.worst.max(e);
        let moved = projection
            .iter()
            .zip(query)
            .map(|(p, q)| (p - q) * (p - q))
            .sum::<f64>()
            .sqrt();
        self.worst_projection = self.worst_projection.max(moved);
        self.count += 1;
    }

    fn rms(&self) -> f64 {
        (self.squares / self.count.max(1) as f64).sqrt()
    }
}

fn main() {
    let root = std::env::args().nth(1).expect("the cases' folder");
    let bandwidth = std::env::args().nth(2).map(|arg| {
        let (c, s) = arg
            .strip_prefix("neighbours=")
            .and_then(|v| v.split_once(','))
            .expect("neighbours=C,S");
        Bandwidth::Neighbours {
            factor: c.parse().unwrap(),
            scale: s.parse().unwrap(),
        }
    });
    let mut names: Vec<_> = fs::read_dir(&root)
        .expect("the cases' folder")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.join("manapprox.txt").exists())
        .collect();
    names.sort();
    println!(
        "| case | growth | RMS | manapprox | ratio | worst | manapprox | projection worst | manapprox | failed / flagged | µs per query | manapprox |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for dir in names {
        let samples = rows(&dir.join("samples.txt"));
        let queries = rows(&dir.join("queries.txt"));
        let peer = rows(&dir.join("manapprox.txt"));
        let degree: usize = fs::read_to_string(dir.join("degree.txt"))
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let n = samples[0].len() - 1;
        let coords: Vec<f64> = samples.iter().flat_map(|r| r[..n].to_vec()).collect();
        let values: Vec<f64> = samples.iter().map(|r| r[n]).collect();
        let cloud = PointCloud::new(n, coords, 1, values).unwrap();
        let mut settings = Settings::new(2, degree);
        if let Some(b) = bandwidth {
            settings.bandwidth = b;
        }
        let mls = ManifoldMls::new(cloud, settings).unwrap();
        let (mut ours, mut theirs) = (Errors::new(), Errors::new());
        let mut flagged = 0;
        // Queries raising each concern: noise-dominated, unresolved, few samples, reach.
        let mut raised = [0usize; 4];
        let start = Instant::now();
        let answers: Vec<_> = queries.iter().map(|q| mls.evaluate(&q[..n])).collect();
        let per_query = start.elapsed().as_secs_f64() / queries.len() as f64;
        for ((q, answer), p) in queries.iter().zip(&answers).zip(&peer) {
            match answer {
                Ok(estimate) => {
                    let c = estimate.quality.concerns;
                    if c.any() {
                        flagged += 1;
                    }
                    for (count, on) in raised.iter_mut().zip([
                        c.noise_dominated,
                        c.unresolved,
                        c.few_samples,
                        c.beyond_reach,
                    ]) {
                        *count += usize::from(on);
                    }
                    ours.add(estimate.value[0], q[n], &estimate.projection, &q[..n]);
                }
                Err(_) => ours.add(f64::NAN, q[n], &[], &[]),
            }
            theirs.add(p[0], q[n], &p[1..=n], &q[..n]);
        }
        let concerns = format!(
            "noise {}, unresolved {}, few {}, reach {}",
            raised[0], raised[1], raised[2], raised[3]
        );
        let peer_time = peer.iter().map(|p| p[n + 1]).sum::<f64>() / peer.len() as f64;
        println!(
            "| {} | {:.2} | {:.3e} | {:.3e} | {:.2} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {} / {} ({}) | {:.0} | {:.0} |",
            dir.file_name().unwrap().to_string_lossy(),
            mls.growth(),
            ours.rms(),
            theirs.rms(),
            ours.rms() / theirs.rms(),
            ours.worst,
            theirs.worst,
            ours.worst_projection,
            theirs.worst_projection,
            ours.failures,
            flagged,
            concerns,
            per_query * 1e6,
            peer_time * 1e6,
        );
    }
}
