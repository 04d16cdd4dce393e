//! The scene's boundary conditions on the kernel's nodes: planes become walls, mesh
//! groups become node sets (a staircase of outside nodes for a grid), regions select the
//! nodes inside them; each condition's nodes also become a reaction set, so its force is
//! reported.

use nalgebra::SVector;
use umls_engine::{FittedClamp, Region, Wall, WallKind, face_points};

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
    for (i, (kind, target)) in ctx.setup.boundaries.iter().enumerate() {
        let nodes = match target {
            BoundaryTarget::Plane { point, normal } => plane(ctx, sim, i, *kind, point, normal)?,
            BoundaryTarget::Vertices(vertices) if !ctx.mesh_kernel => {
                let nodes = staircase(ctx, sim, i, vertices)?;
                hold(sim, *kind, &nodes);
                nodes.iter().map(|(n, _)| *n).collect()
            }
            BoundaryTarget::Vertices(vertices) => {
                hold(sim, *kind, vertices);
                vertices.iter().map(|(v, _)| *v).collect()
            }
            BoundaryTarget::Region {
                region,
                normal,
                imposed,
                penalty,
            } => {
                let held = HeldRegion {
                    region,
                    normal: normal.as_ref(),
                    imposed: *imposed,
                    penalty: *penalty,
                };
                held.apply(ctx, sim, i)?
            }
        };
        // Each condition's nodes are a reaction set, so its force is reported.
        sim.boundary_mut().reaction_sets.push(nodes);
    }
    Ok(())
}

/// A wall on the plane through `point`; returns the nodes it holds.
fn plane<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
    i: usize,
    kind: BoundaryKind,
    point: &SVector<f64, D>,
    normal: &SVector<f64, D>,
) -> Result<Vec<u32>> {
    let wall_kind = match kind {
        BoundaryKind::Fixed => WallKind::Fixed,
        BoundaryKind::Slip => WallKind::Slip,
    };
    let tolerance = 1e-6 * sim.spacing();
    let wall = Wall::facing(wall_kind, *point, *normal, sim.positions()).ok_or_else(|| {
        ctx.scene
            .value_error(format!("boundaries[{i}].plane.normal"), "must not be zero")
    })?;
    let nodes = sim.add_wall(wall, tolerance);
    if nodes.is_empty() {
        return Err(ctx.scene.value_error(
            format!("boundaries[{i}].plane"),
            format!("no {} node lies on or beyond the plane", ctx.kernel_name),
        ));
    }
    Ok(nodes)
}

/// Fixes or lets slip the given nodes, each with its wall normal.
fn hold<const D: usize>(
    sim: &mut dyn Run<D>,
    kind: BoundaryKind,
    nodes: &[(u32, SVector<f64, D>)],
) {
    match kind {
        BoundaryKind::Fixed => sim
            .boundary_mut()
            .fixed
            .extend(nodes.iter().map(|(n, _)| *n)),
        BoundaryKind::Slip => sim.boundary_mut().slip.extend(nodes.iter().copied()),
    }
}

/// A mesh group as a grid sees it, a staircase: the grid's nodes outside the mesh within
/// three spacings of a group vertex, each with its nearest group vertex's normal.
fn staircase<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &dyn Run<D>,
    i: usize,
    vertices: &[(u32, SVector<f64, D>)],
) -> Result<Vec<(u32, SVector<f64, D>)>> {
    let Some(mesh) = ctx.setup.background.mesh() else {
        return Err(ctx.scene.value_error(
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
        return Err(ctx.scene.value_error(
            format!("boundaries[{i}].group"),
            format!(
                "no {} node lies outside the mesh near the group",
                ctx.kernel_name
            ),
        ));
    }
    Ok(nodes)
}

/// A condition on the nodes inside a region of the scene frame.
struct HeldRegion<'a, const D: usize> {
    region: &'a Region<D>,
    normal: Option<&'a SVector<f64, D>>,
    imposed: Imposed,
    penalty: Option<f64>,
}

impl<const D: usize> HeldRegion<'_, D> {
    /// Holds the region's nodes (fixed, slip, on the fit or on the face); returns the
    /// reaction set.
    fn apply(&self, ctx: &Context<'_, D>, sim: &mut dyn Run<D>, i: usize) -> Result<Vec<u32>> {
        let scene = ctx.scene;
        let nodes = self.inside(ctx, &sim.node_positions());
        if nodes.is_empty() {
            return Err(scene.value_error(
                format!("boundaries[{i}].region"),
                format!("holds no {} node", ctx.kernel_name),
            ));
        }
        match self.normal {
            None if self.imposed == Imposed::Face => {
                let frame = &ctx.setup.frame;
                let contains = |x: &SVector<f64, D>| self.region.contains(&frame.point_to_scene(x));
                let points = face_points(sim.positions(), contains, face_reach(sim));
                if points.is_empty() {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].imposed"),
                        "a clamp held on its face needs particles on both sides of the region's boundary",
                    ));
                }
                // The face clamp moves the nodes it holds; those are the reaction set.
                return sim
                    .add_face_clamp(nodes, points, self.penalty)
                    .map_err(|e| {
                        scene.value_error(format!("boundaries[{i}].region"), e.to_string())
                    });
            }
            None if self.imposed == Imposed::Fit => {
                let particles = self.inside(ctx, sim.positions());
                if particles.is_empty() {
                    return Err(scene.value_error(
                        format!("boundaries[{i}].imposed"),
                        "a clamp imposed on the fit needs particles inside its region",
                    ));
                }
                let mut clamp = FittedClamp::new(nodes.clone(), particles);
                clamp.reach = sim.spacing();
                sim.boundary_mut().fitted.push(clamp);
            }
            None => sim.boundary_mut().fixed.extend(nodes.iter().copied()),
            Some(n) => sim
                .boundary_mut()
                .slip
                .extend(nodes.iter().map(|&v| (v, *n))),
        }
        Ok(nodes)
    }

    /// Indices of the points (world frame) inside the region (scene frame).
    fn inside(&self, ctx: &Context<'_, D>, points: &[SVector<f64, D>]) -> Vec<u32> {
        let frame = &ctx.setup.frame;
        points
            .iter()
            .enumerate()
            .filter(|(_, x)| self.region.contains(&frame.point_to_scene(x)))
            .map(|(n, _)| n as u32)
            .collect()
    }
}

/// How far apart two particles may be for a face point between them: 1.5 times the
/// largest particle spacing V_p^(1/D), so that a lattice's diagonal neighbours count and
/// a jittered lattice's gaps are bridged.
fn face_reach<const D: usize>(sim: &dyn Run<D>) -> f64 {
    let largest = sim.volumes().iter().copied().fold(0.0, f64::max);
    1.5 * largest.powf(1.0 / D as f64)
}
