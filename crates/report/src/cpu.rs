//! The processor as a speed measurement should name it, from the text of
//! `/proc/cpuinfo`.
//!
//! Virtual machines often give only the brand ("AMD EPYC"), and the engine's speed
//! against Taichi has differed by almost 2× between CPUs of one brand with the same code
//! (docs/scenes.md, *fluid-box-3d*). So besides the name this gives the family and model
//! numbers, which tell the generation, and the widest vector extensions, which the
//! workspace's `-C target-cpu=native` builds for.
//!
//! `xtask` includes this file as its own module (`#[path]`), so that its speed reports
//! and the comparison report describe a machine alike without xtask depending on this
//! crate; it must therefore need nothing beyond `std`.

/// The first processor's `model name`, if `/proc/cpuinfo`'s text gives one.
pub fn cpu_name(cpuinfo: &str) -> Option<String> {
    field(cpuinfo, "model name")
}

/// What the name leaves out: "family F, model M" and the widest vector extensions
/// ("AVX-512" or "AVX2", then "FMA"), each where the text gives them.
pub fn cpu_details(cpuinfo: &str) -> Vec<String> {
    let mut details = Vec::new();
    if let (Some(family), Some(model)) = (field(cpuinfo, "cpu family"), field(cpuinfo, "model")) {
        details.push(format!("family {family}, model {model}"));
    }
    let flags = field(cpuinfo, "flags").unwrap_or_default();
    let has = |flag: &str| flags.split_whitespace().any(|f| f == flag);
    let vectors: Vec<&str> = [("avx512f", "AVX-512"), ("avx2", "AVX2"), ("fma", "FMA")]
        .into_iter()
        .filter(|(flag, _)| has(flag))
        // AVX-512 implies AVX2: name the widest only.
        .filter(|(flag, _)| *flag != "avx2" || !has("avx512f"))
        .map(|(_, name)| name)
        .collect();
    if !vectors.is_empty() {
        details.push(vectors.join(", "));
    }
    details
}

/// "NAME (DETAILS; N hardware threads, OS)", the machine as every speed report of the
/// project names it (`details` as [`cpu_details`] joined by "; ", left out when empty).
pub fn describe_machine(name: &str, details: &str, threads: usize, os: &str) -> String {
    let details = if details.is_empty() {
        String::new()
    } else {
        format!("{details}; ")
    };
    let plural = if threads == 1 { "" } else { "s" };
    format!("{name} ({details}{threads} hardware thread{plural}, {os})")
}

/// The value of the first line whose key is `name` exactly (`model` is not
/// `model name`); the first processor's, since it comes first.
fn field(cpuinfo: &str, name: &str) -> Option<String> {
    cpuinfo
        .lines()
        .filter_map(|l| l.split_once(':'))
        .find(|(key, _)| key.trim() == name)
        .map(|(_, value)| value.trim().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn family_model_and_the_widest_vectors_are_named() {
        // `model name` before `model`, which it must not be taken for; the second
        // processor's fields are not read.
        let amd = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC\n\
                   cpu family\t: 26\nmodel\t\t: 2\n\
                   flags\t\t: fpu sse2 avx2 fma avx512f avx512vl\n\n\
                   processor\t: 1\ncpu family\t: 99\n";
        assert_eq!(cpu_name(amd).as_deref(), Some("AMD EPYC"));
        assert_eq!(cpu_details(amd), ["family 26, model 2", "AVX-512, FMA"]);
        let zen3 = "cpu family\t: 25\nmodel\t\t: 1\nmodel name\t: AMD EPYC 7B13\n\
                    flags\t\t: fpu avx2 fma\n";
        assert_eq!(cpu_details(zen3), ["family 25, model 1", "AVX2, FMA"]);
        assert_eq!(cpu_name(""), None);
        assert!(cpu_details("").is_empty());
    }

    #[test]
    fn the_description_leaves_out_empty_details_and_counts_threads() {
        assert_eq!(
            describe_machine(
                "AMD EPYC",
                "family 26, model 2; AVX-512, FMA",
                2,
                "linux x86_64"
            ),
            "AMD EPYC (family 26, model 2; AVX-512, FMA; 2 hardware threads, linux x86_64)"
        );
        assert_eq!(
            describe_machine("AMD EPYC 7B13", "", 1, "linux x86_64"),
            "AMD EPYC 7B13 (1 hardware thread, linux x86_64)"
        );
    }
}
