//! The scene model of rtgi and its importers.
//!
//! A [`Scene`] is every mesh of a file merged into one set of triangles.
//! Each [`Triangle`] names its three [`Vertex`]es (position, normal, texture
//! coordinates) and its [`Material`]; triangles keep the order of the file,
//! so a triangle can be named by its index (an OBJ polygon becomes a fan of
//! triangles, in order). Textures are decoded at load time.
//!
//! Importers: Wavefront OBJ with MTL materials (through `tobj`), glTF 2.0
//! (`.gltf` and `.glb`, through `gltf`), and a small TOML scene description
//! that lists meshes and a camera (see [`description`]).
//!
//! ```no_run
//! let scene = rtgi_scene::Scene::load("scenes/cornell-box.toml".as_ref())?;
//! println!("{} triangles, {} materials", scene.triangles.len(), scene.materials.len());
//! for warning in &scene.warnings {
//!     eprintln!("warning: {warning}");
//! }
//! # Ok::<(), rtgi_scene::SceneError>(())
//! ```

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod camera;
pub mod description;
mod files;
pub use files::{DEFAULT_MAX_TRIANGLES, FileReader, LoadOptions};
mod gltf_accessor;
mod gltf_extensions;
mod gltf_import;
mod gltf_material;
pub use gltf_extensions::{ExtensionSupport, GLTF_EXTENSIONS, gltf_extension_support, supported_gltf_extensions};
mod light;
mod material;
mod material_layers;
mod mesh;
mod mtl;
pub mod obj;
mod resolve;
mod texel_range;
mod texture;

pub use camera::Camera;
pub use light::{Light, LightKind, LightSpecError};
pub use material::{AlphaMode, Material, SurfaceModel};
pub use material_layers::{Anisotropy, Clearcoat, DielectricSpecular, Iridescence, Sheen, Volume};
pub use mesh::MeshBuilder;
pub use resolve::resolve_case_insensitive;
pub use texture::{ColorEncoding, MAX_TEXTURE_BYTES, MAX_TEXTURE_SIDE, Texture, TextureId, UvMap, Wrap};

use std::path::{Path, PathBuf};

use rtgi_math::{Aabb, Vec2, Vec3, Vec4};

/// A vertex as triangles reference it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    /// Position in world space.
    pub position: Vec3,
    /// Unit shading normal (computed from the faces where the file has none).
    pub normal: Vec3,
    /// Texture coordinates with the origin at the top left of the image (OBJ's
    /// bottom-left `v` is flipped on import).
    pub uv: Vec2,
    /// The second set of texture coordinates (glTF's `TEXCOORD_1`), for
    /// textures whose [`UvMap`] reads set 1; zero where the file has none.
    pub uv1: Vec2,
    /// The vertex colour (glTF's `COLOR_0`, linear RGBA), which multiplies
    /// the base colour; white where the file has none.
    pub color: Vec4,
    /// Unit tangent along increasing u, perpendicular to the normal, for
    /// normal maps; `w` (±1) gives the bitangent: `cross(normal, tangent) * w`.
    /// From the file where it has them, else computed from the texture
    /// coordinates (Lengyel, "Computing Tangent Space Basis Vectors", 2001).
    pub tangent: Vec4,
}

/// A triangle: indices into [`Scene::vertices`] and [`Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Triangle {
    /// Indices into [`Scene::vertices`] of the three corners, in the file's winding order.
    pub vertices: [u32; 3],
    /// Index into [`Scene::materials`].
    pub material: u32,
}

