//! Light sources and how to sample them: punctual lights (point, spot,
//! directional), emissive triangles as area lights, and the environment.
//!
//! Radiometric conventions: glTF's candela and lux are read as watts per
//! steradian and watts per square metre (the renderer has no photometric
//! curve), emitted radiance comes from materials, and the environment gives
//! the radiance arriving from each direction.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use rtgi_image::{HdrImage, ImageError};
use rtgi_math::glam::Quat;
use rtgi_math::{Ray, SurfacePoint, TriangleShape, Vec2, Vec3, luminance, parse_vec3};
use rtgi_scene::{Light, LightKind, Scene, SurfaceModel, TextureId};

use crate::distribution::Distribution1D;

/// Radiance arriving from infinitely far away, in every direction that
/// hits nothing.
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// The same radiance from every direction.
    Uniform(Vec3),
    /// An equirectangular (latitude-longitude) image, importance-sampled.
    Map(EnvironmentMap),
}

/// An equirectangular environment: +Y is up, the image's top row is the
/// zenith, and its centre column looks along -Z (the default camera's view),
/// unless it is turned ([`EnvironmentMap::turned`]: the default sky of a
/// +Z-up model). Texels are constant over their solid angle (no
/// filtering), which is what makes the sampling density exact.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    image: HdrImage,
    /// From the map's +Y-up frame to the world's.
    turn: Quat,
    /// Chooses a row by its total brightness (weighted by its solid angle).
    rows: Distribution1D,
    /// Chooses a column within each row.
    columns: Vec<Distribution1D>,
}

/// An environment as a specification string names it (the `rtgi`
/// command's `--environment`), before any file is read: a uniform radiance
/// `R,G,B` or the path of an equirectangular `.exr` image (or a `.floats`
/// sky of the course framework).
///
/// ```
/// use rtgi_render::EnvironmentSpec;
/// use rtgi_math::Vec3;
///
/// assert_eq!("0.5,0.6,0.7".parse::<EnvironmentSpec>()?, EnvironmentSpec::Uniform(Vec3::new(0.5, 0.6, 0.7)));
/// assert_eq!("sky.exr".parse::<EnvironmentSpec>()?, EnvironmentSpec::File("sky.exr".into()));
/// assert!("sky.hdr".parse::<EnvironmentSpec>().is_err());
/// # Ok::<(), rtgi_render::EnvironmentSpecError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSpec {
    /// The same radiance from every direction: finite, not negative.
    Uniform(Vec3),
    /// An OpenEXR file, to be read by [`EnvironmentSpec::load`].
    File(PathBuf),
}

/// Why an environment specification could not be used.
#[derive(Debug, thiserror::Error)]
pub enum EnvironmentSpecError {
    /// A radiance with a negative component.
    #[error("environment radiance must not be negative (got '{0}')")]
    NegativeRadiance(String),
    /// Neither three numbers nor a path ending in `.exr` or `.floats`.
    #[error("expected a radiance R,G,B or an .exr or .floats file (got '{0}')")]
    Unrecognised(String),
    /// The `.exr` file could not be read or is no environment map.
    #[error(transparent)]
    Image(#[from] ImageError),
}

impl FromStr for EnvironmentSpec {
    type Err = EnvironmentSpecError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        if let Some(radiance) = parse_vec3(text) {
            if radiance.min_element() < 0.0 {
                return Err(EnvironmentSpecError::NegativeRadiance(text.to_owned()));
            }
            return Ok(EnvironmentSpec::Uniform(radiance));
        }
        let path = PathBuf::from(text);
        if has_extension(&path, "exr") || has_extension(&path, "floats") {
            Ok(EnvironmentSpec::File(path))
        } else {
            Err(EnvironmentSpecError::Unrecognised(text.to_owned()))
        }
    }
}

impl EnvironmentSpec {
    /// The environment it names, reading the file of a map.
    pub fn load(&self) -> Result<Environment, ImageError> {
        match self {
            EnvironmentSpec::Uniform(radiance) => Ok(Environment::Uniform(*radiance)),
            EnvironmentSpec::File(path) => Environment::load(path),
        }
    }
}

