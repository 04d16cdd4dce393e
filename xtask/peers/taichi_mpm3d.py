"""The fluid-box scene as Taichi's own `mpm3d` example runs it, timed: the peer that
`cargo xtask peers` measures `umls run fluid-box-3d` against.

usage: python taichi_mpm3d.py N_GRID STEPS [f32|f64] [THREADS]
Prints one line: n_grid n_particles steps seconds particle_steps_per_s peak_rss_bytes

A weakly compressible J-fluid (E = 400) of n_grid³/4 particles placed at random in
[0.15, 0.55]³ of the unit box, quadratic B-splines on an n_grid³ grid, MLS-MPM
transfer, gravity 9.8, Δt = 4e-4 · 32 / n_grid, velocities zeroed into the walls three
cells from the box's faces; the example's kernel, unchanged. Compilation and the first
step are not timed. Peak memory is the process's resident high-water mark (Linux
reports ru_maxrss in KiB).
"""
import resource
import sys
import time

import taichi as ti

n_grid = int(sys.argv[1])
steps = int(sys.argv[2])
fp = ti.f64 if (len(sys.argv) > 3 and sys.argv[3] == "f64") else ti.f32
threads = int(sys.argv[4]) if len(sys.argv) > 4 else 0
kw = dict(arch=ti.cpu, default_fp=fp, log_level=ti.WARN)
if threads:
    kw["cpu_max_num_threads"] = threads
ti.init(**kw)

dim = 3
dt = 4e-4 * 32 / n_grid
n_particles = n_grid**dim // 2 ** (dim - 1)
dx = 1 / n_grid
p_rho = 1
p_vol = (dx * 0.5) ** 2
p_mass = p_vol * p_rho
gravity = 9.8
bound = 3
E = 400
F_x = ti.Vector.field(dim, float, n_particles)
F_v = ti.Vector.field(dim, float, n_particles)
F_C = ti.Matrix.field(dim, dim, float, n_particles)
F_J = ti.field(float, n_particles)
F_grid_v = ti.Vector.field(dim, float, (n_grid,) * dim)
F_grid_m = ti.field(float, (n_grid,) * dim)
neighbour = (3,) * dim


@ti.kernel
def substep():
    for I in ti.grouped(F_grid_m):
        F_grid_v[I] = ti.zero(F_grid_v[I])
        F_grid_m[I] = 0
    for p in F_x:
        Xp = F_x[p] / dx
        base = int(Xp - 0.5)
        fx = Xp - base
        w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
        stress = -dt * 4 * E * p_vol * (F_J[p] - 1) / dx**2
        affine = ti.Matrix.identity(float, dim) * stress + p_mass * F_C[p]
        for offset in ti.static(ti.grouped(ti.ndrange(*neighbour))):
            dpos = (offset - fx) * dx
            weight = 1.0
            for i in ti.static(range(dim)):
                weight *= w[offset[i]][i]
            F_grid_v[base + offset] += weight * (p_mass * F_v[p] + affine @ dpos)
            F_grid_m[base + offset] += weight * p_mass
    for I in ti.grouped(F_grid_m):
        if F_grid_m[I] > 0:
            F_grid_v[I] /= F_grid_m[I]
        F_grid_v[I][1] -= dt * gravity
        cond = (I < bound) & (F_grid_v[I] < 0) | (I > n_grid - bound) & (F_grid_v[I] > 0)
        F_grid_v[I] = ti.select(cond, 0, F_grid_v[I])
    for p in F_x:
        Xp = F_x[p] / dx
        base = int(Xp - 0.5)
        fx = Xp - base
        w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
        new_v = ti.zero(F_v[p])
        new_C = ti.zero(F_C[p])
        for offset in ti.static(ti.grouped(ti.ndrange(*neighbour))):
            dpos = (offset - fx) * dx
            weight = 1.0
            for i in ti.static(range(dim)):
                weight *= w[offset[i]][i]
            g_v = F_grid_v[base + offset]
            new_v += weight * g_v
            new_C += 4 * weight * g_v.outer_product(dpos) / dx**2
        F_v[p] = new_v
        F_x[p] += dt * F_v[p]
        F_J[p] *= 1 + dt * new_C.trace()
        F_C[p] = new_C


@ti.kernel
def init():
    for i in range(n_particles):
        F_x[i] = ti.Vector([ti.random() for i in range(dim)]) * 0.4 + 0.15
        F_J[i] = 1


init()
substep()
ti.sync()  # compilation and warm-up, not timed
t0 = time.perf_counter()
for _ in range(steps):
    substep()
ti.sync()
t = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(n_grid, n_particles, steps, f"{t:.4f}", f"{n_particles * steps / t:.6e}", peak)
