//! Seeding material points: regions of space, and particles from sample points.

use std::sync::Arc;

use nalgebra::SVector;

use crate::particles::Particles;

/// A point-in-region predicate.
pub type Inside<const D: usize> = Arc<dyn Fn(&SVector<f64, D>) -> bool + Send + Sync>;

/// A region of space that material occupies.
#[derive(Clone)]
pub enum Region<const D: usize> {
    /// All of space.
    Everywhere,
    /// The axis-aligned box lower ≤ x ≤ upper.
    Box {
        /// Lower corner.
        lower: SVector<f64, D>,
        /// Upper corner.
        upper: SVector<f64, D>,
    },
    /// The ball ‖x − centre‖ ≤ radius (a disk in 2D, an interval in 1D).
    Ball {
        /// Centre.
        centre: SVector<f64, D>,
        /// Radius.
        radius: f64,
    },
    /// The half-space n·x ≤ offset.
    HalfSpace {
        /// Outward normal n (any length).
        normal: SVector<f64, D>,
        /// Offset.
        offset: f64,
    },
    /// Any point-in-region predicate.
    Predicate(Inside<D>),
    /// Points in all of the regions.
    Intersection(Vec<Region<D>>),
    /// Points in any of the regions.
    Union(Vec<Region<D>>),
    /// Points in the first region and in none of the others.
    Difference(Vec<Region<D>>),
}

impl<const D: usize> std::fmt::Debug for Region<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Region::Everywhere => write!(f, "Everywhere"),
            Region::Box { lower, upper } => {
                write!(f, "Box({:?}, {:?})", lower.as_slice(), upper.as_slice())
            }
            Region::Ball { centre, radius } => write!(f, "Ball({:?}, {radius})", centre.as_slice()),
            Region::HalfSpace { normal, offset } => {
                write!(f, "HalfSpace({:?}, {offset})", normal.as_slice())
            }
            Region::Predicate(_) => write!(f, "Predicate"),
            Region::Intersection(parts) => {
                write!(f, "Intersection")?;
                f.debug_list().entries(parts).finish()
            }
            Region::Union(parts) => {
                write!(f, "Union")?;
                f.debug_list().entries(parts).finish()
            }
            Region::Difference(parts) => {
                write!(f, "Difference")?;
                f.debug_list().entries(parts).finish()
            }
        }
    }
}

impl<const D: usize> Region<D> {
    /// Whether `x` lies in the region.
    pub fn contains(&self, x: &SVector<f64, D>) -> bool {
        match self {
            Region::Everywhere => true,
            Region::Box { lower, upper } => (0..D).all(|k| lower[k] <= x[k] && x[k] <= upper[k]),
            Region::Ball { centre, radius } => (x - centre).norm() <= *radius,
            Region::HalfSpace { normal, offset } => normal.dot(x) <= *offset,
            Region::Predicate(inside) => inside(x),
            Region::Intersection(parts) => parts.iter().all(|r| r.contains(x)),
            Region::Union(parts) => parts.iter().any(|r| r.contains(x)),
            Region::Difference(parts) => match parts.split_first() {
                Some((first, rest)) => first.contains(x) && !rest.iter().any(|r| r.contains(x)),
                None => false,
            },
        }
    }
}

impl<const D: usize> Region<D> {
    /// The signed distance from `x` to the region's boundary, negative inside: exact for
    /// a box, a ball and a half-space; for their intersections, unions and differences
    /// the max/min combination, exact near the boundary except close to the edges where
    /// two parts meet, and never above the true distance's magnitude outside. `None` for
    /// a region without a boundary (`Everywhere`) or given as a predicate.
    pub fn signed_distance(&self, x: &SVector<f64, D>) -> Option<f64> {
        match self {
            Region::Everywhere | Region::Predicate(_) => None,
            Region::Box { lower, upper } => {
                let centre = (lower + upper) / 2.0;
                let half = (upper - lower) / 2.0;
                let q = (x - centre).abs() - half;
                let outside = q.map(|c| c.max(0.0)).norm();
                Some(outside + q.max().min(0.0))
            }
            Region::Ball { centre, radius } => Some((x - centre).norm() - radius),
            Region::HalfSpace { normal, offset } => {
                let length = normal.norm();
                (length > 0.0).then(|| (normal.dot(x) - offset) / length)
            }
            Region::Intersection(parts) => parts
                .iter()
                .map(|r| r.signed_distance(x))
                .try_fold(f64::NEG_INFINITY, |d, p| Some(d.max(p?)))
                .filter(|d| d.is_finite()),
            Region::Union(parts) => parts
                .iter()
                .map(|r| r.signed_distance(x))
                .try_fold(f64::INFINITY, |d, p| Some(d.min(p?)))
                .filter(|d| d.is_finite()),
            Region::Difference(parts) => {
                let (first, rest) = parts.split_first()?;
                rest.iter()
                    .map(|r| r.signed_distance(x).map(|d| -d))
                    .try_fold(first.signed_distance(x)?, |d, p| Some(d.max(p?)))
            }
        }
    }
}

