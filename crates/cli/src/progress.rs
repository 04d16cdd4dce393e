//! What the command line shows while a run goes: the plan (particles × steps, and the
//! output it is about to write, with a warning past a size a person would not expect),
//! and a progress bar drawn only when asked for and stdout is a terminal, so logs and
//! pipes stay clean.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use umls_runner::{Progress, RunPlan};

/// Output past which the plan is a warning: a few GB is more than a run of a built-in
/// scene writes at its own resolution, and a refinement can multiply it unnoticed.
pub const LARGE_OUTPUT_BYTES: u64 = 2 << 30;
/// Particle-steps past which the plan is a warning (about an hour on two cores).
pub const LARGE_PARTICLE_STEPS: f64 = 1e10;

/// The progress bar and the plan's lines.
pub struct Bar {
    bar: ProgressBar,
    draw: bool,
}

impl Bar {
    /// A bar, visible if `wanted` and stdout is a terminal.
    pub fn new(wanted: bool) -> Self {
        let draw = wanted && std::io::stdout().is_terminal();
        Self {
            bar: ProgressBar::hidden(),
            draw,
        }
    }
}

/// The plan as one line, and a warning when the run is large.
pub fn describe(plan: &RunPlan) -> (String, Option<String>) {
    let gb = plan.output_bytes as f64 / 1e9;
    let line = format!(
        "{}: {} particles × {} steps = {:.2e} particle-steps; {} frames, about {gb:.2} GB of output",
        plan.scene,
        plan.particles,
        plan.steps,
        plan.particle_steps(),
        plan.frames
    );
    let warning = (plan.output_bytes > LARGE_OUTPUT_BYTES
        || plan.particle_steps() > LARGE_PARTICLE_STEPS)
        .then(|| {
            format!(
                "this run is large ({gb:.1} GB of frames, {:.1e} particle-steps): fewer frames (`--set output.frames=N`) or a coarser refinement keep it smaller; Ctrl-C stops it with its output written",
                plan.particle_steps()
            )
        });
    (line, warning)
}

impl Progress for Bar {
    fn start(&self, plan: &RunPlan) {
        for w in &plan.warnings {
            eprintln!("warning: {w}");
        }
        let (line, warning) = describe(plan);
        eprintln!("{line}");
        if let Some(w) = warning {
            eprintln!("warning: {w}");
        }
        if !self.draw {
            return;
        }
        self.bar.set_draw_target(ProgressDrawTarget::stdout());
        self.bar.set_length(plan.steps as u64);
        if let Ok(style) = ProgressStyle::with_template(
            "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} steps, eta {eta}",
        ) {
            self.bar.set_style(style);
        }
        self.bar.set_message(plan.scene.clone());
    }

    fn step(&self) {
        self.bar.inc(1);
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