impl Environment {
    /// The environment a specification names (see [`EnvironmentSpec`]): a
    /// uniform radiance `R,G,B`, or an `.exr` or `.floats` file, which is read.
    pub fn from_spec(text: &str) -> Result<Self, EnvironmentSpecError> {
        Ok(text.parse::<EnvironmentSpec>()?.load()?)
    }

    /// Reads an equirectangular environment from an OpenEXR file, or from
    /// a `.floats` sky of the course framework ([`HdrImage::read_floats`]).
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let image = if has_extension(path, "floats") {
            from_course_longitudes(HdrImage::read_floats(path)?)
        } else {
            HdrImage::read_exr(path)?
        };
        if image.width() < 2 || image.height() < 1 {
            return Err(ImageError::Read {
                path: path.to_owned(),
                message: "an environment map needs at least 2×1 pixels".into(),
            });
        }
        if image.pixels().iter().any(|p| !p.is_finite() || p.min_element() < 0.0) {
            return Err(ImageError::Read {
                path: path.to_owned(),
                message: "an environment map must hold finite, non-negative radiance".into(),
            });
        }
        Ok(Environment::Map(EnvironmentMap::new(image)))
    }

    /// This environment with its radiance multiplied by `scale` (≥ 0).
    pub fn scaled(self, scale: f32) -> Self {
        match self {
            Environment::Uniform(radiance) => Environment::Uniform(radiance * scale),
            Environment::Map(map) => {
                let (w, h) = (map.image.width(), map.image.height());
                let pixels = map.image.pixels().iter().map(|p| *p * scale).collect();
                let scaled = EnvironmentMap::new(HdrImage::from_pixels(w, h, pixels).expect("the map's size"));
                Environment::Map(scaled.turned(map.turn))
            }
        }
    }

    /// The radiance arriving from `direction` (unit).
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        match self {
            Environment::Uniform(radiance) => *radiance,
            Environment::Map(map) => {
                let (x, y) = map.texel_of(map.turn.inverse() * direction);
                map.image.get(x, y)
            }
        }
    }

    /// A direction drawn in proportion to the radiance, with the radiance
    /// and the density (solid angle).
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec3, f32) {
        match self {
            Environment::Uniform(radiance) => (crate::rays::uniform_sphere(u.x, u.y), *radiance, 1.0 / (4.0 * PI)),
            Environment::Map(map) => {
                let (row, p_row, v) = map.rows.sample(u.y);
                let (column, p_column, u) = map.columns[row].sample(u.x);
                let (w, h) = (map.image.width() as f32, map.image.height() as f32);
                let uv = Vec2::new((column as f32 + u) / w, (row as f32 + v) / h);
                let direction = map.turn * direction_of(uv);
                let sin_theta = (PI * uv.y).sin();
                let pdf = if sin_theta > 0.0 { p_row * p_column * w * h / (2.0 * PI * PI * sin_theta) } else { 0.0 };
                (direction, map.image.get(column as u32, row as u32), pdf)
            }
        }
    }

    /// The density with which [`Environment::sample`] draws `direction`.
    pub fn pdf(&self, direction: Vec3) -> f32 {
        match self {
            Environment::Uniform(_) => 1.0 / (4.0 * PI),
            Environment::Map(map) => {
                let direction = map.turn.inverse() * direction;
                let (x, y) = map.texel_of(direction);
                let (w, h) = (map.image.width() as f32, map.image.height() as f32);
                // From x and z rather than 1 - y², which loses everything near the poles.
                let sin_theta = (direction.x * direction.x + direction.z * direction.z).sqrt();
                if sin_theta <= 0.0 {
                    return 0.0;
                }
                let p = map.rows.probability(y as usize) * map.columns[y as usize].probability(x as usize);
                p * w * h / (2.0 * PI * PI * sin_theta)
            }
        }
    }

    /// The mean radiance over all directions.
    pub fn mean_radiance(&self) -> Vec3 {
        match self {
            Environment::Uniform(radiance) => *radiance,
            Environment::Map(map) => {
                let h = map.image.height();
                let mut sum = Vec3::ZERO;
                let mut weight = 0.0;
                for y in 0..h {
                    let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
                    for x in 0..map.image.width() {
                        sum += map.image.get(x, y) * sin_theta;
                        weight += sin_theta;
                    }
                }
                sum / weight.max(1e-30)
            }
        }
    }
}

