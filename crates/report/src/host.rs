//! Where and when the report was made: processor, cores, operating system, the
//! project's git revision and the date, so numbers from two reports can be compared.

use std::path::Path;
use std::process::Command;

/// The machine and the source the numbers come from.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Host {
    /// Processor model (from `/proc/cpuinfo` where available).
    pub cpu: String,
    /// Family and model numbers and the widest vector extensions, "; "-separated
    /// ([`crate::cpu::cpu_details`]; empty where `/proc/cpuinfo` gives none).
    pub cpu_details: String,
    /// Hardware threads the system offers.
    pub cores: usize,
    /// Operating system and architecture.
    pub os: String,
    /// `git describe --always --dirty` of the workspace, if it is a git checkout.
    pub revision: String,
    /// The date, UTC, as YYYY-MM-DD.
    pub date: String,
}

impl Host {
    /// Reads the host; `workspace` is where git is asked for the revision.
    pub fn detect(workspace: &Path) -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu = crate::cpu::cpu_name(&cpuinfo).unwrap_or_else(|| "unknown".into());
        let cpu_details = crate::cpu::cpu_details(&cpuinfo).join("; ");
        let revision = Command::new("git")
            .args(["describe", "--always", "--dirty"])
            .current_dir(workspace)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|| "unknown".into());
        let seconds = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        Self {
            cpu,
            cpu_details,
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
            revision,
            date: civil_date(seconds / 86_400),
        }
    }

    /// "CPU (family F, model M; AVX-512, FMA; N hardware threads, OS)": the machine as
    /// the report's first lines name it ([`crate::cpu::describe_machine`]).
    pub fn machine(&self) -> String {
        crate::cpu::describe_machine(&self.cpu, &self.cpu_details, self.cores, &self.os)
    }
}

/// YYYY-MM-DD of a day count since 1970-01-01 (Howard Hinnant's civil-from-days).
fn civil_date(days: u64) -> String {
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_machine_names_the_details_where_known() {
        let mut host = Host {
            cpu: "AMD EPYC".into(),
            cpu_details: "family 26, model 2; AVX-512, FMA".into(),
            cores: 2,
            os: "linux x86_64".into(),
            revision: "abc".into(),
            date: "2026-12-02".into(),
        };
        assert_eq!(
            host.machine(),
            "AMD EPYC (family 26, model 2; AVX-512, FMA; 2 hardware threads, linux x86_64)"
        );
        host.cpu_details.clear();
        assert_eq!(
            host.machine(),
            "AMD EPYC (2 hardware threads, linux x86_64)"
        );
    }

    #[test]
    fn civil_dates() {
        assert_eq!(civil_date(0), "1970-01-01");
        assert_eq!(civil_date(11_016), "2000-02-29");
        assert_eq!(civil_date(20_415), "2025-11-23");
    }
}
