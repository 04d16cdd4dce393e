//! The distance from a point to a chosen set of the mesh's boundary facets (a wall given
//! as a physical group), by parry's point projection on a polyline (2D) or a triangle
//! mesh (3D) of those facets; a sorted list of points in 1D.
//!
//! This is what turns a conforming wall of the mesh into a signed distance for kernels
//! whose nodes do not conform to it (a B-spline grid): the distance here, the side from
//! [`SimplexMesh::locate`].

use crate::error::MeshError;
use crate::mesh::{Point, SimplexMesh};
use crate::topology::BoundaryFacet;

/// The facets a distance is measured to, in the form parry queries.
#[derive(Clone)]
enum Facets {
    /// 1D: the facets are points.
    Points(Vec<f64>),
    #[cfg(feature = "dim2")]
    Polyline(parry2d_f64::shape::Polyline),
    #[cfg(feature = "dim3")]
    TriMesh(parry3d_f64::shape::TriMesh),
}

/// The distance to a set of boundary facets ([`SimplexMesh::facet_distance`]).
#[derive(Clone)]
pub struct FacetDistance<const D: usize> {
    facets: Facets,
    count: usize,
}

impl<const D: usize> std::fmt::Debug for FacetDistance<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FacetDistance({} facets)", self.count)
    }
}

impl<const D: usize> SimplexMesh<D> {
    /// The distance to the boundary facets for which `keep` holds (for example, those whose
    /// vertices all belong to a physical group). [`MeshError::NoFacets`] when it keeps
    /// none.
    pub fn facet_distance(
        &self,
        keep: impl Fn(&BoundaryFacet<D>) -> bool,
    ) -> Result<FacetDistance<D>, MeshError> {
        let kept: Vec<Vec<u32>> = self
            .topology()
            .boundary_facets()
            .iter()
            .filter(|f| keep(f))
            .map(|f| self.facet_vertices(f))
            .collect();
        if kept.is_empty() {
            return Err(MeshError::NoFacets);
        }
        let count = kept.len();
        let facets = match D {
            1 => Facets::Points(kept.iter().map(|f| self.vertex(f[0] as usize)[0]).collect()),
            2 => {
                #[cfg(feature = "dim2")]
                {
                    use parry2d_f64::math::Vector;
                    let vertices = self
                        .vertices()
                        .iter()
                        .map(|v| Vector::new(v[0], v[1]))
                        .collect();
                    let indices = kept.iter().map(|f| [f[0], f[1]]).collect();
                    Facets::Polyline(parry2d_f64::shape::Polyline::new(vertices, Some(indices)))
                }
                #[cfg(not(feature = "dim2"))]
                return Err(MeshError::DimensionFeatureDisabled {
                    dim: 2,
                    feature: "dim2",
                });
            }
            _ => {
                #[cfg(feature = "dim3")]
                {
                    use parry3d_f64::math::Vector;
                    let vertices = self
                        .vertices()
                        .iter()
                        .map(|v| Vector::new(v[0], v[1], v[2]))
                        .collect();
                    let indices = kept.iter().map(|f| [f[0], f[1], f[2]]).collect();
                    // Only an empty index list is refused, and `kept` is not empty.
                    let mesh = parry3d_f64::shape::TriMesh::new(vertices, indices)
                        .map_err(|_| MeshError::NoFacets)?;
                    Facets::TriMesh(mesh)
                }
                #[cfg(not(feature = "dim3"))]
                return Err(MeshError::DimensionFeatureDisabled {
                    dim: 3,
                    feature: "dim3",
                });
            }
        };
        Ok(FacetDistance { facets, count })
    }

    /// The vertices of a boundary facet: its simplex's vertices but the opposite one.
    pub fn facet_vertices(&self, facet: &BoundaryFacet<D>) -> Vec<u32> {
        self.simplex(facet.simplex as usize)
            .iter()
            .enumerate()
            .filter(|(local, _)| *local != facet.opposite as usize)
            .map(|(_, &v)| v)
            .collect()
    }
}

impl<const D: usize> FacetDistance<D> {
    /// How many facets the distance is measured to.
    pub fn facet_count(&self) -> usize {
        self.count
    }

    /// The closest point to `x` on the facets, and its distance.
    pub fn closest(&self, x: &Point<D>) -> (Point<D>, f64) {
        let mut closest = *x;
        match &self.facets {
            Facets::Points(points) => {
                let nearest = points
                    .iter()
                    .copied()
                    .min_by(|a, b| (a - x[0]).abs().total_cmp(&(b - x[0]).abs()))
                    .unwrap_or(x[0]);
                closest[0] = nearest;
            }
            #[cfg(feature = "dim2")]
            Facets::Polyline(line) => {
                use parry2d_f64::query::PointQuery;
                let p = parry2d_f64::math::Vector::new(x[0], x[1]);
                let projection = line.project_local_point(p, false);
                closest[0] = projection.point.x;
                closest[1] = projection.point.y;
            }
            #[cfg(feature = "dim3")]
            Facets::TriMesh(mesh) => {
                use parry3d_f64::query::PointQuery;
                let p = parry3d_f64::math::Vector::new(x[0], x[1], x[2]);
                let projection = mesh.project_local_point(p, false);
                closest[0] = projection.point.x;
                closest[1] = projection.point.y;
                closest[2] = projection.point.z;
            }
        }
        (closest, (closest - x).norm())
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Vector2, Vector3};

    use crate::generate::{Diagonal, Lattice};

    /// The distance to the bottom of a unit square, and to the whole boundary of a unit
    /// cube, from points inside and outside, against the exact values.
    #[test]
    fn distances_to_chosen_facets_are_exact() {
        let square = Lattice::new([0.0, 0.0], [1.0, 1.0], [5, 5])
            .triangles(Diagonal::Alternating)
            .unwrap();
        let bottom = square
            .facet_distance(|f| f.normal[1] < -0.5)
            .expect("the bottom edge");
        assert_eq!(bottom.facet_count(), 5);
        for (x, point, d) in [
            (Vector2::new(0.3, 0.4), Vector2::new(0.3, 0.0), 0.4),
            (Vector2::new(0.7, -0.2), Vector2::new(0.7, 0.0), 0.2),
            (Vector2::new(1.3, -0.4), Vector2::new(1.0, 0.0), 0.5),
        ] {
            let (closest, distance) = bottom.closest(&x);
            assert!((closest - point).norm() < 1e-14, "{closest:?} for {x:?}");
            assert!((distance - d).abs() < 1e-14);
        }
        let cube = Lattice::new([0.0; 3], [1.0; 3], [3, 3, 3])
            .tetrahedra()
            .unwrap();
        let all = cube.facet_distance(|_| true).unwrap();
        assert_eq!(all.facet_count(), 6 * 9 * 2);
        let (closest, distance) = all.closest(&Vector3::new(0.5, 0.6, 0.9));
        assert!((closest - Vector3::new(0.5, 0.6, 1.0)).norm() < 1e-12);
        assert!((distance - 0.1).abs() < 1e-12);
        let (_, distance) = all.closest(&Vector3::new(1.3, 1.4, 0.5));
        assert!((distance - 0.5).abs() < 1e-12);
        assert!(square.facet_distance(|_| false).is_err());
    }
}
