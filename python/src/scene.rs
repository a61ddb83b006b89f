//! `rtgi.Scene`: a scene loaded from a file (`rtgi.load`), the built-in
//! Cornell box, or made from arrays; what it holds, the structures built
//! over it, and the rays `rtgi rays` writes, as arrays.

use std::path::PathBuf;
use std::sync::Arc;

use numpy::{PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rtgi_job::{LoadedScene, SceneSource, Structure};
use rtgi_math::{NamedChoice, Ray, Vec3, parse_choice};
use rtgi_render::rays::{box_rays, primary_rays, surface_rays};
use rtgi_render::recipe::{self, CameraChoice};
use rtgi_scene::{LoadOptions, Material, MeshBuilder};

use crate::accel::Accel;
use crate::arrays::{rows3_array, rows3_f32, rows3_u32, vec3};
use crate::errors::{request, request_error, scene_error, to_python};

/// A scene: triangles (in file order, as hits name them), materials,
/// cameras and lights.
///
/// Made by `rtgi.load(path)`, `rtgi.cornell_box()` or
/// `rtgi.Scene.from_arrays(vertices, triangles)`; immutable, and shared
/// between threads.
#[pyclass(module = "rtgi", frozen)]
#[derive(Debug)]
pub struct Scene {
    pub(crate) loaded: Arc<LoadedScene>,
}

/// Loads a scene file (.obj, .gltf, .glb or .toml).
///
/// Files the scene references (materials, textures, buffers) must lie in
/// its folder unless `allow_outside` is true. `variant` picks a glTF
/// material variant by name. Raises `rtgi.SceneError` with the loader's
/// message (naming the file) if it cannot be loaded.
#[pyfunction]
#[pyo3(signature = (path, allow_outside = false, variant = None))]
pub fn load(py: Python<'_>, path: PathBuf, allow_outside: bool, variant: Option<String>) -> PyResult<Scene> {
    let options = LoadOptions { allow_outside_folder: allow_outside, gltf_variant: variant, ..LoadOptions::default() };
    let source = SceneSource::File { path, options };
    let loaded = py.detach(|| source.load()).map_err(scene_error)?;
    Ok(Scene { loaded: Arc::new(loaded) })
}

/// The Cornell box built into rtgi (what `rtgi render` renders without a scene).
#[pyfunction]
pub fn cornell_box() -> PyResult<Scene> {
    let loaded = SceneSource::BuiltIn.load().map_err(scene_error)?;
    Ok(Scene { loaded: Arc::new(loaded) })
}

impl Scene {
    /// The description `rtgi info --json` prints, as Python objects.
    fn description<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let description = rtgi_job::describe(&self.loaded, &rtgi_job::default_lighting(), &CameraChoice::default())
            .map_err(request)?;
        to_python(py, &description)
    }

    fn described<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        self.description(py)?.get_item(key)
    }
}

/// Parses a named choice given as a keyword argument: the library's names
/// ([`NamedChoice`]), the error naming the argument.
pub fn choice<T: NamedChoice>(argument: &str, name: &str) -> PyResult<T> {
    parse_choice::<T>(name).map_err(|e| request_error(argument, e))
}

#[pymethods]
impl Scene {
    /// A scene of one mesh: `vertices` (N×3 float32 positions) and
    /// `triangles` (M×3 uint32 indices into them), with one grey diffuse
    /// material. Other float and integer dtypes are converted; indices
    /// beyond the vertices raise `rtgi.RequestError`.
    #[staticmethod]
    #[pyo3(signature = (vertices, triangles, name = "arrays".to_owned()))]
    fn from_arrays(vertices: &Bound<'_, PyAny>, triangles: &Bound<'_, PyAny>, name: String) -> PyResult<Scene> {
        let positions = rows3_f32("vertices", vertices)?;
        let positions: Vec<Vec3> = positions.as_slice()?.chunks_exact(3).map(Vec3::from_slice).collect();
        let faces = rows3_u32("triangles", triangles)?;
        if let Some((row, &index)) = faces
            .iter()
            .enumerate()
            .find_map(|(row, f)| f.iter().find(|&&i| i as usize >= positions.len()).map(|i| (row, i)))
        {
            return Err(request_error(
                "triangles",
                format!("row {row} names vertex {index}, and there are {} vertices", positions.len()),
            ));
        }
        let mut scene = rtgi_scene::Scene {
            materials: vec![Material { name: "default".into(), ..Material::default() }],
            ..rtgi_scene::Scene::default()
        };
        let mut mesh = MeshBuilder::new(positions, Vec::new(), Vec::new());
        for face in faces {
            mesh.push(face, None, None, 0);
        }
        mesh.finish_into(&mut scene);
        Ok(Scene { loaded: Arc::new(LoadedScene { scene, name, load_ms: 0.0 }) })
    }

