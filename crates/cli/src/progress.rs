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

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(particles: usize, steps: usize, frames: usize, output_bytes: u64) -> RunPlan {
        RunPlan {
            scene: "s".into(),
            particles,
            steps,
            frames,
            output_bytes,
            warnings: Vec::new(),
        }
    }

    #[test]
    fn a_small_run_is_described_without_a_warning() {
        let (line, warning) = describe(&plan(1000, 2000, 50, 8_550_000));
        assert_eq!(
            line,
            "s: 1000 particles × 2000 steps = 2.00e6 particle-steps; 50 frames, about 0.01 GB of output"
        );
        assert_eq!(warning, None);
    }

    #[test]
    fn much_output_or_much_work_is_a_warning() {
        let (_, output) = describe(&plan(1000, 2000, 50, LARGE_OUTPUT_BYTES + 1));
        assert!(output.unwrap().contains("2.1 GB of frames"));
        let (_, work) = describe(&plan(1_000_000, 20_000, 2, 1));
        assert!(work.unwrap().contains("2.0e10 particle-steps"));
        let (_, edge) = describe(&plan(1, 1, 2, LARGE_OUTPUT_BYTES));
        assert_eq!(edge, None, "the threshold itself is not large");
    }
}
