//! Initial geostatic (K0) stress: the state a soil column or slope has settled into under
//! its own weight, so a quasi-static analysis starts at equilibrium instead of dropping
//! the body onto its base.
//!
//! The engine's materials are functions of the deformation gradient, so an initial stress
//! is imposed as an initial elastic pre-strain: for each particle the symmetric stretch U
//! with σ(U) = σ₀ is found by Newton's method (finite-difference Jacobian, at most
//! D(D+1)/2 = 6 unknowns, least-squares steps so that a fluid's pressure is reached
//! although it resists no shear), which works for every [`Constitutive`] model and keeps
//! stress, energy and plasticity consistent with each other.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use umls_constitutive::Constitutive;

/// The geostatic Cauchy stress at `depth` below the surface: σ_v = −ρ |g| depth along
/// gravity and K0 σ_v across it.
pub fn geostatic_stress<const D: usize>(
    gravity: &SVector<f64, D>,
    density: f64,
    depth: f64,
    k0: f64,
) -> SMatrix<f64, D, D> {
    let g = gravity.norm();
    if g == 0.0 {
        return SMatrix::zeros();
    }
    let down = gravity / g;
    let vertical = -density * g * depth.max(0.0);
    let along = down * down.transpose();
    (SMatrix::<f64, D, D>::identity() - along) * (k0 * vertical) + along * vertical
}

/// Depth of every particle below the surface above it: the top of the highest particle
/// in its vertical column (columns one mean particle size wide, particle size
/// V^(1/D)), measured along `gravity`.
pub fn depths<const D: usize>(
    positions: &[SVector<f64, D>],
    volumes: &[f64],
    gravity: &SVector<f64, D>,
) -> Vec<f64> {
    let down = gravity.normalize();
    let sizes: Vec<f64> = volumes.iter().map(|v| v.powf(1.0 / D as f64)).collect();
    let width = sizes.iter().sum::<f64>() / sizes.len().max(1) as f64;
    // Horizontal coordinates: x minus its vertical part, binned per axis.
    let column = |x: &SVector<f64, D>| -> [i64; 3] {
        let horizontal = x - down * x.dot(&down);
        std::array::from_fn(|k| {
            if k < D {
                (horizontal[k] / width).round() as i64
            } else {
                0
            }
        })
    };
    let mut tops = std::collections::HashMap::<[i64; 3], f64>::new();
    for (x, size) in positions.iter().zip(&sizes) {
        let top = -x.dot(&down) + 0.5 * size;
        tops.entry(column(x))
            .and_modify(|t| *t = t.max(top))
            .or_insert(top);
    }
    positions
        .iter()
        .map(|x| tops[&column(x)] + x.dot(&down))
        .collect()
}

