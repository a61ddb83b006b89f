//! The workspace around the code: deployment scripts (on a real Slurm),
//! the experiments and their report, the generated docs' tables, and a
//! build that does nothing when nothing changed.
//!
//! One test binary for the theme, a module a file.

mod cli_reference;
mod counters_doc;
mod deploy;
mod experiment;
mod experiment_index;
mod gltf_extensions_doc;
mod import_cycles;
mod library_errors;
mod noop_build;
mod release_profiles_doc;
mod slurm_cluster;
mod targets_doc;