/// Everything a renderer needs to know about a scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Every vertex of every mesh, transformed to world space.
    pub vertices: Vec<Vertex>,
    /// Every triangle, in file order: accelerators and outputs name triangles by their index here.
    pub triangles: Vec<Triangle>,
    /// The materials, indexed by [`Triangle::material`].
    pub materials: Vec<Material>,
    /// Decoded textures, referred to by [`TextureId`] from the materials.
    pub textures: Vec<Texture>,
    /// The cameras the file defines, in file order (none for OBJ files).
    pub cameras: Vec<Camera>,
    /// Point, spot and directional lights (emissive surfaces are materials).
    pub lights: Vec<Light>,
    /// The format extensions the file uses (glTF's `extensionsUsed`).
    pub extensions_used: Vec<String>,
    /// The names of the file's material variants (glTF's
    /// KHR_materials_variants), of which [`LoadOptions::gltf_variant`] chose one.
    pub material_variants: Vec<String>,
    /// The up direction the file's format fixes: +Y for glTF, whose
    /// specification makes +Y up. `None` where the format has no
    /// convention (OBJ), so that a renderer may judge it from the model.
    pub up: Option<Vec3>,
    /// Problems that did not stop the import (a missing texture, an unknown
    /// material, an MTL statement that could not be read, a reference
    /// refused because it leads outside the scene's folder).
    pub warnings: Vec<String>,
    /// Every file the load read, in the order read: the scene file, MTL
    /// libraries, textures, glTF buffers and images, the meshes of a
    /// description. Canonical paths for scenes loaded from disk; the names
    /// given to the [`FileReader`] for scenes loaded from memory.
    pub sources: Vec<PathBuf>,
}

/// Why a scene could not be loaded; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file (the scene or one it references) could not be read.
    #[error("{path}: cannot read: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The OBJ file (or one of its MTL libraries) is malformed or refused.
    #[error("{path}: not a valid OBJ file: {message}")]
    Obj {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the line or the reference where known.
        message: String,
    },
    /// The TOML scene description is malformed or names unusable meshes.
    #[error("{path}: not a valid scene description: {message}")]
    Description {
        /// The description file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The glTF file, its buffers or its images are malformed or refused.
    #[error("{path}: not a valid glTF file: {message}")]
    Gltf {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the accessor, node or image where known.
        message: String,
    },
    /// The glTF file requires an extension rtgi does not support: the file
    /// may be valid, but rtgi cannot render it.
    #[error(
        "{path} uses {extension}, which rtgi does not support (without it, {lacks}); it supports: {}",
        supported_gltf_extensions().collect::<Vec<_>>().join(", ")
    )]
    UnsupportedGltfExtension {
        /// The file.
        path: PathBuf,
        /// The extension the file lists in `extensionsRequired`.
        extension: String,
        /// What rendering without it would lose.
        lacks: &'static str,
    },
    /// The material variant asked for ([`LoadOptions::gltf_variant`]) is
    /// not one of the file's.
    #[error(
        "{path} has no material variant '{variant}' ({})",
        if variants.is_empty() { "it has none".to_owned() } else { format!("its variants: {}", variants.join(", ")) }
    )]
    UnknownMaterialVariant {
        /// The file.
        path: PathBuf,
        /// The name asked for.
        variant: String,
        /// The file's variants (KHR_materials_variants), in its order.
        variants: Vec<String>,
    },
    /// The file's extension is none of `.obj`, `.gltf`, `.glb`, `.toml`.
    #[error("{path}: unsupported scene format (expected .obj, .gltf, .glb or .toml)")]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
}

