//! Quadratic APIC: the particles' quadratic modes keep what APIC's round trip filters,
//! for mesh and grid kernels alike, and its FLIP blend at α = 0 is the same scheme.

use nalgebra::Vector2;
use umls_constitutive::{ElasticParameters, NeoHookean};
use umls_engine::{
    Apic, Particles, QuadraticApic, QuadraticApicFlip, Simulation, StepSettings, TransferScheme,
};
use umls_kernels::{BSplineOrder, Umls2};
use umls_transfer::Kernel;

#[path = "common/unit_square.rs"]
mod unit_square;
use unit_square::{grid, mesh};

/// A quadratic velocity field around the unit square's centre.
fn quadratic(p: Vector2<f64>) -> Vector2<f64> {
    let r = p - Vector2::new(0.5, 0.5);
    Vector2::new(
        0.1 + 0.8 * r.y * r.y - 0.3 * r.x * r.y,
        -0.05 + 0.6 * r.x * r.x + 0.4 * r.y * r.y,
    )
}

/// Particles four per 0.05-cell filling [0.25, 0.75]², moving with [`quadratic`].
fn block<C: Copy + Default>() -> Particles<2, (), C> {
    let h = 0.025;
    let x: Vec<Vector2<f64>> = (0..400)
        .map(|k| {
            let (i, j) = (k / 20, k % 20);
            Vector2::new(0.25 + (i as f64 + 0.5) * h, 0.25 + (j as f64 + 0.5) * h)
        })
        .collect();
    let mut particles = Particles::at_rest(x, vec![h * h; 400], 1000.0, ());
    for (v, p) in particles.velocity.iter_mut().zip(&particles.position) {
        *v = quadratic(*p);
    }
    particles
}

/// A nearly stress-free block (E = 10⁻⁶, no gravity, Δt = 10⁻⁴: the particles move
/// 10⁻⁵ of a cell per step), stepped `steps` times.
fn run<K: Kernel<2>, T: TransferScheme>(
    kernel: K,
    transfer: T,
    steps: usize,
) -> Simulation<2, K, NeoHookean, T> {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e-6, 0.3).unwrap(),
    };
    let settings = StepSettings::new(1e-4);
    let mut sim = Simulation::new(kernel, material, transfer, block(), settings).unwrap();
    for _ in 0..steps {
        sim.step().unwrap();
    }
    sim
}

/// The fraction of the particles' kinetic energy one round trip loses, measured over the
/// tenth step (the first steps fit the particles' fields to the grid).
fn loss_per_step<K: Kernel<2> + Clone, T: TransferScheme>(kernel: &K, transfer: T) -> f64 {
    let mut sim = run(kernel.clone(), transfer, 9);
    let before = sim.diagnostics().unwrap().kinetic;
    sim.step().unwrap();
    1.0 - sim.diagnostics().unwrap().kinetic / before
}

/// Without stress the step is the transfers' round trip alone. APIC keeps affine fields
/// and filters the curvature of this one every step; the quadratic modes keep it up to
/// the fit's ridge and the block's free edges. Measured: `umls` 1.22·10⁻⁴ → 8.7·10⁻⁶ per
/// step (0.07×), bspline2 5.7·10⁻⁵ → 7.0·10⁻⁷ (0.012×), bspline3 9.4·10⁻⁵ → 4.8·10⁻⁶
/// (0.05×).
#[test]
fn quadratic_modes_keep_what_the_apic_round_trip_filters() {
    let cases: [(&str, f64); 3] = [("umls", 0.1), ("bspline2", 0.03), ("bspline3", 0.1)];
    for (name, bound) in cases {
        let (apic, quad) = match name {
            "umls" => {
                let k = Umls2::new(mesh());
                (loss_per_step(&k, Apic), loss_per_step(&k, QuadraticApic))
            }
            "bspline2" => {
                let k = grid(BSplineOrder::Quadratic);
                (loss_per_step(&k, Apic), loss_per_step(&k, QuadraticApic))
            }
            _ => {
                let k = grid(BSplineOrder::Cubic);
                (loss_per_step(&k, Apic), loss_per_step(&k, QuadraticApic))
            }
        };
        eprintln!("{name}: loss per step APIC {apic:.3e}, quadratic APIC {quad:.3e}");
        assert!(
            apic > 0.0 && quad > 0.0,
            "{name}: a round trip never gains energy"
        );
        assert!(
            quad < bound * apic,
            "{name}: {quad:e} against APIC's {apic:e}"
        );
    }
}

/// The quadratic modes' coefficients are fitted and stored per particle, and an affine
/// field has none: its modes vanish by their orthogonality to the constant and to r.
#[test]
fn the_particles_carry_their_modes_and_an_affine_field_has_none() {
    let sim = run(Umls2::new(mesh()), QuadraticApic, 10);
    let p = sim.particles();
    assert_eq!(p.quadratic.len(), p.len());
    // ½ ∂²v/∂y² of the first component is 0.8 at every particle: the fitted y² mode
    // (index 2) carries it. The fit converges over the steps from the first P2G's
    // smoothed field (measured after ten steps, two cells or more inside the block:
    // 0.75–0.88).
    let inner: Vec<f64> = (0..p.len())
        .filter(|&i| (p.position[i] - Vector2::new(0.5, 0.5)).amax() < 0.1)
        .map(|i| p.quadratic[i][2][0])
        .collect();
    assert!(!inner.is_empty());
    for q in &inner {
        assert!((q - 0.8).abs() < 0.1, "y² mode {q}, expected 0.8");
    }
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e-6, 0.3).unwrap(),
    };
    // An affine field with its gradient as C_p: the first P2G gives it exactly at every
    // node the particles reach, and the fit finds no curvature there.
    let gradient = nalgebra::Matrix2::new(0.0, 0.3, -0.3, 0.1);
    let mut affine = block::<_>();
    for ((v, c), x) in affine
        .velocity
        .iter_mut()
        .zip(&mut affine.affine)
        .zip(&affine.position)
    {
        *v = Vector2::new(0.2, -0.1) + gradient * x;
        *c = gradient;
    }
    let mut sim = Simulation::new(
        Umls2::new(mesh()),
        material,
        QuadraticApic,
        affine,
        StepSettings::new(1e-4),
    )
    .unwrap();
    sim.step().unwrap();
    let largest = sim
        .particles()
        .quadratic
        .iter()
        .flat_map(|m| m.iter().map(|c| c.norm()))
        .fold(0.0, f64::max);
    assert!(largest < 1e-9, "modes of an affine field: {largest}");
}

/// FLIP blended with quadratic APIC at α = 0 takes the PIC velocity exactly: the same
/// bits as quadratic APIC.
#[test]
fn quadratic_apic_flip_at_zero_is_quadratic_apic() {
    let a = run(Umls2::new(mesh()), QuadraticApic, 5);
    let b = run(Umls2::new(mesh()), QuadraticApicFlip { alpha: 0.0 }, 5);
    assert!(a.particles().velocity == b.particles().velocity);
    assert!(a.particles().quadratic == b.particles().quadratic);
    let c = run(Umls2::new(mesh()), QuadraticApicFlip { alpha: 0.5 }, 5);
    assert!(a.particles().velocity != c.particles().velocity);
}