/// Sample points (centres) of a regular lattice with spacing `h` filling the box
/// [lower, upper], each with volume h^D: seeding for grid kernels.
pub fn lattice_samples<const D: usize>(
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    h: f64,
) -> Vec<(SVector<f64, D>, f64)> {
    lattice_points(lower, upper, h).collect()
}

/// [`lattice_samples`] one at a time, so a caller that keeps only the points inside a
/// body never holds the whole box's lattice (a million points for a 0.01 lattice in the
/// unit cube).
pub fn lattice_points<const D: usize>(
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    h: f64,
) -> impl Iterator<Item = (SVector<f64, D>, f64)> {
    let counts: [usize; D] =
        std::array::from_fn(|k| ((upper[k] - lower[k]) / h).round().max(0.0) as usize);
    let total: usize = counts.iter().product();
    (0..total).map(move |mut index| {
        let x = SVector::<f64, D>::from_fn(|k, _| {
            let i = index % counts[k];
            index /= counts[k];
            lower[k] + (i as f64 + 0.5) * h
        });
        (x, h.powi(D as i32))
    })
}

impl<const D: usize, S: Clone, C: Copy + Default> Particles<D, S, C> {
    /// Particles at the `samples` (point, volume) that lie in `region`, with density
    /// `density`, the material state `state` and initial velocity `velocity(x)`.
    pub fn seed(
        samples: &[(SVector<f64, D>, f64)],
        region: &Region<D>,
        density: f64,
        state: S,
        velocity: impl Fn(&SVector<f64, D>) -> SVector<f64, D>,
    ) -> Self {
        let (positions, volumes): (Vec<_>, Vec<_>) = samples
            .iter()
            .filter(|(x, _)| region.contains(x))
            .copied()
            .unzip();
        let mut particles = Self::at_rest(positions, volumes, density, state);
        for (v, x) in particles.velocity.iter_mut().zip(&particles.position) {
            *v = velocity(x);
        }
        particles
    }

