//! The line that says where a speed measurement was taken: processor, vector
//! extensions, hardware threads, operating system, revision and date.
//!
//! Timings of `peers` and `compare` mean little without the machine: the engine's lead
//! over Taichi has been measured at 1.8× on one CPU and 3.0–3.4× on another
//! (docs/scenes.md, *fluid-box-3d*). Virtual machines often name the processor
//! only by its brand ("AMD EPYC"), so the family and model numbers, which tell its
//! generation, and the vector extensions, which `-C target-cpu=native` builds for, are
//! given with it.

use std::path::Path;
use std::process::Command;

use crate::cpu;

/// "NAME (family F, model M; AVX-512, FMA; N hardware threads, OS)" from the text of
/// `/proc/cpuinfo` (its first processor), in the comparison report's words
/// ([`cpu::describe_machine`]); "unknown processor" where it names none.
pub fn describe_cpu(cpuinfo: &str, threads: usize, os: &str) -> String {
    let name = cpu::cpu_name(cpuinfo).unwrap_or_else(|| "unknown processor".into());
    cpu::describe_machine(&name, &cpu::cpu_details(cpuinfo).join("; "), threads, os)
}

/// "Machine: … Revision `R`, DATE." for this machine and the checkout at `workspace`.
pub fn machine_line(workspace: &Path) -> String {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let output = |program: &str, args: &[&str]| {
        Command::new(program)
            .args(args)
            .current_dir(workspace)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|| "unknown".into())
    };
    format!(
        "Machine: {}. Revision `{}`, {} (UTC).",
        describe_cpu(
            &cpuinfo,
            threads,
            &format!("{} {}", std::env::consts::OS, std::env::consts::ARCH)
        ),
        output("git", &["describe", "--always", "--dirty"]),
        output("date", &["-u", "+%Y-%m-%d %H:%M"]),
    )
}

/// `report` (a Markdown text that starts with its title) with `line` as the paragraph
/// after the title.
pub fn after_title(report: &str, line: &str) -> String {
    match report.split_once("\n\n") {
        Some((title, rest)) => format!("{title}\n\n{line}\n\n{rest}"),
        None => format!("{report}\n\n{line}\n"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_processor_is_described_with_its_threads() {
        let zen3 = "cpu family\t: 25\nmodel\t\t: 1\nmodel name\t: AMD EPYC 7B13\n\
                    flags\t\t: fpu avx2 fma\n";
        assert_eq!(
            describe_cpu(zen3, 1, "linux x86_64"),
            "AMD EPYC 7B13 (family 25, model 1; AVX2, FMA; 1 hardware thread, linux x86_64)"
        );
        assert_eq!(
            describe_cpu("", 4, "linux x86_64"),
            "unknown processor (4 hardware threads, linux x86_64)"
        );
    }

    #[test]
    fn the_machine_line_follows_the_title() {
        assert_eq!(
            after_title("# T\n\nBody.\n\n| a |\n", "Machine: M."),
            "# T\n\nMachine: M.\n\nBody.\n\n| a |\n"
        );
        assert_eq!(after_title("# T", "Machine: M."), "# T\n\nMachine: M.\n");
    }
}
