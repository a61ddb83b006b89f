//! Where the files a scene references come from, and the containment rule.
//!
//! A scene file names other files: OBJ its MTL libraries and textures, glTF
//! its buffers and images, a TOML description its meshes. By default they
//! are read only from inside the folder of the scene file that was opened:
//! a reference is resolved, canonicalized (following symbolic links) and
//! refused unless the result lies under that folder's canonical path, so a
//! hostile scene cannot make rtgi read `../../etc/passwd` as a texture.
//! [`LoadOptions::allow_outside_folder`] lifts the rule for trusted scenes.

use std::path::{Component, Path, PathBuf};

use crate::resolve_case_insensitive;

/// Reads the file a scene references, by the name the scene gives it, for
/// scenes loaded from memory ([`Scene::load_from_bytes`](crate::Scene::load_from_bytes));
/// `None` if there is no such file.
pub type FileReader<'a> = dyn Fn(&str) -> Option<Vec<u8>> + Sync + 'a;

/// How a scene is loaded; [`LoadOptions::default`] is the safe choice.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Lets references (OBJ `mtllib` and texture paths, glTF buffer and image
    /// URIs, meshes of a TOML description) reach files outside the folder of
    /// the scene file: `../` paths, absolute paths and symbolic links that
    /// point elsewhere. Off by default; only for scenes you trust.
    pub allow_outside_folder: bool,
    /// The most triangles a scene may have; glTF files that instance large
    /// meshes many times are refused before their triangles are built.
    pub max_triangles: usize,
    /// The glTF material variant (KHR_materials_variants) to render, by
    /// name; `None` renders each primitive's default material.
    pub gltf_variant: Option<String>,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self { allow_outside_folder: false, max_triangles: DEFAULT_MAX_TRIANGLES, gltf_variant: None }
    }
}

/// The default of [`LoadOptions::max_triangles`]: 2^27, about 134 million
/// (400 times the conference room; at 16 bytes a triangle and more for its
/// vertices, several gigabytes).
pub const DEFAULT_MAX_TRIANGLES: usize = 1 << 27;

/// How deeply scene descriptions may include one another (a description
/// that lists itself would otherwise recurse until the stack overflows).
pub(crate) const MAX_NESTING: u32 = 8;

/// The files one scene file may read, and the files read so far.
pub(crate) struct Files<'a> {
    place: Place<'a>,
    pub(crate) options: LoadOptions,
    /// How many descriptions include this file.
    pub(crate) depth: u32,
}

enum Place<'a> {
    /// References resolve against `base` (the scene file's folder); unless
    /// `root` is `None`, the result must lie under `root` (the canonical
    /// folder of the scene file that was opened first).
    Disk {
        base: PathBuf,
        root: Option<PathBuf>,
    },
    Memory(&'a FileReader<'a>),
}

/// A file read for a scene: its bytes and the name it goes by (its
/// canonical path on disk, or the reference in memory).
pub(crate) struct ReadFile {
    pub(crate) bytes: Vec<u8>,
    pub(crate) path: PathBuf,
}

impl<'a> Files<'a> {
    /// The files beside the scene file `path` (whose canonical form is `canonical`).
    pub(crate) fn disk(path: &Path, canonical: &Path, options: &LoadOptions) -> Self {
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let root =
            (!options.allow_outside_folder).then(|| canonical.parent().map(Path::to_path_buf).unwrap_or_default());
        Self { place: Place::Disk { base, root }, options: options.clone(), depth: 0 }
    }

    pub(crate) fn memory(read: &'a FileReader<'a>, options: &LoadOptions) -> Self {
        Self { place: Place::Memory(read), options: options.clone(), depth: 0 }
    }

    /// The files of a scene file that this one references (a description's
    /// mesh): relative to that file's folder, but contained in the same root.
    pub(crate) fn nested(&self, file: &ReadFile) -> Files<'a> {
        let place = match &self.place {
            Place::Disk { root, .. } => {
                Place::Disk { base: file.path.parent().map(Path::to_path_buf).unwrap_or_default(), root: root.clone() }
            }
            Place::Memory(read) => Place::Memory(*read),
        };
        Files { place, options: self.options.clone(), depth: self.depth + 1 }
    }

    /// Reads the file `reference` names, or says why not (naming the
    /// reference). Letter case may differ from the file's on disk.
    pub(crate) fn read(&self, reference: &str) -> Result<ReadFile, String> {
        match &self.place {
            Place::Memory(read) => read(reference)
                .map(|bytes| ReadFile { bytes, path: PathBuf::from(reference) })
                .ok_or_else(|| format!("'{reference}' not found")),
            Place::Disk { base, root } => {
                let path = self.locate(base, root.as_deref(), reference)?;
                let bytes = std::fs::read(&path).map_err(|e| format!("'{reference}': {}: {e}", path.display()))?;
                Ok(ReadFile { bytes, path })
            }
        }
    }

    /// The canonical path of the file `reference` names, if it may be read.
    fn locate(&self, base: &Path, root: Option<&Path>, reference: &str) -> Result<PathBuf, String> {
        let normalized = reference.replace('\\', "/");
        let relative = Path::new(&normalized);
        let absolute = relative.has_root() || relative.components().any(|c| matches!(c, Component::Prefix(_)));
        let found = if absolute {
            if root.is_some() {
                return Err(format!(
                    "refusing '{reference}': absolute paths are not read (the scene may only read inside its folder)"
                ));
            }
            relative.is_file().then(|| relative.to_path_buf())
        } else {
            resolve_case_insensitive(base, &normalized)
        };
        let found = found.ok_or_else(|| format!("'{reference}' not found"))?;
        let canonical = found.canonicalize().map_err(|e| format!("'{reference}': {}: {e}", found.display()))?;
        if let Some(root) = root
            && !canonical.starts_with(root)
        {
            return Err(format!(
                "refusing '{reference}': it leaves the scene's folder {} (it is {})",
                root.display(),
                canonical.display()
            ));
        }
        Ok(canonical)
    }
}
