use std::path::{Component, Path, PathBuf};

/// Finds the file that `relative` names inside `base`, matching each path
/// component without regard to letter case when no exact match exists.
///
/// Scenes authored on case-insensitive file systems often name their
/// textures in a case that differs from the files (the Dabrovic Sponza's
/// MTL says `00_SKAP.JPG` for `00_skap.JPG`). Backslashes are read as
/// separators, as Windows-authored MTL files use them.
pub fn resolve_case_insensitive(base: &Path, relative: &str) -> Option<PathBuf> {
    let relative = relative.replace('\\', "/");
    if Path::new(&relative).has_root() {
        return None;
    }
    let exact = base.join(&relative);
    if exact.is_file() {
        return Some(exact);
    }
    let mut current = base.to_path_buf();
    for component in Path::new(&relative).components() {
        match component {
            Component::Normal(name) => {
                let candidate = current.join(name);
                if candidate.exists() {
                    current = candidate;
                    continue;
                }
                let wanted = name.to_string_lossy().to_lowercase();
                let found = std::fs::read_dir(&current)
                    .ok()?
                    .filter_map(Result::ok)
                    .map(|entry| entry.file_name())
                    .filter(|entry| entry.to_string_lossy().to_lowercase() == wanted)
                    .min()?;
                current = current.join(found);
            }
            Component::CurDir => {}
            Component::ParentDir => current = current.join(".."),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    current.is_file().then_some(current)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_files_whose_names_differ_in_case() {
        let temporary = tempfile::tempdir().unwrap();
        let dir = temporary.path().to_path_buf();
        std::fs::create_dir_all(dir.join("Sub")).unwrap();
        std::fs::write(dir.join("Sub").join("tex.JPG"), b"x").unwrap();
        assert_eq!(resolve_case_insensitive(&dir, "sub/TEX.jpg"), Some(dir.join("Sub").join("tex.JPG")));
        assert_eq!(resolve_case_insensitive(&dir, "Sub\\tex.JPG"), Some(dir.join("Sub/tex.JPG")));
        assert_eq!(resolve_case_insensitive(&dir, "sub/other.jpg"), None);
        assert_eq!(resolve_case_insensitive(&dir, "/etc/passwd"), None);
    }
}