/// The symmetric stretch U with Cauchy stress σ(U) = `target` for `material` in `state`,
/// or `None` when Newton's method does not reach it (a stress the model cannot carry,
/// such as shear in a fluid).
pub fn prestrain<const D: usize, M: Constitutive<D>>(
    material: &M,
    state: &M::State,
    target: &SMatrix<f64, D, D>,
) -> Option<SMatrix<f64, D, D>> {
    let pairs: Vec<(usize, usize)> = (0..D).flat_map(|a| (a..D).map(move |b| (a, b))).collect();
    let n = pairs.len();
    let modulus = material.p_wave_modulus();
    let scale = target.amax().max(1e-12 * modulus);
    let stretch = |u: &DVector<f64>| {
        let mut m = SMatrix::<f64, D, D>::identity();
        for (k, &(a, b)) in pairs.iter().enumerate() {
            m[(a, b)] += u[k];
            m[(b, a)] = m[(a, b)];
        }
        m
    };
    let residual = |u: &DVector<f64>| -> Option<DVector<f64>> {
        let sigma = material.cauchy_stress(&stretch(u), state).ok()?;
        Some(DVector::from_iterator(
            n,
            pairs
                .iter()
                .map(|&(a, b)| (sigma[(a, b)] - target[(a, b)]) / scale),
        ))
    };
    // Start from the small-strain guess ε = σ / M on the diagonal.
    let mut u = DVector::from_iterator(
        n,
        pairs.iter().map(|&(a, b)| {
            if a == b {
                target[(a, a)] / modulus
            } else {
                0.0
            }
        }),
    );
    let step = 1e-7;
    for _ in 0..50 {
        let r = residual(&u)?;
        if r.amax() <= 1e-10 {
            return Some(stretch(&u));
        }
        let mut jacobian = DMatrix::zeros(n, n);
        for k in 0..n {
            let mut plus = u.clone();
            plus[k] += step;
            let mut minus = u.clone();
            minus[k] -= step;
            let column = (residual(&plus)? - residual(&minus)?) / (2.0 * step);
            jacobian.set_column(k, &column);
        }
        // The least-squares step of smallest norm: a fluid has no stiffness against
        // shear, so its Jacobian is singular in the deviatoric directions, and the
        // pseudo-inverse leaves them alone while it solves the volumetric one.
        let svd = jacobian.svd(true, true);
        let cutoff = 1e-10 * svd.singular_values.max();
        let delta = svd.solve(&r, cutoff).ok()?;
        u -= delta;
    }
    None
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
    use umls_constitutive::{
        ElasticParameters, FixedCorotated, LinearElastic, NeoHookean, WeaklyCompressibleFluid,
    };

    use super::*;

    #[test]
    fn stress_of_the_prestrain_is_the_target() {
        let parameters = ElasticParameters::from_young_poisson(1e7, 0.3).unwrap();
        let target = geostatic_stress(&Vector2::new(0.0, -10.0), 2000.0, 3.0, 0.6);
        assert_eq!(target, Matrix2::new(-36000.0, 0.0, 0.0, -60000.0));
        let u = prestrain(&NeoHookean { parameters }, &(), &target).unwrap();
        let sigma = NeoHookean { parameters }.cauchy_stress(&u, &()).unwrap();
        assert!((sigma - target).amax() < 1e-9 * 60000.0);
        // Small strains: the linear-elastic answer, ε = C⁻¹σ in plane strain.
        let u = prestrain(&LinearElastic { parameters }, &(), &target).unwrap();
        let (l, m) = (parameters.lambda(), parameters.mu());
        let exx = u[(0, 0)] - 1.0;
        let eyy = u[(1, 1)] - 1.0;
        assert!(((l + 2.0 * m) * exx + l * eyy + 36000.0).abs() < 1e-6);
        assert!((l * exx + (l + 2.0 * m) * eyy + 60000.0).abs() < 1e-6);
        // A tilted gravity in 3D gives shear in the axes; corotated reaches it too.
        let g = Vector3::new(3.0, 0.0, -9.0);
        let target = geostatic_stress(&g, 1500.0, 2.0, 0.5);
        let model = FixedCorotated { parameters };
        let u = prestrain(&model, &(), &target).unwrap();
        assert!(u[(0, 2)].abs() > 0.0 && (u - u.transpose()).amax() == 0.0);
        let sigma: Matrix3<f64> = model.cauchy_stress(&u, &()).unwrap();
        assert!((sigma - target).amax() < 1e-9 * target.amax());
    }

    /// A fluid resists no shear, so its Jacobian is singular: the hydrostatic pressure
    /// (K0 = 1) is still reached, by an isotropic stretch with p(J) = ρ g d, and a
    /// deviatoric stress (K0 ≠ 1), which a fluid cannot carry, is refused.
    #[test]
    fn a_fluid_reaches_its_pressure_and_refuses_shear() {
        let fluid = WeaklyCompressibleFluid::new(1e7, 1.0).unwrap();
        for g in [Vector3::new(0.0, 0.0, -10.0), Vector3::new(2.0, 1.0, -9.0)] {
            let target = geostatic_stress(&g, 1000.0, 0.8, 1.0);
            let u = prestrain(&fluid, &(), &target).unwrap();
            let sigma: Matrix3<f64> = fluid.cauchy_stress(&u, &()).unwrap();
            assert!((sigma - target).amax() < 1e-9 * target.amax());
            let j = u.determinant();
            assert!((fluid.pressure(j) - 1000.0 * g.norm() * 0.8).abs() < 1e-6);
        }
        let sheared = geostatic_stress(&Vector2::new(0.0, -10.0), 1000.0, 0.8, 0.5);
        assert!(prestrain(&fluid, &(), &sheared).is_none());
    }
}
