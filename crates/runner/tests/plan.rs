//! The plan a run announces before its first step: particles, steps, frames and the
//! size of the output it is about to write, which must be near what it then writes.

#[path = "common/runs.rs"]
mod runs;

use std::sync::{Arc, Mutex};

use runs::options;
use umls_runner::{Progress, RunPlan, RunStatus, Scene, run};

/// Keeps the plan it is told and counts the steps.
#[derive(Default)]
struct Listener {
    plan: Mutex<Option<RunPlan>>,
    steps: Mutex<usize>,
}

impl Progress for Listener {
    fn start(&self, plan: &RunPlan) {
        *self.plan.lock().unwrap() = Some(plan.clone());
    }
    fn step(&self) {
        *self.steps.lock().unwrap() += 1;
    }
}

#[test]
fn the_plan_matches_the_run_and_its_output_estimate_the_files() {
    let scene = Scene::load("colliding-disks").unwrap();
    let listener = Arc::new(Listener::default());
    let mut opts = options("plan-disks", None, Some(0.2));
    opts.progress = Some(listener.clone());
    let report = run(&scene, &opts).unwrap();
    assert_eq!(report.summary.status, RunStatus::Completed);
    let plan = listener.plan.lock().unwrap().clone().unwrap();
    assert_eq!(plan.particles, report.summary.particles);
    assert_eq!(plan.steps, report.summary.steps);
    assert_eq!(*listener.steps.lock().unwrap(), report.summary.steps);
    let out = report.out.unwrap();
    let frames: Vec<u64> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.file_name().to_string_lossy().starts_with("particles_"))
        .map(|e| e.metadata().unwrap().len())
        .collect();
    assert_eq!(frames.len(), plan.frames);
    let written: u64 = frames.iter().sum();
    let ratio = written as f64 / plan.output_bytes as f64;
    assert!(
        (0.7..1.3).contains(&ratio),
        "{written} bytes written, {} planned",
        plan.output_bytes
    );
}

#[test]
fn a_run_without_files_plans_none() {
    let scene = Scene::load("vibrating-bar").unwrap();
    let listener = Arc::new(Listener::default());
    let mut opts = options("unused", None, Some(0.05));
    opts.out = None;
    opts.progress = Some(listener.clone());
    let report = run(&scene, &opts).unwrap();
    assert_eq!(report.summary.status, RunStatus::Completed);
    let plan = listener.plan.lock().unwrap().clone().unwrap();
    assert_eq!((plan.frames, plan.output_bytes), (0, 0));
    assert_eq!(plan.particles, 100);
}
