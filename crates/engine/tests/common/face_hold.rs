//! What the face-clamp tests share in 2D and 3D: how the clamp region is imposed, the
//! spread of the tip's swing over lattice layouts, and the speed left at the face.

use nalgebra::SVector;
use umls_constitutive::Constitutive;
use umls_engine::{Simulation, TransferScheme};
use umls_transfer::{Kernel, Stencil};

/// How the clamp region x ≤ 0 is imposed.
#[derive(Clone, Copy, PartialEq, Debug)]
pub enum Clamp {
    /// Every node in the region fixed.
    Nodes,
    /// Held on its face ([`umls_engine::FaceClamp`]).
    Face,
}

/// The spreads of the deepest tip displacement over the lattice moved by 0, ¼, ½ and ¾
/// of a cell along the beam, (node clamp, face clamp); `deepest(shift, clamp)` runs one.
pub fn layout_spreads(deepest: impl Fn(f64, Clamp) -> f64) -> (f64, f64) {
    let over_shifts = |clamp| -> Vec<f64> {
        [0.0, 0.25, 0.5, 0.75]
            .iter()
            .map(|&shift| deepest(shift, clamp))
            .collect()
    };
    (
        spread(&over_shifts(Clamp::Nodes)),
        spread(&over_shifts(Clamp::Face)),
    )
}

/// The relative spread (largest less smallest over the largest in size) of the deepest
/// tip displacements.
fn spread(deepest: &[f64]) -> f64 {
    let (low, high) = deepest
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &d| (l.min(d), h.max(d)));
    (high - low) / high.abs()
}

/// The largest speed `sim`'s grid velocity interpolates at the face `points`, over the
/// fastest particle's speed.
pub fn face_speed<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme>(
    sim: &Simulation<D, K, M, T>,
    points: &[SVector<f64, D>],
) -> f64 {
    let fastest = sim
        .particles()
        .velocity
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    let (_, velocity) = sim.grid();
    let mut stencil = Stencil::new();
    let mut speed = 0.0f64;
    for x in points {
        sim.kernel
            .stencil(x, &mut K::Cache::default(), &mut stencil)
            .unwrap();
        let v: SVector<f64, D> = stencil
            .iter()
            .map(|(n, value, _)| velocity[n as usize] * value)
            .sum();
        speed = speed.max(v.norm() / fastest);
    }
    speed
}
