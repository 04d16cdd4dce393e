//! The kernel report: UMLS against linear FE shape functions on a jittered, rotated
//! triangle mesh, the comparison at the heart of UMLS-MPM.
//!
//! `cargo run --release --example kernel_report [OUT_DIR]` (default `out/kernel-report`)
//! prints the mesh quality and two tables, and writes
//! - `gradient_profile.csv` / `.svg`: ∂f/∂x of an interpolated smooth field along a line
//!   crossing ~60 element facets: linear FE jumps at every crossing (the cell-crossing
//!   error that makes MPM stresses oscillate), UMLS is continuous;
//! - `convergence.csv`: RMS value and gradient errors of both under refinement.

use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

use nalgebra::Vector2;
use umls::io::chart::{Axis, LineChart, Series};
use umls::mesh::SimplexMesh;
use umls::mesh::generate::{Diagonal, Lattice};
use umls::mls::{GradientKind, Linear, Stencil, UmlsKernel};

fn field(x: &Vector2<f64>) -> (f64, Vector2<f64>) {
    let value = (2.0 * PI * x.x).sin() * (PI * x.y).cos();
    let grad = Vector2::new(
        2.0 * PI * (2.0 * PI * x.x).cos() * (PI * x.y).cos(),
        -PI * (2.0 * PI * x.x).sin() * (PI * x.y).sin(),
    );
    (value, grad)
}

fn mesh(n: usize) -> Result<SimplexMesh<2>, Box<dyn Error>> {
    Ok(Lattice::new([0.0, 0.0], [1.0, 1.0], [n, n])
        .jitter(0.2, 11)
        .rotate_by(0.0)
        .triangles(Diagonal::Alternating)?)
}

/// Value and gradient of the interpolated field at `x` by UMLS and by linear FE.
struct Interpolants<'a> {
    mesh: &'a SimplexMesh<2>,
    kernel: UmlsKernel<2>,
    nodal: Vec<f64>,
}

impl Interpolants<'_> {
    fn umls(&self, x: &Vector2<f64>, host: u32) -> Result<(f64, Vector2<f64>), Box<dyn Error>> {
        let mut st = Stencil::new();
        self.kernel.evaluate::<3, Linear>(
            self.mesh,
            host,
            x,
            GradientKind::Reconstructed,
            &mut st,
        )?;
        Ok(st.interpolate(&self.nodal)?)
    }

    fn linear_fe(&self, x: &Vector2<f64>, host: u32) -> (f64, Vector2<f64>) {
        let lambda = self.mesh.barycentric(host as usize, x);
        let grads = self.mesh.barycentric_gradients(host as usize);
        let verts = self.mesh.simplex(host as usize);
        (0..3).fold((0.0, Vector2::zeros()), |(v, g), i| {
            let u = self.nodal[verts[i] as usize];
            (v + lambda.as_slice()[i] * u, g + grads.as_slice()[i] * u)
        })
    }
}

