//! Taichi's `mpm3d` substep (the kernel `xtask/peers/taichi_mpm3d.py` runs) ported line by
//! line to serial Rust, on the fluid box's particles (the 64,000 of
//! `scenes/fluid-box-3d.toml`, 0.01 apart in [0.15, 0.55]³, 64³ grid, Δt = 2·10⁻⁴): a
//! measuring instrument, not part of the library. It is what one core does without the
//! engine's generality: the fluid keeps J alone (no F, no stress array, no material
//! call), the walls act on grid velocities only, nothing is checked, and the scatter
//! writes straight into the grid, so its sums depend on the particle order and it
//! cannot run on two threads with the same bits. The engine's `fluid_box` bench on one
//! thread against this one says what that generality costs per particle-step
//! (docs/scenes.md, *fluid-box-3d*).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

/// Cells per axis of the unit box.
const CELLS: usize = 64;
/// Taichi's walls: grid velocities into them are zeroed this many cells from the faces.
const BOUND: usize = 3;

/// The port's state: Taichi's fields, in arrays of structures as Taichi lays them out.
struct Port {
    x: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    c: Vec<[[f64; 3]; 3]>,
    j: Vec<f64>,
    grid_v: Vec<[f64; 3]>,
    grid_m: Vec<f64>,
}

/// The node index of grid coordinates (i, j, k), k fastest as in Taichi's dense field.
fn node(i: usize, j: usize, k: usize) -> usize {
    (i * CELLS + j) * CELLS + k
}

/// The quadratic B-spline weights of the three nodes from `base` along one axis, for a
/// particle at `fx` cells from it, as Taichi writes them.
fn weights(fx: f64) -> [f64; 3] {
    [
        0.5 * (1.5 - fx).powi(2),
        0.75 - (fx - 1.0).powi(2),
        0.5 * (fx - 0.5).powi(2),
    ]
}

/// The particle's base node and its offsets from it in cells.
fn base_and_offset(x: &[f64; 3], inv_dx: f64) -> ([usize; 3], [f64; 3]) {
    let base = x.map(|c| (c * inv_dx - 0.5) as usize);
    let fx = std::array::from_fn(|d| x[d] * inv_dx - base[d] as f64);
    (base, fx)
}

/// Calls `visit(node, weight, x_node − x)` for the 27 nodes of the quadratic stencil at
/// `x`, in Taichi's order (the last axis fastest).
fn for_each_node(x: &[f64; 3], mut visit: impl FnMut(usize, f64, [f64; 3])) {
    let dx = 1.0 / CELLS as f64;
    let (base, fx) = base_and_offset(x, CELLS as f64);
    let w = fx.map(weights);
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                let offset = [i, j, k];
                let dpos = std::array::from_fn(|d| (offset[d] as f64 - fx[d]) * dx);
                let weight = w[0][i] * w[1][j] * w[2][k];
                visit(node(base[0] + i, base[1] + j, base[2] + k), weight, dpos);
            }
        }
    }
}

impl Port {
    fn new() -> Self {
        let mut x = Vec::new();
        let count = 40;
        for a in 0..count {
            for b in 0..count {
                for c in 0..count {
                    let at = |i: usize| 0.15 + 0.01 * (i as f64 + 0.5);
                    x.push([at(a), at(b), at(c)]);
                }
            }
        }
        let n = x.len();
        Self {
            x,
            v: vec![[0.0; 3]; n],
            c: vec![[[0.0; 3]; 3]; n],
            j: vec![1.0; n],
            grid_v: vec![[0.0; 3]; CELLS * CELLS * CELLS],
            grid_m: vec![0.0; CELLS * CELLS * CELLS],
        }
    }

    /// Taichi's `substep`: clear the grid, P2G, grid update, G2P.
    fn substep(&mut self) {
        let dx = 1.0 / CELLS as f64;
        let inv_dx = CELLS as f64;
        let dt = 2e-4;
        let p_vol = (dx * 0.5f64).powi(2);
        let p_mass = p_vol;
        let e = 400.0;
        self.grid_v.fill([0.0; 3]);
        self.grid_m.fill(0.0);
        for p in 0..self.x.len() {
            let stress = -dt * 4.0 * e * p_vol * (self.j[p] - 1.0) / (dx * dx);
            let affine: [[f64; 3]; 3] = std::array::from_fn(|r| {
                std::array::from_fn(|s| {
                    p_mass * self.c[p][r][s] + if r == s { stress } else { 0.0 }
                })
            });
            let (grid_v, grid_m, v) = (&mut self.grid_v, &mut self.grid_m, self.v[p]);
            for_each_node(&self.x[p], |g, weight, dpos| {
                for (r, row) in affine.iter().enumerate() {
                    let a = row[0] * dpos[0] + row[1] * dpos[1] + row[2] * dpos[2];
                    grid_v[g][r] += weight * (p_mass * v[r] + a);
                }
                grid_m[g] += weight * p_mass;
            });
        }
        for i in 0..CELLS {
            for j in 0..CELLS {
                for k in 0..CELLS {
                    let g = node(i, j, k);
                    let (m, v) = (self.grid_m[g], &mut self.grid_v[g]);
                    if m > 0.0 {
                        v.iter_mut().for_each(|c| *c /= m);
                    }
                    v[1] -= dt * 9.8;
                    for (d, &at) in [i, j, k].iter().enumerate() {
                        if (at < BOUND && v[d] < 0.0) || (at > CELLS - BOUND && v[d] > 0.0) {
                            v[d] = 0.0;
                        }
                    }
                }
            }
        }
        for p in 0..self.x.len() {
            let mut new_v = [0.0; 3];
            let mut new_c = [[0.0; 3]; 3];
            for_each_node(&self.x[p], |g, weight, dpos| {
                let g_v = self.grid_v[g];
                for r in 0..3 {
                    new_v[r] += weight * g_v[r];
                    for s in 0..3 {
                        new_c[r][s] += 4.0 * weight * g_v[r] * dpos[s] * inv_dx * inv_dx;
                    }
                }
            });
            self.v[p] = new_v;
            for (x, v) in self.x[p].iter_mut().zip(new_v) {
                *x += dt * v;
            }
            self.j[p] *= 1.0 + dt * (new_c[0][0] + new_c[1][1] + new_c[2][2]);
            self.c[p] = new_c;
        }
    }
}

fn taichi_port(c: &mut Criterion) {
    let mut group = c.benchmark_group("taichi-port");
    group.sample_size(10);
    let mut port = Port::new();
    group.throughput(Throughput::Elements(port.x.len() as u64));
    group.bench_function("serial step", |b| b.iter(|| port.substep()));
    group.finish();
}

criterion_group!(benches, taichi_port);
criterion_main!(benches);