impl Scene {
    /// Loads a scene, choosing the importer by the file's extension, with
    /// the default [`LoadOptions`]: the files the scene references are read
    /// only from inside the scene file's folder.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Self::load_with(path, &LoadOptions::default())
    }

    /// Loads a scene with the given options.
    pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
        let io_error = |source| SceneError::Io { path: path.to_owned(), source };
        if !path.is_file() {
            let source = if path.exists() {
                std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file")
            } else {
                std::io::Error::new(std::io::ErrorKind::NotFound, "no such file")
            };
            return Err(io_error(source));
        }
        Self::check_format(path)?;
        let canonical = path.canonicalize().map_err(io_error)?;
        let bytes = std::fs::read(path).map_err(io_error)?;
        let files = files::Files::disk(path, &canonical, options);
        let mut sources = vec![canonical];
        let mut scene = Self::load_read(&bytes, path, &files, &mut sources)?;
        scene.sources = sources;
        Ok(scene)
    }

    /// Loads a scene from bytes in memory: `name` gives the format by its
    /// extension (`.obj`, `.gltf`, `.glb`, `.toml`) and names the scene in
    /// messages, and the files the scene references (MTL libraries,
    /// textures, buffers, images, meshes) are asked of `read` by the name
    /// the scene gives them. Nothing is read from disk.
    ///
    /// ```
    /// let obj = b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    /// let read = |name: &str| (name == "m.mtl").then(|| b"newmtl red\nKd 1 0 0\n".to_vec());
    /// let scene = rtgi_scene::Scene::load_from_bytes("tri.obj", obj, &read)?;
    /// assert_eq!(scene.materials[0].name, "red");
    /// # Ok::<(), rtgi_scene::SceneError>(())
    /// ```
    pub fn load_from_bytes(name: &str, bytes: &[u8], read: &FileReader<'_>) -> Result<Scene, SceneError> {
        let path = Path::new(name);
        Self::check_format(path)?;
        let files = files::Files::memory(read, &LoadOptions::default());
        let mut sources = vec![path.to_owned()];
        let mut scene = Self::load_read(bytes, path, &files, &mut sources)?;
        scene.sources = sources;
        Ok(scene)
    }

    fn check_format(path: &Path) -> Result<(), SceneError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("obj" | "toml" | "gltf" | "glb") => Ok(()),
            _ => Err(SceneError::UnsupportedFormat { path: path.to_owned() }),
        }
    }

    /// Imports a scene file already read, by its extension.
    fn load_read(
        bytes: &[u8],
        path: &Path,
        files: &files::Files<'_>,
        sources: &mut Vec<PathBuf>,
    ) -> Result<Scene, SceneError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("obj") => obj::load(bytes, path, files, sources),
            Some("toml") => description::load(bytes, path, files, sources),
            Some("gltf") | Some("glb") => gltf_import::load(bytes, path, files, sources),
            _ => Err(SceneError::UnsupportedFormat { path: path.to_owned() }),
        }
    }

    /// The corner positions of every triangle, in triangle order: what an
    /// acceleration structure is built from.
    pub fn triangle_positions(&self) -> Vec<[Vec3; 3]> {
        self.triangles.iter().map(|t| t.vertices.map(|v| self.vertices[v as usize].position)).collect()
    }

    /// The box around all finite vertex positions used by triangles.
    pub fn bounds(&self) -> Aabb {
        self.triangles
            .iter()
            .flat_map(|t| t.vertices)
            .map(|v| self.vertices[v as usize].position)
            .filter(|p| p.is_finite())
            .fold(Aabb::EMPTY, |b, p| b.grow(p))
    }

    /// Appends `other`, renumbering its vertices, materials and textures.
    /// The result keeps an up direction only where both had the same one
    /// (or this scene was empty).
    pub fn append(&mut self, other: Scene) {
        let empty = self.vertices.is_empty() && self.triangles.is_empty();
        self.up = if empty || self.up == other.up { other.up } else { None };
        let vertex_base = self.vertices.len() as u32;
        let material_base = self.materials.len() as u32;
        let texture_base = self.textures.len() as u32;
        self.vertices.extend(other.vertices);
        self.triangles.extend(
            other.triangles.into_iter().map(|t| Triangle {
                vertices: t.vertices.map(|v| v + vertex_base),
                material: t.material + material_base,
            }),
        );
        self.materials.extend(other.materials.into_iter().map(|mut m| {
            m.offset_textures(texture_base);
            m
        }));
        self.textures.extend(other.textures);
        self.cameras.extend(other.cameras);
        self.lights.extend(other.lights);
        self.extensions_used.extend(other.extensions_used);
        self.material_variants.extend(other.material_variants);
        self.warnings.extend(other.warnings);
        self.sources.extend(other.sources);
    }

    /// Both texture coordinate sets at barycentric coordinates `(beta,
    /// gamma)`, for [`Texture::lookup`].
    #[inline]
    pub fn texture_coords(&self, triangle: &Triangle, beta: f32, gamma: f32) -> [Vec2; 2] {
        let [a, b, c] = triangle.vertices.map(|v| &self.vertices[v as usize]);
        let alpha = 1.0 - beta - gamma;
        [a.uv * alpha + b.uv * beta + c.uv * gamma, a.uv1 * alpha + b.uv1 * beta + c.uv1 * gamma]
    }

    /// Interpolates a vertex attribute at barycentric coordinates `(beta, gamma)`.
    #[inline]
    pub fn interpolate<T>(&self, triangle: &Triangle, beta: f32, gamma: f32, attribute: impl Fn(&Vertex) -> T) -> T
    where
        T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
    {
        let [a, b, c] = triangle.vertices.map(|v| attribute(&self.vertices[v as usize]));
        a * (1.0 - beta - gamma) + b * beta + c * gamma
    }
}
