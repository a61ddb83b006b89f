//! Which code measured: recorded in every report so that a figure can be
//! traced to the commit, compiler and flags that produced it, and so that
//! an index refuses to put figures of different programs side by side.

use serde::{Deserialize, Serialize};

/// The program an experiment ran: its version, the git commit it was built
/// from and whether the sources differed from it, the compiler, profile and flags.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Build {
    /// The crate's version.
    pub version: String,
    /// The git commit of the workspace at build time (`unknown` outside git).
    pub commit: String,
    /// A hash of the uncommitted changes to the sources (crates, apps,
    /// scenes, Cargo files) at build time; `None` for a clean tree.
    pub dirty: Option<String>,
    /// `rustc -V` of the compiler.
    pub rustc: String,
    /// Cargo's profile (`release`, `debug`) and its optimisation level.
    pub profile: String,
    /// The optimisation level.
    pub opt_level: String,
    /// Extra flags given to rustc (`RUSTFLAGS`), empty for none.
    pub rustflags: String,
    /// The target features the code was compiled for (SIMD beyond them is chosen at run time).
    pub target_features: String,
    /// The peer libraries built in, with their versions and build quality
    /// (`rtgi_accel::peer_libraries`).
    #[serde(default)]
    pub peers: Vec<String>,
}

impl Build {
    /// The build of this program, as its build script recorded it.
    pub fn this() -> Build {
        let dirty = env!("RTGI_BUILD_DIRTY");
        Build {
            version: env!("CARGO_PKG_VERSION").to_owned(),
            commit: env!("RTGI_BUILD_COMMIT").to_owned(),
            dirty: (!dirty.is_empty()).then(|| dirty.to_owned()),
            rustc: env!("RTGI_BUILD_RUSTC").to_owned(),
            profile: env!("RTGI_BUILD_PROFILE").to_owned(),
            opt_level: env!("RTGI_BUILD_OPT_LEVEL").to_owned(),
            rustflags: env!("RTGI_BUILD_RUSTFLAGS").to_owned(),
            target_features: env!("RTGI_BUILD_TARGET_FEATURES").to_owned(),
            peers: rtgi_accel::peer_libraries(),
        }
    }

    /// The code's identity in one word: the commit, with `+dirty-HASH` when
    /// the sources differed from it. References are cached under it.
    pub fn code_version(&self) -> String {
        match &self.dirty {
            Some(hash) => format!("{}+dirty-{hash}", self.commit),
            None => self.commit.clone(),
        }
    }

    /// The commit's first 10 digits, with `+dirty` where it applies: for prose.
    pub fn short(&self) -> String {
        let commit = &self.commit[..self.commit.len().min(10)];
        if self.dirty.is_some() { format!("{commit}+dirty") } else { commit.to_owned() }
    }
}

/// The current time in UTC as `YYYY-MM-DDTHH:MM:SSZ`.
pub fn utc_now() -> String {
    let seconds = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    utc_date(seconds)
}

/// Seconds since 1970 as a UTC date and time (the proleptic Gregorian
/// calendar, by Howard Hinnant's days-to-civil algorithm).
fn utc_date(seconds: u64) -> String {
    let days = (seconds / 86_400) as i64;
    let time = seconds % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z.rem_euclid(146_097);
    let year_of_era = (day_of_era - day_of_era / 1_460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let month_index = (5 * day_of_year + 2) / 153;
    let day = day_of_year - (153 * month_index + 2) / 5 + 1;
    let month = if month_index < 10 { month_index + 3 } else { month_index - 9 };
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z", time / 3600, time / 60 % 60, time % 60)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_are_utc_calendar_dates() {
        assert_eq!(utc_date(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_date(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_date(1_795_559_045), "2026-11-24T22:24:05Z");
        assert_eq!(utc_date(4_107_542_399), "2100-02-28T23:59:59Z");
    }

    #[test]
    fn the_build_names_a_commit() {
        let build = Build::this();
        assert!(!build.commit.is_empty() && !build.rustc.is_empty(), "{build:?}");
        assert!(build.code_version().starts_with(&build.commit));
    }
}
