//! The scene's boundary conditions on the kernel's nodes: planes become walls, mesh
//! groups become node sets (a staircase of outside nodes for a grid), regions select the
//! nodes inside them; each condition's nodes also become a reaction set, so its force is
//! reported.

use nalgebra::SVector;
use umls_engine::{FittedClamp, Wall, WallKind, face_points};

use crate::context::Context;
use crate::error::Result;
use crate::handle::Run;
use crate::schema::{BoundaryKind, Imposed};
use crate::setup::BoundaryTarget;

/// Walls on planes, and fixed or slip conditions on the nodes of mesh groups.
pub(crate) fn apply_boundaries<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
) -> Result<()> {
    let scene = ctx.scene;
    let mesh_kernel = ctx.mesh_kernel;
    for (i, (kind, target)) in ctx.setup.boundaries.iter().enumerate() {
        let wall_kind = match kind {
            BoundaryKind::Fixed => WallKind::Fixed,
            BoundaryKind::Slip => WallKind::Slip,
        };
        match target {
            BoundaryTarget::Plane { point, normal } => {
                let tolerance = 1e-6 * sim.spacing();
                let wall =
                    Wall::facing(wall_kind, *point, *normal, sim.positions()).ok_or_else(|| {
                        scene.value_error(
                            format!("boundaries[{i}].plane.normal"),
                            "must not be zero",
                        )
                    })?;
                let nodes = sim.add_wall(wall, tolerance);
                if nodes.is_empty() {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].plane"),
                        format!("no {} node lies on or beyond the plane", ctx.kernel_name),
                    ));
                }
                sim.boundary().reaction_sets.push(nodes);
            }
            BoundaryTarget::Vertices(vertices) if !mesh_kernel => {
                // A grid sees the group as a staircase: its nodes outside the mesh near
                // the group take the condition, with the nearest group vertex's normal.
                let Some(mesh) = ctx.setup.background.mesh() else {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].group"),
                        "a group condition needs the mesh it belongs to",
                    ));
                };
                let reach = 3.0 * sim.spacing();
                let nodes: Vec<(u32, SVector<f64, D>)> = sim
                    .node_positions()
                    .iter()
                    .enumerate()
                    .filter(|(_, x)| mesh.locate(x).is_none())
                    .filter_map(|(n, x)| {
                        vertices
                            .iter()
                            .map(|(v, normal)| ((mesh.vertex(*v as usize) - x).norm(), normal))
                            .min_by(|a, b| a.0.total_cmp(&b.0))
                            .filter(|(d, _)| *d <= reach)
                            .map(|(_, normal)| (n as u32, *normal))
                    })
                    .collect();
                if nodes.is_empty() {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].group"),
                        format!(
                            "no {} node lies outside the mesh near the group",
                            ctx.kernel_name
                        ),
                    ));
                }
                match kind {
                    BoundaryKind::Fixed => {
                        sim.boundary().fixed.extend(nodes.iter().map(|(n, _)| *n))
                    }
                    BoundaryKind::Slip => sim.boundary().slip.extend(nodes.iter().copied()),
                }
                sim.boundary()
                    .reaction_sets
                    .push(nodes.iter().map(|(n, _)| *n).collect());
            }
            BoundaryTarget::Vertices(vertices) => {
                match kind {
                    BoundaryKind::Fixed => sim
                        .boundary()
                        .fixed
                        .extend(vertices.iter().map(|(v, _)| *v)),
                    BoundaryKind::Slip => sim.boundary().slip.extend(vertices.iter().copied()),
                }
                let nodes = vertices.iter().map(|(v, _)| *v).collect();
                sim.boundary().reaction_sets.push(nodes);
            }
            BoundaryTarget::Region {
                region,
                normal,
                imposed,
                penalty,
            } => {
                let frame = &ctx.setup.frame;
                // Indices of the points (world frame) inside the region (scene frame).
                let inside = |points: &[SVector<f64, D>]| -> Vec<u32> {
                    points
                        .iter()
                        .enumerate()
                        .filter(|(_, x)| region.contains(&frame.point_to_scene(x)))
                        .map(|(n, _)| n as u32)
                        .collect()
                };
                let nodes = inside(&sim.node_positions());
                if nodes.is_empty() {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].region"),
                        format!("holds no {} node", ctx.kernel_name),
                    ));
                }
                match normal {
                    None if *imposed == Imposed::Face => {
                        let contains =
                            |x: &SVector<f64, D>| region.contains(&frame.point_to_scene(x));
                        let points = face_points(sim.positions(), contains, face_reach(sim));
                        if points.is_empty() {
                            return Err(scene.value_error(
                                format!("boundaries[{i}].imposed"),
                                "a clamp held on its face needs particles on both sides of the region's boundary",
                            ));
                        }
                        let moved = sim
                            .add_face_clamp(nodes.clone(), points, *penalty)
                            .map_err(|e| {
                                scene.value_error(format!("boundaries[{i}].region"), e.to_string())
                            })?;
                        sim.boundary().reaction_sets.push(moved);
                        continue;
                    }
                    None if *imposed == Imposed::Fit => {
                        let particles = inside(sim.positions());
                        if particles.is_empty() {
                            return Err(scene.value_error(
                                format!("boundaries[{i}].imposed"),
                                "a clamp imposed on the fit needs particles inside its region",
                            ));
                        }
                        let mut clamp = FittedClamp::new(nodes.clone(), particles);
                        clamp.reach = sim.spacing();
                        sim.boundary().fitted.push(clamp);
                    }
                    None => sim.boundary().fixed.extend(nodes.iter().copied()),
                    Some(n) => sim.boundary().slip.extend(nodes.iter().map(|&v| (v, *n))),
                }
                sim.boundary().reaction_sets.push(nodes);
            }
        }
    }
    Ok(())
}

/// How far apart two particles may be for a face point between them: 1.5 times the
/// largest particle spacing V_p^(1/D), so that a lattice's diagonal neighbours count and
/// a jittered lattice's gaps are bridged.
fn face_reach<const D: usize>(sim: &dyn Run<D>) -> f64 {
    let largest = sim.volumes().iter().copied().fold(0.0, f64::max);
    1.5 * largest.powf(1.0 / D as f64)
}
