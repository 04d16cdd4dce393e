//! Nodes at the same point. Gmsh writes a node twice when two CAD entities were meshed
//! without being joined (duplicate points in the geometry, or meshes merged without
//! `Coherence Mesh`); the cells then meet along a crack that no boundary condition
//! names, and the run treats it as two free surfaces.

use std::collections::HashMap;

use nalgebra::SVector;

/// Points closer than this fraction of the mesh extent are the same point: Gmsh prints
/// 16 significant digits, so a duplicate written from one coordinate is exact, and one
/// computed twice differs by round-off, well below this.
pub(crate) const COINCIDENCE_TOLERANCE: f64 = 1e-12;

/// The first pair (earlier index, later index) of `points` closer than `tolerance`,
/// in the order the later point appears; `None` if all are apart.
///
/// Hashes each point to a cube of side `tolerance` and compares it with the points
/// already in its cube and the 3^D − 1 around it: linear time, where sorting along one
/// axis would compare whole lattice planes with each other.
pub(crate) fn first_coincident<const D: usize>(
    points: &[SVector<f64, D>],
    tolerance: f64,
) -> Option<(usize, usize)> {
    let cube = |x: &SVector<f64, D>| -> [i64; D] {
        std::array::from_fn(|k| (x[k] / tolerance).floor() as i64)
    };
    let mut cubes: HashMap<[i64; D], Vec<usize>> = HashMap::with_capacity(points.len());
    for (later, x) in points.iter().enumerate() {
        let home = cube(x);
        for offset in 0..3usize.pow(D as u32) {
            let mut key = home;
            let mut rest = offset;
            for k in key.iter_mut() {
                *k += (rest % 3) as i64 - 1;
                rest /= 3;
            }
            if let Some(earlier) = cubes.get(&key).and_then(|list| {
                list.iter()
                    .copied()
                    .find(|&i| (points[i] - x).norm() <= tolerance)
            }) {
                return Some((earlier, later));
            }
        }
        cubes.entry(home).or_default().push(later);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(n: usize) -> Vec<SVector<f64, 2>> {
        (0..n * n)
            .map(|i| SVector::<f64, 2>::new((i % n) as f64 / n as f64, (i / n) as f64 / n as f64))
            .collect()
    }

    #[test]
    fn a_lattice_has_no_coincident_points() {
        assert_eq!(first_coincident(&lattice(50), 1e-12), None);
    }

    #[test]
    fn a_repeated_point_is_found_with_its_first_copy() {
        let mut points = lattice(20);
        let copy = points[137];
        points.push(copy);
        assert_eq!(first_coincident(&points, 1e-12), Some((137, 400)));
    }

    #[test]
    fn round_off_apart_is_coincident_and_a_tolerance_apart_is_not() {
        // Straddling a cube boundary: the neighbouring cube must be searched.
        let a = SVector::<f64, 3>::new(1e-12 * 5.0 - 1e-15, 0.5, 0.25);
        let near = a + SVector::<f64, 3>::new(2e-15, 0.0, 0.0);
        let far = a + SVector::<f64, 3>::new(0.0, 2e-12, 0.0);
        assert_eq!(first_coincident(&[a, far], 1e-12), None);
        assert_eq!(first_coincident(&[a, far, near], 1e-12), Some((0, 2)));
    }
}
