//! The scene as written, turned into the world it runs in by `[transform]`: background,
//! gravity, particles and boundary geometry (the references stay in the scene frame).

use std::sync::Arc;

use nalgebra::SVector;

use super::BoundaryTarget;
use crate::background::Background;
use crate::error::Result;
use crate::frame::SceneFrame;
use crate::scene::Scene;
use crate::schema::BoundaryKind;
use crate::seeds::Seeds;

/// What `[transform]` turns: the set-up's geometry in the scene frame.
pub(super) struct Geometry<'a, const D: usize> {
    pub background: Background<D>,
    pub gravity: SVector<f64, D>,
    pub seeds: &'a mut Seeds<D>,
    pub boundaries: &'a mut [(BoundaryKind, BoundaryTarget<D>)],
}

impl<const D: usize> Geometry<'_, D> {
    /// Turns everything into the world frame; returns the background and gravity.
    pub(super) fn into_world(
        self,
        scene: &Scene,
        frame: &SceneFrame<D>,
    ) -> Result<(Background<D>, SVector<f64, D>)> {
        if frame.is_identity() {
            return Ok((self.background, self.gravity));
        }
        let background = match self.background {
            Background::Mesh(mesh) => Background::Mesh(Arc::new(
                frame
                    .mesh_to_world(&mesh)
                    .map_err(|e| scene.value_error("transform", e.to_string()))?,
            )),
            Background::Box { lower, upper, .. } => Background::Box {
                lower,
                upper,
                frame: *frame,
            },
        };
        let seeds = self.seeds;
        for x in &mut seeds.position {
            *x = frame.point_to_world(x);
        }
        for v in &mut seeds.velocity {
            *v = frame.vector_to_world(v);
        }
        for c in &mut seeds.affine {
            *c = frame.tensor_to_world(c);
        }
        for (_, target) in self.boundaries.iter_mut() {
            match target {
                BoundaryTarget::Plane { point, normal } => {
                    *point = frame.point_to_world(point);
                    *normal = frame.vector_to_world(normal);
                }
                BoundaryTarget::Vertices(vertices) => {
                    for (_, normal) in vertices {
                        *normal = frame.vector_to_world(normal);
                    }
                }
                BoundaryTarget::Region { normal, .. } => {
                    if let Some(n) = normal {
                        *n = frame.vector_to_world(n);
                    }
                }
                // Its distance is taken in the scene frame (a rotation keeps distances).
                BoundaryTarget::Shape { .. } => {}
            }
        }
        Ok((background, frame.vector_to_world(&self.gravity)))
    }
}