impl EnvironmentMap {
    /// An environment map over `image`, with the distributions that sample it in proportion to brightness.
    pub fn new(image: HdrImage) -> Self {
        let (w, h) = (image.width(), image.height());
        let columns: Vec<Distribution1D> =
            (0..h).map(|y| Distribution1D::new((0..w).map(|x| luminance(image.get(x, y))))).collect();
        let rows = Distribution1D::new(
            columns.iter().enumerate().map(|(y, c)| c.total() as f32 * (PI * (y as f32 + 0.5) / h as f32).sin()),
        );
        Self { image, rows, columns, turn: Quat::IDENTITY }
    }

    /// The map turned by `turn` (from its +Y-up frame to the world's).
    pub fn turned(self, turn: Quat) -> Self {
        Self { turn, ..self }
    }

    /// The rotation from the map's +Y-up frame to the world's.
    pub fn turn(&self) -> Quat {
        self.turn
    }

    /// The equirectangular image.
    pub fn image(&self) -> &HdrImage {
        &self.image
    }

    fn texel_of(&self, direction: Vec3) -> (u32, u32) {
        let uv = uv_of(direction);
        let x = ((uv.x * self.image.width() as f32) as u32).min(self.image.width() - 1);
        let y = ((uv.y * self.image.height() as f32) as u32).min(self.image.height() - 1);
        (x, y)
    }
}

/// Equirectangular coordinates of a unit direction: u from the azimuth
/// (0.5 looks along -Z), v from the polar angle (0 straight up).
/// Whether `path` ends in `.extension`, in any case.
fn has_extension(path: &Path, extension: &str) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case(extension))
}

/// The course framework's skies put longitude φ = atan2(z, x) at u = φ / 2π;
/// ours ([`uv_of`]) put it at u = φ / 2π + 3/4. Its columns are turned a
/// quarter of the way round, so that a sky lights the scene from the same
/// side in both (exactly when the width is a multiple of 4, else to the
/// nearest column).
fn from_course_longitudes(image: HdrImage) -> HdrImage {
    let (w, h) = (image.width(), image.height());
    let shift = ((3 * w as u64 + 2) / 4) as u32 % w.max(1);
    let mut turned = HdrImage::new(w, h);
    for y in 0..h {
        for x in 0..w {
            turned.set((x + shift) % w, y, image.get(x, y));
        }
    }
    turned
}

fn uv_of(d: Vec3) -> Vec2 {
    let u = 0.5 + d.x.atan2(-d.z) / (2.0 * PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u.rem_euclid(1.0), v)
}

fn direction_of(uv: Vec2) -> Vec3 {
    let phi = 2.0 * PI * (uv.x - 0.5);
    let theta = PI * uv.y;
    Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
}

/// One light that [`LightSet`] samples.
#[derive(Clone, Debug, PartialEq)]
enum Source {
    /// A point or, with a cone, a spot light.
    Point {
        position: Vec3,
        intensity: Vec3,
        range: Option<f32>,
        cone: Option<Cone>,
    },
    /// `direction` is the way the light travels.
    Directional {
        direction: Vec3,
        irradiance: Vec3,
    },
    Triangle(EmissiveTriangle),
    Environment,
}

/// A spot light's cone: its axis (the way light travels) and the cosines
/// of its inner and outer half-angles.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cone {
    direction: Vec3,
    cos_inner: f32,
    cos_outer: f32,
}

