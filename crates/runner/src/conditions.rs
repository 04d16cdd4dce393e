//! The scene's boundary conditions on the kernel's nodes: planes become walls, mesh
//! groups become node sets (for a kernel whose nodes do not conform to the mesh, a
//! signed-distance collider), regions select the nodes inside them; a slip condition may
//! carry Coulomb friction. Each condition's nodes also become a reaction set, so its
//! force is reported.

use nalgebra::SVector;

use umls_engine::{FittedClamp, Region, Wall, WallKind, face_points};

use crate::context::Context;
use crate::error::Result;
use crate::group_wall::GroupWall;
use crate::handle::Run;
use crate::sampled_wall::{NODE_REACH, sampled_collider};
use crate::schema::{BoundaryKind, Imposed};
use crate::setup::BoundaryTarget;

/// Walls on planes, and fixed or slip conditions on the nodes of mesh groups.
pub(crate) fn apply_boundaries<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
) -> Result<()> {
    for (i, (kind, target)) in ctx.setup.boundaries.iter().enumerate() {
        // Validated with the set-up: finite, not negative, on slip conditions only.
        let friction = ctx.scene.spec.boundaries[i].friction.unwrap_or(0.0);
        let nodes = match target {
            BoundaryTarget::Plane { point, normal } => {
                plane(ctx, sim, i, *kind, friction, point, normal)?
            }
            BoundaryTarget::Vertices(vertices) if !ctx.mesh_kernel => {
                collider(ctx, sim, i, *kind, friction, vertices)?
            }
            BoundaryTarget::Vertices(vertices) => {
                hold(sim, *kind, friction, vertices);
                vertices.iter().map(|(v, _)| *v).collect()
            }
            BoundaryTarget::Shape {
                region,
                inside,
                velocity,
            } => {
                let wall = ShapeWall {
                    region,
                    inside: *inside,
                    velocity: ctx.setup.frame.vector_to_world(velocity),
                };
                wall.apply(ctx, sim, i, *kind, friction)?
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
                    friction,
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

/// The engine's wall kind of a condition.
fn wall_kind(kind: BoundaryKind) -> WallKind {
    match kind {
        BoundaryKind::Fixed => WallKind::Fixed,
        BoundaryKind::Slip => WallKind::Slip,
    }
}

/// A wall on the plane through `point`; returns the nodes it holds.
fn plane<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
    i: usize,
    kind: BoundaryKind,
    friction: f64,
    point: &SVector<f64, D>,
    normal: &SVector<f64, D>,
) -> Result<Vec<u32>> {
    let tolerance = 1e-6 * sim.spacing();
    let wall =
        Wall::facing(wall_kind(kind), *point, *normal, sim.positions()).ok_or_else(|| {
            ctx.scene
                .value_error(format!("boundaries[{i}].plane.normal"), "must not be zero")
        })?;
    let nodes = sim.add_wall(wall.with_friction(friction), tolerance);
    if nodes.is_empty() {
        return Err(ctx.scene.value_error(
            format!("boundaries[{i}].plane"),
            format!("no {} node lies on or beyond the plane", ctx.kernel_name),
        ));
    }
    Ok(nodes)
}

/// Fixes the given nodes, or lets them slip along their wall normals (with Coulomb
/// friction `friction`).
fn hold<const D: usize>(
    sim: &mut dyn Run<D>,
    kind: BoundaryKind,
    friction: f64,
    nodes: &[(u32, SVector<f64, D>)],
) {
    let boundary = sim.boundary_mut();
    match kind {
        BoundaryKind::Fixed => boundary.fixed.extend(nodes.iter().map(|(n, _)| *n)),
        BoundaryKind::Slip if friction > 0.0 => boundary
            .frictional
            .extend(nodes.iter().map(|&(n, normal)| (n, normal, friction))),
        BoundaryKind::Slip => boundary.slip.extend(nodes.iter().copied()),
    }
}

/// A mesh group as a kernel whose nodes do not conform to it sees it: a signed-distance
/// collider ([`GroupWall`]) that holds the grid nodes on or beyond the wall, along its
/// normal there, and keeps the particles inside. Returns the nodes it holds.
fn collider<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
    i: usize,
    kind: BoundaryKind,
    friction: f64,
    vertices: &[(u32, SVector<f64, D>)],
) -> Result<Vec<u32>> {
    let key = format!("boundaries[{i}].group");
    let Some(mesh) = ctx.setup.background.mesh() else {
        return Err(ctx
            .scene
            .value_error(key, "a group condition needs the mesh it belongs to"));
    };
    let ids: Vec<u32> = vertices.iter().map(|(v, _)| *v).collect();
    let wall = GroupWall::new(mesh, &ids).map_err(|e| {
        ctx.scene.value_error(
            key.clone(),
            format!("no boundary facet has all its vertices in the group ({e})"),
        )
    })?;
    let spacing = sim.spacing();
    let distance = |x: &SVector<f64, D>| wall.signed_distance(x, spacing);
    let collider = sampled_collider(
        wall_kind(kind),
        friction,
        wall.sample_box(spacing),
        spacing,
        distance,
    )
    .map_err(|e| ctx.scene.value_error(key.clone(), e.to_string()))?;
    let held = sim.add_collider(collider, 1e-6 * spacing, NODE_REACH * spacing);
    held_nodes(ctx, key, "the group's wall", held)
}

/// The nodes a collider holds, or an error naming the condition `key` when it holds
/// none of the kernel's nodes (on or beyond `surface`).
fn held_nodes<const D: usize>(
    ctx: &Context<'_, D>,
    key: String,
    surface: &str,
    held: Vec<u32>,
) -> Result<Vec<u32>> {
    if held.is_empty() {
        return Err(ctx.scene.value_error(
            key,
            format!("no {} node lies on or beyond {surface}", ctx.kernel_name),
        ));
    }
    Ok(held)
}

/// The surface of a region as a wall for any kernel, at rest or in rigid translation.
struct ShapeWall<'a, const D: usize> {
    region: &'a Region<D>,
    inside: bool,
    /// World frame.
    velocity: SVector<f64, D>,
}

impl<const D: usize> ShapeWall<'_, D> {
    /// The region's signed distance (scene frame, which a rotation into the world keeps),
    /// sampled at half the kernel's spacing over the nodes' box (and the box the motion
    /// sweeps back over, for a moving wall), as a collider. Returns the nodes it holds, or
    /// may reach when it moves.
    fn apply(
        &self,
        ctx: &Context<'_, D>,
        sim: &mut dyn Run<D>,
        i: usize,
        kind: BoundaryKind,
        friction: f64,
    ) -> Result<Vec<u32>> {
        let name = if self.inside { "container" } else { "obstacle" };
        let key = format!("boundaries[{i}].{name}");
        let frame = &ctx.setup.frame;
        let sign = if self.inside { 1.0 } else { -1.0 };
        // Checked at set-up: the region has a surface, so the distance is there everywhere.
        let distance = |x: &SVector<f64, D>| {
            sign * self
                .region
                .signed_distance(&frame.point_to_scene(x))
                .unwrap_or(f64::NAN)
        };
        let nodes = sim.node_positions();
        let (mut lower, mut upper) = (nodes[0], nodes[0]);
        for x in &nodes {
            lower = lower.inf(x);
            upper = upper.sup(x);
        }
        // At time t the field is read at x − V t: the box swept back over the run.
        let swept = self.velocity * ctx.end_time;
        let (lower, upper) = (lower.inf(&(lower - swept)), upper.sup(&(upper - swept)));
        let spacing = sim.spacing();
        let bounds = (lower.add_scalar(-spacing), upper.add_scalar(spacing));
        let collider = sampled_collider(wall_kind(kind), friction, bounds, spacing, distance)
            .map_err(|e| ctx.scene.value_error(key.clone(), e.to_string()))?;
        let (tolerance, reach) = (1e-6 * spacing, NODE_REACH * spacing);
        let held = if self.velocity.iter().all(|c| *c == 0.0) {
            sim.add_collider(collider, tolerance, reach)
        } else {
            sim.add_moving_collider(collider, self.velocity, tolerance, reach, ctx.end_time)
        };
        held_nodes(ctx, key, "its surface", held)
    }
}

/// A condition on the nodes inside a region of the scene frame.
struct HeldRegion<'a, const D: usize> {
    region: &'a Region<D>,
    normal: Option<&'a SVector<f64, D>>,
    friction: f64,
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
            Some(n) => {
                let held: Vec<(u32, SVector<f64, D>)> = nodes.iter().map(|&v| (v, *n)).collect();
                hold(sim, BoundaryKind::Slip, self.friction, &held);
            }
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