    /// The file's path, or the built-in scene's name.
    #[getter]
    fn name(&self) -> &str {
        &self.loaded.name
    }

    /// Triangles (hits name them by their index, in file order).
    #[getter]
    fn triangle_count(&self) -> usize {
        self.loaded.scene.triangles.len()
    }

    fn __len__(&self) -> usize {
        self.triangle_count()
    }

    /// Milliseconds the load took.
    #[getter]
    fn load_ms(&self) -> f64 {
        self.loaded.load_ms
    }

    /// The bounding box: a 2×3 float32 array, its smallest corner and its largest.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let bounds = self.loaded.scene.bounds();
        rows3_array(py, [bounds.min.to_array(), bounds.max.to_array()].concat())
    }

    /// Vertex positions: an N×3 float32 array (a vertex per distinct
    /// position, normal and texture coordinate).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        rows3_array(py, self.loaded.scene.vertices.iter().flat_map(|v| v.position.to_array()).collect())
    }

    /// The triangles' corners as indices into `vertices`: an M×3 uint32 array.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let indices: Vec<u32> = self.loaded.scene.triangles.iter().flat_map(|t| t.vertices).collect();
        let rows = indices.len() / 3;
        numpy::PyArray1::from_vec(py, indices).reshape([rows, 3])
    }

    /// Every material, as a dict (name, triangles, base colour, metalness, ...).
    #[getter]
    fn materials<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.described(py, "materials")
    }

    /// Every camera of the file, as a dict (position, direction, up, field of view, aspect).
    #[getter]
    fn cameras<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.described(py, "cameras")
    }

    /// Every light of the file, as a dict (name, kind, position, direction, colour, intensity).
    #[getter]
    fn lights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.described(py, "lights")
    }

    /// What the loader passed over.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.scene.warnings.clone()
    }

    /// Everything `rtgi info --json` says of the scene, as a dict.
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.description(py)
    }

    /// Builds an acceleration structure over the triangles.
    ///
    /// `accel` is any structure `rtgi --accel` takes (`rtgi.names("accel")`;
    /// `embree` in builds with it); the knobs are those of the command
    /// line, each `None` for the structure's own default. Raises
    /// `rtgi.RequestError` for an unknown name or a value out of range.
    #[pyo3(signature = (
        accel = "bvh8", *, leaf_size = None, sah_bins = None, sah_axes = None, traversal_cost = None,
        intersector = None, traversal = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn build(
        &self,
        py: Python<'_>,
        accel: &str,
        leaf_size: Option<u32>,
        sah_bins: Option<u32>,
        sah_axes: Option<&str>,
        traversal_cost: Option<f32>,
        intersector: Option<&str>,
        traversal: Option<&str>,
    ) -> PyResult<Accel> {
        let mut structure = Structure::of(accel.parse().map_err(|e| request_error("accel", e))?);
        structure.leaf_size = leaf_size;
        structure.traversal_cost = traversal_cost;
        if let Some(bins) = sah_bins {
            structure.sah_bins = bins;
        }
        if let Some(axes) = sah_axes {
            structure.sah_axes = choice("sah_axes", axes)?;
        }
        if let Some(name) = intersector {
            structure.intersector = choice("intersector", name)?;
        }
        if let Some(name) = traversal {
            structure.traversal = choice("traversal", name)?;
        }
        Accel::build(py, &self.loaded.scene.triangle_positions(), &structure)
    }

    /// Rays with origins uniform in the bounding box and directions
    /// uniform on the sphere (`rtgi rays --kind random`): `(origins,
    /// directions)`, two N×3 float32 arrays. The same seed gives the same rays.
    #[pyo3(signature = (count = 1_000_000, seed = 0))]
    fn box_rays<'py>(&self, py: Python<'py>, count: usize, seed: u64) -> PyResult<RayArrays<'py>> {
        let rays = py.detach(|| box_rays(&self.loaded.scene, count, seed));
        ray_arrays(py, &rays)
    }

    /// Rays leaving the surfaces (triangles chosen by area, origins lifted
    /// off them, directions uniform on the sphere; `rtgi rays --kind
    /// surface`): `(origins, directions)`, two N×3 float32 arrays.
    #[pyo3(signature = (count = 1_000_000, seed = 0))]
    fn surface_rays<'py>(&self, py: Python<'py>, count: usize, seed: u64) -> PyResult<RayArrays<'py>> {
        let rays = py.detach(|| surface_rays(&self.loaded.scene, count, seed));
        ray_arrays(py, &rays)
    }

    /// One ray through the centre of every pixel of the view `rtgi render`
    /// would use (`rtgi rays --kind camera`), in 4×4 tiles of pixels:
    /// `(origins, directions)`, two (width·height)×3 float32 arrays.
    ///
    /// `camera` picks a camera of the file; `at`, `look`, `up` and `fov`
    /// (degrees) override it. The automatic framing of a scene without a
    /// camera probes the scene through `accel` (a bvh8 is built when `None`).
    #[pyo3(signature = (width = 512, height = 512, *, accel = None, camera = None, at = None, look = None, up = None, fov = None))]
    #[allow(clippy::too_many_arguments)]
    fn camera_rays<'py>(
        &self,
        py: Python<'py>,
        width: u32,
        height: u32,
        accel: Option<&Accel>,
        camera: Option<usize>,
        at: Option<[f32; 3]>,
        look: Option<[f32; 3]>,
        up: Option<[f32; 3]>,
        fov: Option<f32>,
    ) -> PyResult<RayArrays<'py>> {
        for (argument, side) in [("width", width), ("height", height)] {
            if !(1..=rtgi_job::MAX_IMAGE_SIDE).contains(&side) {
                return Err(request_error(argument, format!("{side}: expected 1 to {}", rtgi_job::MAX_IMAGE_SIDE)));
            }
        }
        let choice = CameraChoice {
            index: camera,
            at: vec3("at", at)?,
            look: vec3("look", look)?,
            up: vec3("up", up)?,
            fov_degrees: fov,
        };
        let built;
        let accel: &dyn rtgi_accel::Accel = match accel {
            Some(accel) => accel.inner(),
            None => {
                built = Accel::build(py, &self.loaded.scene.triangle_positions(), &Structure::default())?;
                built.inner()
            }
        };
        let scene = &self.loaded.scene;
        let rays = py.detach(|| {
            let chosen = recipe::choose_camera(scene, accel, &choice, width as f32 / height as f32)?;
            Ok::<_, recipe::RecipeError>(primary_rays(&chosen.camera, width, height))
        });
        ray_arrays(py, &rays.map_err(request)?)
    }

    fn __repr__(&self) -> String {
        format!("<rtgi.Scene {:?}: {} triangles>", self.loaded.name, self.loaded.scene.triangles.len())
    }
}

/// Origins and directions, each an N×3 float32 array.
type RayArrays<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<f32>>);

fn ray_arrays<'py>(py: Python<'py>, rays: &[Ray]) -> PyResult<RayArrays<'py>> {
    let origins = rays.iter().flat_map(|r| r.origin.to_array()).collect();
    let directions = rays.iter().flat_map(|r| r.direction.to_array()).collect();
    Ok((rows3_array(py, origins)?, rows3_array(py, directions)?))
}

/// Keyword arguments as a dict, for functions that take many.
pub fn kwargs_or_empty<'py>(py: Python<'py>, kwargs: Option<&Bound<'py, PyDict>>) -> Bound<'py, PyDict> {
    kwargs.cloned().unwrap_or_else(|| PyDict::new(py))
}