/// An emissive triangle, as an area light.
#[derive(Clone, Debug, PartialEq)]
pub struct EmissiveTriangle {
    /// The triangle's index in the scene.
    pub triangle: u32,
    /// Its corners in world space.
    pub corners: [Vec3; 3],
    /// Both texture coordinate sets of its corners, for a textured emission.
    pub uvs: [[Vec2; 2]; 3],
    /// Unit geometric normal (right-hand rule); the front side.
    pub normal: Vec3,
    /// The triangle's [`rtgi_math::elongation`], for the error bound of points on it.
    pub elongation: f32,
    /// Its area, in square scene units.
    pub area: f32,
    /// Emitted radiance (linear RGB), multiplied by the texture where there is one.
    pub emission: Vec3,
    /// The emission texture, if any.
    pub texture: Option<TextureId>,
    /// Whether the back side emits too (else only the front, the side of `normal`).
    pub two_sided: bool,
}

impl EmissiveTriangle {
    /// The radiance leaving the point `(beta, gamma)` towards `towards` (unit).
    // Always inlined: see `bent_towards_view`.
    #[inline(always)]
    pub fn radiance(&self, scene: &Scene, beta: f32, gamma: f32, towards: Vec3) -> Vec3 {
        if !self.two_sided && self.normal.dot(towards) <= 0.0 {
            return Vec3::ZERO;
        }
        let texture = self.texture.map_or(Vec3::ONE, |t| {
            let [a, b, c] = self.uvs;
            let coords = std::array::from_fn(|set| (1.0 - beta - gamma) * a[set] + beta * b[set] + gamma * c[set]);
            scene.textures[t.0 as usize].lookup(coords).truncate()
        });
        self.emission * texture
    }
}

/// Light arriving at a point from a sampled light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// Incident radiance (for delta lights, the irradiance normal to `wi`).
    pub radiance: Vec3,
    /// Solid-angle density, including the choice of light; for delta
    /// lights just the probability of choosing the light.
    pub pdf: f32,
    /// Whether the light is a point or a direction, which only light
    /// sampling can find.
    pub delta: bool,
    /// The ray that must be unoccluded for the light to arrive.
    pub shadow_ray: Ray,
}

/// All the lights of a scene, chosen in proportion to their power.
#[derive(Clone, Debug)]
pub struct LightSet {
    sources: Vec<Source>,
    choice: Option<Distribution1D>,
    /// For each triangle, its index in `sources`, or `u32::MAX` if it does not emit.
    source_of_triangle: Vec<u32>,
    environment_index: Option<usize>,
}

