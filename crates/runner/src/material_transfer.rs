//! The material table and the transfer scheme of a run, chosen from the scene (the
//! scheme as a value: one simulation type serves all of them), and the simulation built
//! from the set-up's seeds.

use std::sync::Arc;

use nalgebra::SVector;
use umls_constitutive::table::{MaterialTable, PlasticPart, TableState};
use umls_engine::{
    AnyTransfer, ApicFlip, Flip, Particles, QuadraticApicFlip, Simulation, StepSettings,
};
use umls_transfer::Kernel;

use crate::context::Context;
use crate::error::Result;
use crate::handle::Run;
use crate::schema::{ForcePosition, TransferKind};

/// The simulation of `ctx`'s scene on `kernel` with the material `table` and the
/// scene's transfer scheme, as the run loop's trait object.
pub(crate) fn with_material<const D: usize, K: Kernel<D> + 'static, P: PlasticPart<D> + 'static>(
    ctx: &Context<'_, D>,
    kernel: K,
    table: MaterialTable<P>,
) -> Result<Box<dyn Run<D>>> {
    // One transfer type for the eight kinds: the scheme is chosen at run time, so the
    // step is compiled once per kernel and material table, not once per scheme as well
    // (`AnyTransfer`; the loops where a branch on the scheme would cost are compiled per
    // shape inside the engine). α was checked with the scene's header.
    let t = &ctx.scene.spec.transfer;
    let alpha = t.alpha;
    let transfer = match t.kind {
        TransferKind::Pic => AnyTransfer::Pic,
        TransferKind::Flip => AnyTransfer::Flip(Flip { alpha }),
        TransferKind::ApicFlip => AnyTransfer::ApicFlip(ApicFlip { alpha }),
        TransferKind::Apic => AnyTransfer::Apic,
        TransferKind::QuadraticApic => AnyTransfer::QuadraticApic,
        TransferKind::QuadraticApicFlip => {
            AnyTransfer::QuadraticApicFlip(QuadraticApicFlip { alpha })
        }
        TransferKind::VelocityGradient => AnyTransfer::VelocityGradient,
        TransferKind::MlsMpm => {
            if !kernel.regular_second_moment() {
                return Err(ctx.scene.value_error(
                    "transfer.kind",
                    "mls-mpm takes D_p⁻¹ N_i (x_i − x_p) as the force's gradient, and linear \
                     elements' D_p vanishes at the vertices: it needs a B-spline or UMLS kernel",
                ));
            }
            AnyTransfer::MlsMpm
        }
    };
    start(ctx, kernel, table, transfer)
}

/// The typed part of a run: particles of the table's state and the kernel's cache, and
/// the simulation, handed to the run loop as a [`Run`].
fn start<const D: usize, K: Kernel<D> + 'static, P: PlasticPart<D> + 'static>(
    ctx: &Context<'_, D>,
    kernel: K,
    table: MaterialTable<P>,
    transfer: AnyTransfer,
) -> Result<Box<dyn Run<D>>> {
    let seeds = &ctx.setup.seeds;
    let mut particles = Particles::<D, TableState<P::State>, K::Cache>::at_rest(
        seeds.position.clone(),
        seeds.volume.clone(),
        1.0,
        TableState::default(),
    );
    particles.mass.clone_from(&seeds.mass);
    particles.velocity.clone_from(&seeds.velocity);
    particles.affine.clone_from(&seeds.affine);
    for (state, &m) in particles.state.iter_mut().zip(&seeds.material) {
        state.material = m;
    }
    let mut settings = StepSettings::new(1.0);
    settings.gravity = ctx.setup.gravity;
    settings.gravity_ramp = ctx.setup.gravity_ramp;
    settings.stress_update = ctx.setup.stress_update;
    settings.stencil_storage = ctx.scene.spec.kernel.stencils.storage();
    settings.particle_sort_interval = ctx.scene.spec.kernel.particle_sort_interval;
    settings.mass_matrix = crate::schema::MassSpec::matrix(ctx.scene.spec.transfer.mass);
    settings.damping = ctx.setup.damping;
    if let Some(limit) = ctx.scene.spec.time.max_wave_courant {
        settings.max_wave_courant = limit;
    }
    let mut sim = Simulation::new(kernel, table, transfer, particles, settings)?;
    if let Some((field, position)) = &ctx.setup.body_force {
        let (field, frame) = (field.clone(), ctx.setup.frame);
        // The seeds are where the particles start, in the particles' order.
        let reference: Option<Vec<SVector<f64, D>>> =
            (*position == ForcePosition::Reference).then(|| {
                seeds
                    .position
                    .iter()
                    .map(|x| frame.point_to_scene(x))
                    .collect()
            });
        // An evaluation error (none is expected: the field was evaluated at every
        // particle before the run) gives NaN, which the engine stops at.
        sim.body_force = Some(Arc::new(move |p: usize, x: &SVector<f64, D>, t: f64| {
            let at = match &reference {
                Some(start) => start[p],
                None => frame.point_to_scene(x),
            };
            field
                .eval(&at, t)
                .map(|b| frame.vector_to_world(&b))
                .unwrap_or_else(|_| SVector::from_element(f64::NAN))
        }));
    }
    Ok(Box::new(sim))
}