fn interpolants(mesh: &SimplexMesh<2>) -> Interpolants<'_> {
    Interpolants {
        mesh,
        kernel: UmlsKernel::new(mesh),
        nodal: mesh.vertices().iter().map(|v| field(v).0).collect(),
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "out/kernel-report".into()),
    );
    std::fs::create_dir_all(&out)?;

    // 1. Gradient profile along a line through a 32×32 jittered mesh.
    let m = mesh(32)?;
    println!(
        "mesh: {} vertices, {} triangles\n{}\n",
        m.vertex_count(),
        m.simplex_count(),
        m.quality_summary()
    );
    let interp = interpolants(&m);
    let mut csv = String::from("s,x,y,exact_dfdx,umls_dfdx,linear_fe_dfdx\n");
    let mut rows = Vec::new();
    let mut host = None;
    let samples = 2000;
    for i in 0..=samples {
        let s = 0.03 + 0.94 * i as f64 / samples as f64;
        let x = Vector2::new(s, 0.31 + 0.12 * s);
        let found = match host {
            Some(h) => m.locate_from(&x, h),
            None => m.locate(&x),
        }
        .ok_or("profile point outside the mesh")?;
        host = Some(found.simplex);
        let exact = field(&x).1.x;
        let umls = interp.umls(&x, found.simplex)?.1.x;
        let fe = interp.linear_fe(&x, found.simplex).1.x;
        writeln!(csv, "{s},{},{},{exact},{umls},{fe}", x.x, x.y)?;
        rows.push((s, exact, umls, fe));
    }
    std::fs::write(out.join("gradient_profile.csv"), csv)?;
    // Total variation of the error along the line: counts every jump.
    let variation = |pick: fn(&Row) -> f64| {
        rows.windows(2)
            .map(|w| ((pick(&w[1]) - w[1].1) - (pick(&w[0]) - w[0].1)).abs())
            .sum::<f64>()
    };
    let max_error = |pick: fn(&Row) -> f64| {
        rows.iter()
            .map(|r| (pick(r) - r.1).abs())
            .fold(0.0, f64::max)
    };
    println!(
        "∂f/∂x along the line y = 0.31 + 0.12 x ({} samples)",
        samples + 1
    );
    println!("  kernel      max |error|   total variation of the error");
    println!(
        "  UMLS        {:>11.4e}   {:>11.4e}",
        max_error(|r| r.2),
        variation(|r| r.2)
    );
    println!(
        "  linear FE   {:>11.4e}   {:>11.4e}\n",
        max_error(|r| r.3),
        variation(|r| r.3)
    );
    plot(&out.join("gradient_profile.svg"), &rows)?;

    // 2. Convergence under refinement.
    let mut table =
        String::from("cells,h,umls_value_rms,umls_gradient_rms,fe_value_rms,fe_gradient_rms\n");
    println!("refinement (RMS errors at 3 points per triangle)");
    println!("  cells   h          UMLS value  UMLS grad   FE value    FE grad");
    for n in [8, 16, 32, 64] {
        let m = mesh(n)?;
        let interp = interpolants(&m);
        let mut sums = [0.0; 4];
        let mut count = 0.0;
        for s in 0..m.simplex_count() {
            for raw in [[0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6]] {
                let x = m.point_at(
                    s,
                    &umls::mesh::Barycentric::from_slice(&raw).ok_or("3 coordinates")?,
                );
                let (v, g) = field(&x);
                let (uv, ug) = interp.umls(&x, s as u32)?;
                let (fv, fg) = interp.linear_fe(&x, s as u32);
                sums[0] += (uv - v).powi(2);
                sums[1] += (ug - g).norm_squared();
                sums[2] += (fv - v).powi(2);
                sums[3] += (fg - g).norm_squared();
                count += 1.0;
            }
        }
        let r = sums.map(|e| (e / count).sqrt());
        let h = m.max_edge_length();
        writeln!(table, "{n},{h},{},{},{},{}", r[0], r[1], r[2], r[3])?;
        println!(
            "  {n:>5}   {h:.4e}  {:.4e}  {:.4e}  {:.4e}  {:.4e}",
            r[0], r[1], r[2], r[3]
        );
    }
    std::fs::write(out.join("convergence.csv"), table)?;
    println!(
        "\nwrote {}/gradient_profile.{{csv,svg}} and convergence.csv",
        out.display()
    );
    Ok(())
}

/// One profile sample: (s, exact, UMLS, linear FE).
type Row = (f64, f64, f64, f64);

fn plot(path: &std::path::Path, rows: &[Row]) -> Result<(), Box<dyn Error>> {
    let column = |pick: fn(&Row) -> f64| rows.iter().map(|r| (r.0, pick(r))).collect();
    LineChart {
        title: "∂f/∂x along a line crossing ~60 facets: UMLS vs linear FE".into(),
        x: Axis::linear("arc-length parameter s [-]"),
        y: Axis::linear("∂f/∂x [-]"),
        series: vec![
            Series::new("exact", column(|r| r.1)),
            Series::new("linear FE", column(|r| r.3)),
            Series::new("UMLS (reconstructed)", column(|r| r.2)),
        ],
    }
    .write_svg(path)?;
    Ok(())
}
