//! Helpers shared by the binary's test files.

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs `umls` with `args`, killing it after `limit`: a hang fails the test instead of
/// stalling the suite.
pub fn umls_within(args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_umls"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("`umls {}` did not finish within {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}
