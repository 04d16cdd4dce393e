//! `[transform]`: the scene is described in its own frame and then turned as a whole
//! (mesh, particles, velocities, planes, boundary normals, gravity) into the world frame
//! the simulation runs in. A mesh kernel sees the same problem turned; a B-spline grid,
//! which stays aligned with the world axes, cannot follow, which is what a rotated scene
//! measures. References are evaluated in the scene frame and turned back.

use nalgebra::{SMatrix, SVector, Unit, Vector3};
use umls_mesh::{Orientation, SimplexMesh};

use crate::error::Result;
use crate::scene::Scene;
use crate::schema::TransformSpec;

/// A rotation about a centre: world = R (scene − c) + c.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneFrame<const D: usize> {
    /// The rotation R.
    pub rotation: SMatrix<f64, D, D>,
    /// The fixed point c.
    pub centre: SVector<f64, D>,
}

impl<const D: usize> Default for SceneFrame<D> {
    fn default() -> Self {
        Self {
            rotation: SMatrix::identity(),
            centre: SVector::zeros(),
        }
    }
}

impl<const D: usize> SceneFrame<D> {
    /// The frame of the scene's `[transform]` table (the identity without one).
    pub fn from_scene(scene: &Scene) -> Result<Self> {
        Self::from_spec(scene, "transform", scene.spec.transform.as_ref())
    }

    /// The frame of a transform table at `key` (the identity without one).
    pub fn from_spec(scene: &Scene, key: &str, spec: Option<&TransformSpec>) -> Result<Self> {
        let Some(t) = spec else {
            return Ok(Self::default());
        };
        if !t.rotation.is_finite() {
            return Err(scene.value_error(format!("{key}.rotation"), "must be finite"));
        }
        let centre = match &t.centre {
            None => SVector::zeros(),
            Some(c) => scene.vector(&format!("{key}.centre"), c)?,
        };
        let angle = t.rotation.to_radians();
        let rotation = match D {
            2 => {
                if t.axis.is_some() {
                    return Err(scene.value_error(
                        format!("{key}.axis"),
                        "a 2D scene turns about the z axis; give no axis",
                    ));
                }
                let (s, c) = angle.sin_cos();
                SMatrix::from_fn(|i, j| match (i, j) {
                    (0, 0) | (1, 1) => c,
                    (0, 1) => -s,
                    _ => s,
                })
            }
            3 => {
                let axis: Vector3<f64> = match &t.axis {
                    None => Vector3::z(),
                    Some(a) => scene.vector(&format!("{key}.axis"), a)?,
                };
                let Some(axis) = Unit::try_new(axis, 1e-300) else {
                    return Err(scene.value_error(format!("{key}.axis"), "must not be zero"));
                };
                let r = nalgebra::Rotation3::from_axis_angle(&axis, angle);
                SMatrix::from_fn(|i, j| r[(i, j)])
            }
            _ => {
                return Err(scene.value_error(key, "a 1D scene cannot be rotated"));
            }
        };
        Ok(Self { rotation, centre })
    }

    /// Whether the frame changes nothing.
    pub fn is_identity(&self) -> bool {
        self.rotation == SMatrix::<f64, D, D>::identity()
    }

    /// A scene-frame point in the world.
    pub fn point_to_world(&self, x: &SVector<f64, D>) -> SVector<f64, D> {
        self.rotation * (x - self.centre) + self.centre
    }

    /// A world point in the scene frame.
    pub fn point_to_scene(&self, x: &SVector<f64, D>) -> SVector<f64, D> {
        self.rotation.transpose() * (x - self.centre) + self.centre
    }

    /// A scene-frame vector (velocity, normal, gravity) in the world.
    pub fn vector_to_world(&self, v: &SVector<f64, D>) -> SVector<f64, D> {
        self.rotation * v
    }

    /// A world vector in the scene frame: Rᵀ v.
    pub fn vector_to_scene(&self, v: &SVector<f64, D>) -> SVector<f64, D> {
        self.rotation.transpose() * v
    }

    /// A scene-frame tensor (an affine velocity matrix) in the world: R t Rᵀ.
    pub fn tensor_to_world(&self, t: &SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
        self.rotation * t * self.rotation.transpose()
    }

    /// A world tensor (stress) in the scene frame: Rᵀ σ R.
    pub fn tensor_to_scene(&self, t: &SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
        self.rotation.transpose() * t * self.rotation
    }

    /// The mesh with every vertex turned; a rotation keeps orientations, so the cells are
    /// the same.
    pub fn mesh_to_world(
        &self,
        mesh: &SimplexMesh<D>,
    ) -> std::result::Result<SimplexMesh<D>, umls_mesh::MeshError> {
        let vertices = mesh
            .vertices()
            .iter()
            .map(|p| self.point_to_world(p))
            .collect();
        SimplexMesh::new(vertices, mesh.connectivity().to_vec(), Orientation::Reject)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn points_go_to_the_world_and_back_and_tensors_turn_with_them() {
        let angle: f64 = 30f64.to_radians();
        let (s, c) = angle.sin_cos();
        let frame = SceneFrame::<2> {
            rotation: SMatrix::<f64, 2, 2>::new(c, -s, s, c),
            centre: Vector2::new(0.5, 2.0),
        };
        let x = Vector2::new(1.0, 0.0);
        let w = frame.point_to_world(&x);
        // The offset (0.5, −2) turned by 30° about (0.5, 2).
        let expected = Vector2::new(0.5 + 0.5 * c + 2.0 * s, 2.0 + 0.5 * s - 2.0 * c);
        assert!((w - expected).norm() < 1e-15);
        assert!((frame.point_to_scene(&w) - x).norm() < 1e-15);
        // A uniaxial stress along the world image of e_y is σ_yy in the scene frame.
        let n = frame.vector_to_world(&Vector2::y());
        let sigma = -3.0 * n * n.transpose();
        let back = frame.tensor_to_scene(&sigma);
        assert!((back - SMatrix::<f64, 2, 2>::new(0.0, 0.0, 0.0, -3.0)).norm() < 1e-14);
    }
}
