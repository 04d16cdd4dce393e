//! `cargo xtask --help` describes every task and succeeds; an unknown task fails with
//! the same description.

use std::process::Command;

const TASKS: [&str; 6] = ["ci", "bench", "compare", "peers", "deny", "help"];

#[test]
fn help_lists_every_task_and_exits_zero() {
    for flag in ["--help", "-h", "help"] {
        let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
            .arg(flag)
            .output()
            .unwrap();
        assert!(out.status.success(), "{flag}: {:?}", out.status);
        let text = String::from_utf8_lossy(&out.stdout);
        for task in TASKS {
            assert!(
                text.lines().any(|l| l.trim_start().starts_with(task)),
                "{flag}: `{task}` is not described in\n{text}"
            );
        }
    }
}

#[test]
fn an_unknown_task_fails_and_says_which() {
    let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("bech")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("unknown task `bech`"), "{text}");
    assert!(text.contains("compare"), "{text}");
}
