//! The peak resident memory of this process, for `summary.json`: read from
//! `/proc/self/status` (`VmHWM`) where the system has it (Linux), absent elsewhere.
//! Runs in a process of their own (`umls run`, and every run of `umls report`) measure
//! their own peak; runs inside a longer-lived process see that process's peak.

/// Peak resident set size in bytes, if the system reports it.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    parse_vm_hwm(&status)
}

/// `VmHWM:   123456 kB` → bytes.
fn parse_vm_hwm(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
