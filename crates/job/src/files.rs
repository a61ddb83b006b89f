//! Checks on the files a render writes, made before long work: that they
//! can be written, and that none of them is a file the render reads.

use std::path::{Path, PathBuf};

use crate::error::{Field, JobError};

/// Checks that `path` can be created, before long work whose result goes there.
pub fn check_output_folder(path: &Path, field: Field) -> Result<(), JobError> {
    let unwritable = |why: String| JobError::Unwritable { field, path: path.to_owned(), why };
    if path.is_dir() {
        return Err(unwritable("is a directory".into()));
    }
    if let Some(why) = rtgi_image::unusable_folder(path) {
        return Err(unwritable(why));
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let probe = path.with_file_name(format!(".{name}.{}.probe", std::process::id()));
    std::fs::File::create(&probe).map_err(|e| unwritable(e.to_string()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Whether `a` and `b` name the same file, following links; a file that
/// does not exist yet is compared by its folder and name.
pub fn same_file(a: &Path, b: &Path) -> bool {
    fn canonical(path: &Path) -> Option<PathBuf> {
        if let Ok(path) = path.canonicalize() {
            return Some(path);
        }
        let folder = match path.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent.canonicalize().ok()?,
            _ => std::env::current_dir().ok()?,
        };
        Some(folder.join(path.file_name()?))
    }
    match (canonical(a), canonical(b)) {
        (Some(a), Some(b)) => a == b,
        _ => a == b,
    }
}

/// Refuses to write over a file the render reads: an output named like
/// the scene, a texture or the environment map would destroy it.
/// `inputs` are each described for the message (`the scene`, ...).
pub(crate) fn refuse_inputs_as_outputs(outputs: &[(Field, &Path)], inputs: &[(String, &Path)]) -> Result<(), JobError> {
    for &(field, output) in outputs {
        if let Some((what, _)) = inputs.iter().find(|(_, input)| same_file(output, input)) {
            return Err(JobError::InputAsOutput { field, path: output.to_owned(), what: what.clone() });
        }
    }
    Ok(())
}
