//! The machine an experiment ran on, recorded beside its measurements.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
/// The machine an experiment ran on, recorded with its numbers.
pub struct Machine {
    /// The CPU's model name, as the operating system reports it.
    pub cpu: String,
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

/// The model name from `/proc/cpuinfo` (Linux); `None` elsewhere.
fn cpu_model() -> Option<String> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    info.lines()
        .find(|line| line.starts_with("model name"))
        .and_then(|line| line.split_once(':'))
        .map(|(_, name)| name.trim().to_owned())
}
