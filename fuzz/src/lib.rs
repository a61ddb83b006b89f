//! What the fuzz targets share: the files a fuzzed scene may reference,
//! the same as the test corpus's (`tests/src/corpus/referenced_files.rs`,
//! included here so that the two cannot drift apart).

#[path = "../../tests/src/corpus/referenced_files.rs"]
mod referenced_files;
pub use referenced_files::*;