    /// Appends `other` (for scenes with several bodies or materials' worth of points).
    pub fn append(&mut self, other: Self) {
        // Quadratic modes where either has them, zero for the particles without.
        if !(self.quadratic.is_empty() && other.quadratic.is_empty()) {
            let zero = [SVector::zeros(); crate::MAX_QUADRATIC_MODES];
            self.quadratic.resize(self.position.len(), zero);
            let mut modes = other.quadratic;
            modes.resize(other.position.len(), zero);
            self.quadratic.extend(modes);
        }
        self.position.extend(other.position);
        self.velocity.extend(other.velocity);
        self.affine.extend(other.affine);
        self.affine_moment.extend(other.affine_moment);
        self.deformation.extend(other.deformation);
        self.volume.extend(other.volume);
        self.mass.extend(other.mass);
        self.state.extend(other.state);
        self.cache.extend(other.cache);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn appending_pads_the_quadratic_modes_of_the_side_without_them() {
        let at = |n: usize| {
            Particles::<2, (), ()>::at_rest(vec![Vector2::zeros(); n], vec![1.0; n], 1.0, ())
        };
        let mut with_modes = at(3);
        with_modes.quadratic = vec![[Vector2::new(1.0, 2.0); crate::MAX_QUADRATIC_MODES]; 3];
        let mut joined = at(2);
        joined.append(with_modes.clone());
        assert_eq!(joined.quadratic.len(), 5);
        assert!(
            joined.quadratic[..2]
                .iter()
                .flatten()
                .all(|c| *c == Vector2::zeros())
        );
        assert_eq!(joined.quadratic[2..], with_modes.quadratic[..]);
        with_modes.append(at(2));
        assert_eq!(with_modes.quadratic.len(), 5);
        assert!(
            with_modes.quadratic[3..]
                .iter()
                .flatten()
                .all(|c| *c == Vector2::zeros())
        );
        let mut plain = at(2);
        plain.append(at(2));
        assert!(
            plain.quadratic.is_empty(),
            "no modes where neither side has them"
        );
    }

    #[test]
    fn combined_regions_are_the_set_operations() {
        let ball = |r: f64| Region::Ball {
            centre: Vector2::zeros(),
            radius: r,
        };
        let annulus = Region::Difference(vec![ball(1.25), ball(0.75)]);
        let right = Region::HalfSpace {
            normal: Vector2::new(-1.0, 0.0),
            offset: 0.0,
        };
        let half_annulus = Region::Intersection(vec![annulus.clone(), right]);
        let either = Region::Union(vec![ball(0.5), half_annulus.clone()]);
        for (x, y, in_annulus, in_half, in_either) in [
            (1.0, 0.0, true, true, true),
            (-1.0, 0.0, true, false, false),
            (0.0, 0.0, false, false, true),
            (0.0, 0.6, false, false, false),
            (0.0, 1.3, false, false, false),
        ] {
            let p = Vector2::new(x, y);
            assert_eq!(annulus.contains(&p), in_annulus, "{p}");
            assert_eq!(half_annulus.contains(&p), in_half, "{p}");
            assert_eq!(either.contains(&p), in_either, "{p}");
        }
        assert!(!Region::<2>::Difference(Vec::new()).contains(&Vector2::zeros()));
        assert!(format!("{annulus:?}").starts_with("Difference[Ball"));
    }

    /// Signed distances against the exact ones: a box inside, beside a face and off a
    /// corner; a ball; a half-space given with a normal of any length; an annulus as a
    /// difference of balls. The sign agrees with `contains` everywhere sampled.
    #[test]
    fn signed_distances_are_exact_for_the_simple_regions() {
        let unit = Region::Box {
            lower: Vector2::new(0.0, 0.0),
            upper: Vector2::new(2.0, 1.0),
        };
        for (x, y, d) in [
            (1.0, 0.5, -0.5),
            (0.2, 0.5, -0.2),
            (2.5, 0.5, 0.5),
            (3.0, 2.0, 2f64.sqrt()),
        ] {
            let got = unit.signed_distance(&Vector2::new(x, y)).unwrap();
            assert!((got - d).abs() < 1e-15, "({x}, {y}): {got}");
        }
        let ball = |r: f64| Region::Ball {
            centre: Vector2::new(1.0, 1.0),
            radius: r,
        };
        let at = Vector2::new(4.0, 5.0);
        assert!((ball(2.0).signed_distance(&at).unwrap() - 3.0).abs() < 1e-15);
        let half = Region::HalfSpace {
            normal: Vector2::new(0.0, 3.0),
            offset: 3.0,
        };
        assert!((half.signed_distance(&at).unwrap() - 4.0).abs() < 1e-15);
        let annulus = Region::Difference(vec![ball(2.0), ball(1.0)]);
        let mid = Vector2::new(2.5, 1.0);
        assert!((annulus.signed_distance(&mid).unwrap() + 0.5).abs() < 1e-15);
        let hole = Vector2::new(1.2, 1.0);
        assert!((annulus.signed_distance(&hole).unwrap() - 0.8).abs() < 1e-15);
        for region in [unit, ball(1.5), half, annulus] {
            for k in 0..200 {
                let p = Vector2::new(-1.0 + 0.023 * k as f64, 3.0 - 0.031 * k as f64);
                let d = region.signed_distance(&p).unwrap();
                assert_eq!(d <= 0.0, region.contains(&p), "{region:?} at {p}");
            }
        }
        assert_eq!(Region::<2>::Everywhere.signed_distance(&at), None);
    }
}