impl LightSet {
    /// Collects the scene's punctual lights and `extra` ones, its emissive
    /// triangles (when `emission` is on) and the environment (when given).
    pub fn new(scene: &Scene, extra: &[Light], emission: bool, environment: Option<&Environment>) -> Self {
        let bounds = scene.bounds();
        let radius = if bounds.is_empty() { 1.0 } else { 0.5 * bounds.extent().length().max(1e-6) };
        let mut sources = Vec::new();
        let mut powers = Vec::new();
        for light in scene.lights.iter().chain(extra) {
            let intensity = light.color * light.intensity;
            let point = |cone| Source::Point { position: light.position, intensity, range: light.range, cone };
            let (source, power) = match light.kind {
                LightKind::Point => (point(None), 4.0 * PI * luminance(intensity)),
                LightKind::Spot { inner_cone, outer_cone } => {
                    let (cos_inner, cos_outer) = (inner_cone.cos(), outer_cone.cos());
                    let cone = Cone { direction: light.direction.normalize(), cos_inner, cos_outer };
                    (point(Some(cone)), 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * luminance(intensity))
                }
                LightKind::Directional => (
                    Source::Directional { direction: light.direction.normalize(), irradiance: intensity },
                    PI * radius * radius * luminance(intensity),
                ),
            };
            sources.push(source);
            powers.push(power);
        }
        let mut source_of_triangle = Vec::new();
        if emission {
            // Mean emission textures, for the lights' power: only those of emitters (averaging is a pass over every texel).
            let mut texture_mean: Vec<Option<Vec3>> = vec![None; scene.textures.len()];
            for m in scene.materials.iter().filter(|m| m.is_emissive()) {
                if let Some(t) = m.emission_texture {
                    texture_mean[t.0 as usize] = Some(scene.textures[t.0 as usize].average().truncate());
                }
            }
            for (index, triangle) in scene.triangles.iter().enumerate() {
                let material = &scene.materials[triangle.material as usize];
                if !material.is_emissive() {
                    continue;
                }
                let corners = triangle.vertices.map(|v| scene.vertices[v as usize].position);
                let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
                let area = 0.5 * cross.length();
                if !(area > 0.0 && area.is_finite()) {
                    continue;
                }
                let mean = material.emission_texture.and_then(|t| texture_mean[t.0 as usize]).unwrap_or(Vec3::ONE);
                // Emitters shine from their front face (by winding), as in pbrt and
                // Mitsuba; glTF's double-sided materials shine from both.
                let two_sided = material.double_sided && material.model == SurfaceModel::MetallicRoughness;
                let sides = if two_sided { 2.0 } else { 1.0 };
                let power = sides * PI * area * luminance(material.emission * mean);
                if power <= 0.0 {
                    continue;
                }
                if source_of_triangle.is_empty() {
                    source_of_triangle = vec![u32::MAX; scene.triangles.len()];
                }
                source_of_triangle[index] = sources.len() as u32;
                sources.push(Source::Triangle(EmissiveTriangle {
                    triangle: index as u32,
                    corners,
                    uvs: triangle.vertices.map(|v| [scene.vertices[v as usize].uv, scene.vertices[v as usize].uv1]),
                    normal: cross / (2.0 * area),
                    elongation: rtgi_math::elongation(&corners),
                    area,
                    emission: material.emission,
                    texture: material.emission_texture,
                    two_sided,
                }));
                powers.push(power);
            }
        }
        let mut environment_index = None;
        if let Some(environment) = environment {
            // What the environment brings through the disc a directional
            // light is weighed by (π r² times an irradiance of π times its
            // mean radiance), so that a sun and a sky of equal irradiance are
            // chosen equally often. (Its power through the bounding sphere,
            // four times more, drowned a sun in sky samples and speckled
            // every sunlit surface.)
            let power = PI * radius * radius * PI * luminance(environment.mean_radiance());
            if power > 0.0 {
                environment_index = Some(sources.len());
                sources.push(Source::Environment);
                powers.push(power);
            }
        }
        let choice = (!sources.is_empty()).then(|| Distribution1D::new(powers));
        Self { sources, choice, source_of_triangle, environment_index }
    }

    /// Whether there is no light at all (no light, emitter or environment).
    pub fn is_empty(&self) -> bool {
        self.sources.is_empty()
    }

    /// How many lights there are.
    pub fn len(&self) -> usize {
        self.sources.len()
    }

    /// How many of the lights are emissive triangles.
    pub fn emissive_triangles(&self) -> usize {
        self.sources.iter().filter(|s| matches!(s, Source::Triangle(_))).count()
    }

    /// The area light of `triangle`, if it is one.
    pub fn emitter(&self, triangle: u32) -> Option<&EmissiveTriangle> {
        let index = *self.source_of_triangle.get(triangle as usize)?;
        match self.sources.get(index as usize) {
            Some(Source::Triangle(e)) => Some(e),
            _ => None,
        }
    }

