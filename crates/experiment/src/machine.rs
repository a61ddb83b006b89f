//! The machine an experiment ran on, recorded beside its measurements.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
/// The machine an experiment ran on, recorded with its numbers.
pub struct Machine {
    /// The CPU's model name, as the operating system reports it.
    pub cpu: String,
    /// The CPU's identity beyond its name, which a virtual machine often
    /// makes generic ("Intel Xeon Processor"): vendor, family, model and
    /// stepping, microcode and cache, as `/proc/cpuinfo` gives them.
    #[serde(default)]
    pub cpu_id: String,
    /// Logical cores the operating system offers this process.
    pub cores: usize,
    /// Worker threads the experiment used.
    pub threads: usize,
    /// The widest SIMD level the acceleration structures run at.
    pub simd: String,
    /// The operating system, as Rust names it (`linux`, `macos`, `windows`).
    pub os: String,
}

impl Machine {
    /// This machine, with `threads` worker threads.
    pub fn this(threads: usize) -> Machine {
        Machine {
            cpu: cpu_model().unwrap_or_else(|| std::env::consts::ARCH.to_owned()),
            cpu_id: cpu_id().unwrap_or_default(),
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            threads,
            simd: rtgi_accel::simd::active_simd_level().name().to_owned(),
            os: std::env::consts::OS.to_owned(),
        }
    }

    /// A short description for plot titles: "Intel Xeon, 2 threads".
    pub fn short(&self) -> String {
        let cpu = self.cpu.replace("(R)", "").replace("(TM)", "").replace(" Processor", "").replace(" CPU", "");
        let cpu = cpu.split(" @ ").next().unwrap_or(&cpu).split_whitespace().collect::<Vec<_>>().join(" ");
        format!("{cpu}, {} thread{}", self.threads, if self.threads == 1 { "" } else { "s" })
    }
}

/// "GenuineIntel family 6 model 106 stepping 6, microcode 0x1, cache 16384 KB"
/// from the first processor of `/proc/cpuinfo` (Linux); `None` elsewhere.
fn cpu_id() -> Option<String> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    let field = |name: &str| {
        info.lines()
            .find(|line| line.split(':').next().is_some_and(|key| key.trim() == name))
            .and_then(|line| line.split_once(':'))
            .map(|(_, value)| value.trim().to_owned())
            .unwrap_or_else(|| "?".to_owned())
    };
    Some(format!(
        "{} family {} model {} stepping {}, microcode {}, cache {}",
        field("vendor_id"),
        field("cpu family"),
        field("model"),
        field("stepping"),
        field("microcode"),
        field("cache size")
    ))
}

/// The model name from `/proc/cpuinfo` (Linux); `None` elsewhere.
fn cpu_model() -> Option<String> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    info.lines()
        .find(|line| line.starts_with("model name"))
        .and_then(|line| line.split_once(':'))
        .map(|(_, name)| name.trim().to_owned())
}