    /// Chooses a light and a point or direction on it, as seen from `at`;
    /// `u.x` chooses the light. `None` when the light sends nothing to `at`.
    pub fn sample(
        &self,
        scene: &Scene,
        environment: Option<&Environment>,
        at: &SurfacePoint,
        u_choice: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let (index, p_choice, _) = self.choice.as_ref()?.sample(u_choice);
        let p = at.position;
        match &self.sources[index] {
            Source::Point { position, intensity, range, cone } => {
                let (wi, window) = toward_point(p, *position, *range)?;
                let falloff = cone.map_or(1.0, |c| spot_falloff(c.direction.dot(-wi), c.cos_inner, c.cos_outer));
                if falloff <= 0.0 {
                    return None;
                }
                Some(LightSample {
                    wi,
                    radiance: *intensity * (window * falloff),
                    pdf: p_choice,
                    delta: true,
                    shadow_ray: at.spawn_ray_to_point(*position),
                })
            }
            Source::Directional { direction, irradiance } => {
                let wi = -*direction;
                Some(LightSample {
                    wi,
                    radiance: *irradiance,
                    pdf: p_choice,
                    delta: true,
                    shadow_ray: at.spawn_ray(wi),
                })
            }
            Source::Triangle(emitter) => {
                // Uniform on the triangle (the square-root warp of Turk 1990).
                let s = u.x.sqrt();
                let (beta, gamma) = (s * (1.0 - u.y), s * u.y);
                let target = SurfacePoint::on_triangle_with_shape(
                    &emitter.corners,
                    beta,
                    gamma,
                    TriangleShape { normal: emitter.normal, elongation: emitter.elongation },
                );
                let offset = target.position - p;
                let distance2 = offset.length_squared();
                let wi = offset / distance2.sqrt();
                let cos_light = emitter.normal.dot(-wi).abs();
                if distance2 <= 0.0 || distance2.is_nan() || cos_light <= 0.0 {
                    return None;
                }
                let radiance = emitter.radiance(scene, beta, gamma, -wi);
                if radiance == Vec3::ZERO {
                    return None;
                }
                let pdf = p_choice * distance2 / (cos_light * emitter.area);
                Some(LightSample { wi, radiance, pdf, delta: false, shadow_ray: at.spawn_ray_to(&target) })
            }
            Source::Environment => {
                let (wi, radiance, pdf) = environment?.sample(u);
                (pdf > 0.0).then(|| LightSample {
                    wi,
                    radiance,
                    pdf: p_choice * pdf,
                    delta: false,
                    shadow_ray: at.spawn_ray(wi),
                })
            }
        }
    }

    /// The density with which [`LightSet::sample`] picks the point `hit`
    /// (barycentrics irrelevant: uniform over the triangle) on the emitter
    /// `triangle`, seen from `from` along the unit `direction`, `distance` away.
    pub fn pdf_emitter(&self, triangle: u32, direction: Vec3, distance: f32) -> f32 {
        let Some(index) = self.source_of_triangle.get(triangle as usize).copied().filter(|&i| i != u32::MAX) else {
            return 0.0;
        };
        let Source::Triangle(emitter) = &self.sources[index as usize] else { return 0.0 };
        let cos_light = emitter.normal.dot(direction).abs();
        if cos_light <= 0.0 {
            return 0.0;
        }
        let p_choice = self.choice.as_ref().map_or(0.0, |c| c.probability(index as usize));
        p_choice * distance * distance / (cos_light * emitter.area)
    }

    /// The density with which [`LightSet::sample`] picks `direction` on the environment.
    pub fn pdf_environment(&self, environment: &Environment, direction: Vec3) -> f32 {
        match (self.environment_index, &self.choice) {
            (Some(index), Some(choice)) => choice.probability(index) * environment.pdf(direction),
            _ => 0.0,
        }
    }
}

/// The direction from `p` to a point light at `position` and the light's
/// falloff there: 1/d², windowed to zero at `range` as glTF recommends.
fn toward_point(p: Vec3, position: Vec3, range: Option<f32>) -> Option<(Vec3, f32)> {
    let offset = position - p;
    let distance2 = offset.length_squared();
    if distance2 <= 0.0 || distance2.is_nan() {
        return None;
    }
    let window = range.map_or(1.0, |r| (1.0 - (distance2 / (r * r)).powi(2)).clamp(0.0, 1.0).powi(2));
    (window > 0.0).then(|| (offset / distance2.sqrt(), window / distance2))
}

/// glTF's spot cone: full inside the inner cone, none outside the outer,
/// a squared linear ramp in cosine between.
fn spot_falloff(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let scale = 1.0 / (cos_inner - cos_outer).max(1e-3);
    ((cos_angle - cos_outer) * scale).clamp(0.0, 1.0).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Rng;

    fn gradient_map() -> Environment {
        let mut image = HdrImage::new(16, 8);
        for y in 0..8 {
            for x in 0..16 {
                image.set(
                    x,
                    y,
                    Vec3::new(1.0 + x as f32, 0.5 + (y * y) as f32, if x == 3 && y == 2 { 400.0 } else { 0.1 }),
                );
            }
        }
        Environment::Map(EnvironmentMap::new(image))
    }

    /// A course sky lights the same side of the scene as in the course:
    /// its texel at longitude φ = atan2(z, x) and colatitude θ from +Y
    /// is what our map returns for that direction, after the quarter turn.
    #[test]
    fn course_skies_keep_their_directions() {
        let (w, h) = (16u32, 8u32);
        let dir = std::env::temp_dir().join(format!("rtgi-course-sky-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sky.floats");
        for (x, y) in [(0u32, 1u32), (5, 3), (11, 6), (15, 0)] {
            let mut image = HdrImage::new(w, h);
            image.set(x, y, Vec3::new(9.0, 8.0, 7.0));
            std::fs::write(&path, image.encode_floats()).unwrap();
            let sky = Environment::load(&path).unwrap().scaled(2.0);
            // The course's direction at the texel's centre.
            let (phi, theta) = (2.0 * PI * (x as f32 + 0.5) / w as f32, PI * (y as f32 + 0.5) / h as f32);
            let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            assert_eq!(sky.radiance(d), Vec3::new(18.0, 16.0, 14.0), "texel {x},{y}");
            assert_eq!(sky.radiance(-d), Vec3::ZERO, "texel {x},{y}, opposite");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn equirectangular_directions_round_trip() {
        for uv in [Vec2::new(0.5, 0.5), Vec2::new(0.1, 0.3), Vec2::new(0.9, 0.95), Vec2::new(0.25, 0.01)] {
            assert!((uv_of(direction_of(uv)) - uv).length() < 1e-5, "{uv}");
        }
        assert!((direction_of(Vec2::new(0.5, 0.5)) - Vec3::NEG_Z).length() < 1e-6);
        assert!((direction_of(Vec2::new(0.3, 0.0)) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn environment_samples_match_their_density_and_integrate_to_one() {
        let environment = gradient_map();
        let mut rng = Rng::new(7, 8);
        for _ in 0..5000 {
            let (direction, radiance, pdf) = environment.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!((direction.length() - 1.0).abs() < 1e-5);
            assert_eq!(radiance, environment.radiance(direction));
            assert!((pdf - environment.pdf(direction)).abs() <= 2e-3 * pdf, "{pdf} vs {}", environment.pdf(direction));
        }
        // ∫ pdf dω = 1 and E[L / pdf] = ∫ L dω = 4π × mean radiance.
        let n = 400_000;
        let (mut pdf_integral, mut estimate) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let d = crate::rays::uniform_sphere(rng.next_f32(), rng.next_f32());
            pdf_integral += environment.pdf(d) as f64 * 4.0 * std::f64::consts::PI;
            let (_, radiance, pdf) = environment.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            estimate += (radiance.x / pdf) as f64;
        }
        assert!((pdf_integral / n as f64 - 1.0).abs() < 0.01, "{}", pdf_integral / n as f64);
        let exact = 4.0 * PI * environment.mean_radiance().x;
        assert!(((estimate / n as f64) as f32 - exact).abs() < 0.01 * exact);
    }

    #[test]
    fn spot_cone_and_range_window() {
        assert_eq!(spot_falloff(1.0, 0.9, 0.8), 1.0);
        assert_eq!(spot_falloff(0.7, 0.9, 0.8), 0.0);
        assert!((spot_falloff(0.85, 0.9, 0.8) - 0.25).abs() < 1e-5);
        let (_, near) = toward_point(Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0), None).unwrap();
        assert_eq!(near, 0.25);
        assert!(toward_point(Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0), Some(1.5)).is_none());
        let (_, windowed) = toward_point(Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0), Some(2.0)).unwrap();
        assert!((windowed - (1.0 - 1.0 / 16.0f32).powi(2)).abs() < 1e-6);
    }
}
