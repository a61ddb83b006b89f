//! Light transport: direct lighting and path tracing with next-event
//! estimation, multiple importance sampling and Russian roulette, compiled
//! once per set of effects ([`EffectPlan::specialisation`], a const
//! generic `S`: the bits of an [`EffectSet`]).
//!
//! Every bounce draws the same block of random numbers whatever the plan,
//! so that a render whose plan leaves an effect out follows the same paths
//! as one with the effect forced on: the images agree, which the tests check.

use rtgi_accel::{Accel, Hit};
use rtgi_math::{Frame, Ray, Rng, SurfacePoint, TriangleShape, Vec2, Vec3, Vec4, luminance};
use rtgi_scene::{Material, Scene, SurfaceModel, Triangle};

use crate::alpha::AlphaTest;
use crate::bsdf::{Bsdf, energy_conserving};
use crate::effects::{Effect, EffectPlan, is_glossy, transmits};
use crate::lights::{Environment, LightSet};
use crate::shade::closest_hit;
use crate::shading_normal::bent_towards_view;
use crate::surface_layers::{LayerInputs, LayerSwitches, needs_layers, pbr_layers};
use crate::{BounceSampling, EffectSet, PathStart, RenderSettings};

/// What the renderer computes for each pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Integrator {
    /// The closest hit's colour, lit from the viewer (a fast preview).
    Primary,
    /// The closest hit's surface colour.
    Albedo,
    /// The closest hit's unit shading normal (x, y, z in [-1, 1]).
    Normal,
    /// The distance to the closest hit (0 where nothing is hit).
    Depth,
    /// The closest hit's position.
    Position,
    /// The light the closest hit emits towards the camera (its texture included).
    Emission,
    /// Boxes (red) and triangles (green) tested to find the closest hit.
    Cost,
    /// Light arriving directly from lights and emitters, after one reflection.
    Direct,
    /// Global illumination: paths of many reflections.
    Path,
}

impl Integrator {
    /// Every integrator, in the order help texts list them.
    pub const ALL: &'static [Integrator] = &[
        Integrator::Primary,
        Integrator::Albedo,
        Integrator::Normal,
        Integrator::Depth,
        Integrator::Position,
        Integrator::Emission,
        Integrator::Cost,
        Integrator::Direct,
        Integrator::Path,
    ];

    /// The integrator's name on command lines and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Primary => "primary",
            Integrator::Albedo => "albedo",
            Integrator::Normal => "normal",
            Integrator::Depth => "depth",
            Integrator::Position => "position",
            Integrator::Emission => "emission",
            Integrator::Cost => "cost",
            Integrator::Direct => "direct",
            Integrator::Path => "path",
        }
    }

    /// Whether the integrator computes how light travels (rather than a
    /// property of the closest hit).
    pub fn simulates_light(self) -> bool {
        matches!(self, Integrator::Direct | Integrator::Path)
    }

    /// Whether the integrator writes an arbitrary output variable.
    pub fn is_aov(self) -> bool {
        matches!(
            self,
            Integrator::Albedo
                | Integrator::Normal
                | Integrator::Depth
                | Integrator::Position
                | Integrator::Emission
                | Integrator::Cost
        )
    }
}

impl rtgi_math::NamedChoice for Integrator {
    const KIND: &'static str = "integrator";
    const ALL: &'static [Self] = Integrator::ALL;
    fn name(self) -> &'static str {
        Integrator::name(self)
    }
}

impl std::fmt::Display for Integrator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How direct light is estimated at each surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum DirectStrategy {
    /// Sample points on lights only (misses glossy highlights of big lights).
    Light,
    /// Sample the BSDF only (cannot find point lights; noisy for small lights).
    Bsdf,
    /// Both, weighted by Veach's power heuristic.
    Mis,
}

impl DirectStrategy {
    /// Every strategy, in the order help texts list them.
    pub const ALL: &'static [DirectStrategy] = &[DirectStrategy::Light, DirectStrategy::Bsdf, DirectStrategy::Mis];

    /// The strategy's name on command lines and in reports (`light`, `bsdf`, `mis`).
    pub fn name(self) -> &'static str {
        match self {
            DirectStrategy::Light => "light",
            DirectStrategy::Bsdf => "bsdf",
            DirectStrategy::Mis => "mis",
        }
    }
}

impl rtgi_math::NamedChoice for DirectStrategy {
    const KIND: &'static str = "direct-light strategy";
    const ALL: &'static [Self] = DirectStrategy::ALL;
    fn name(self) -> &'static str {
        DirectStrategy::name(self)
    }
}

impl std::fmt::Display for DirectStrategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Bounces after which Russian roulette may end a path, unless the
/// settings say otherwise ([`RenderSettings::roulette_start`]).
pub const ROULETTE_START: u32 = 2;

/// GGX widths below this are treated as perfect mirrors (metals) or clamped
/// (dielectrics): narrower lobes only add fireflies in f32.
const MIN_ALPHA: f32 = 1e-3;

/// The indices of a bounce's random numbers.
mod dim {
    pub(super) const LOBE: usize = 0;
    pub(super) const BSDF: usize = 1; // and 2
    pub(super) const LIGHT_CHOICE: usize = 3;
    pub(super) const LIGHT: usize = 4; // and 5
    pub(super) const ROULETTE: usize = 6;
    pub(super) const ALPHA: usize = 7;
    pub(super) const COUNT: usize = 8;
}

/// The vertices of a path, from the camera ray's hit on, whose random
/// numbers come from the pixel sampler ([`crate::PixelSampler::vertex`]);
/// deeper ones draw them from the sample's generator. The first vertex is
/// where it pays: at 16 spp it halved the RMSE of the sky-lit bunny and
/// took a fifth off Sponza's, while spreading the next two vertices too
/// gained about 1% more on the Cornell box, Sponza and the conference room.
const SAMPLED_VERTICES: u32 = 1;

/// What the light-transport loop needs, prepared once per render.
pub(crate) struct Transport<'a, A: Accel + ?Sized> {
    scene: &'a Scene,
    accel: &'a A,
    lights: LightSet,
    environment: Option<&'a Environment>,
    background: Vec3,
    /// Whether camera rays that miss see the environment: not the dim one
    /// set only for glossy surfaces to reflect ([`crate::DefaultLighting::Reflections`]).
    environment_in_view: bool,
    max_depth: u32,
    strategy: DirectStrategy,
    indirect_clamp: Option<f32>,
    filter_glossy: Option<crate::FilterGlossy>,
    russian_roulette: bool,
    roulette_start: u32,
    bounce_sampling: BounceSampling,
    glossy: bool,
    refraction: bool,
    normal_maps: bool,
    /// The layers of glTF's material the plan simulates.
    layers: LayerSwitches,
    /// Per material: whether it is shaded with the layered model
    /// ([`needs_layers`]), decided once rather than at every hit.
    layered_materials: Vec<bool>,
    /// Normal and elongation of every triangle, for the points spawning rays.
    shapes: Vec<TriangleShape>,
    /// Per triangle, its shading normal where its three vertices share one
    /// (flat faces, as in most architectural scenes): normalised once here
    /// instead of interpolated and normalised at every hit.
    flat_normals: Vec<Option<Vec3>>,
    /// Whether any vertex has a colour other than white; without, the
    /// interpolation of `COLOR_0` is skipped (multiplying by white is exact).
    vertex_colors: bool,
    /// The alpha test of cut-outs, where the plan has them.
    cut_outs: Option<AlphaTest<'a>>,
}

/// A surface hit, ready to scatter light.
struct Interaction {
    point: SurfacePoint,
    /// Local shading frame: `z` is the shading normal, on the side of the
    /// geometric normal `point.normal`.
    frame: Frame,
    bsdf: Bsdf,
    /// Compensates the random choice of one lobe of a layered material.
    weight: Vec3,
}

/// Whether the loop compiled for the effect set of bits `s` runs `effect`'s
/// code: a constant in each compiled loop, so the code of the others is
/// left out ([`crate::effects::SPECIALISED`] says what stands for what).
const fn compiled(s: u16, effect: Effect) -> bool {
    EffectSet::from_bits(s).contains(effect)
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2.is_infinite() { 1.0 } else { a2 / (a2 + b2).max(f32::MIN_POSITIVE) }
}

impl<'a, A: Accel + ?Sized> Transport<'a, A> {
    pub(crate) fn new(
        scene: &'a Scene,
        accel: &'a A,
        plan: &EffectPlan,
        environment: Option<&'a Environment>,
        settings: &RenderSettings,
    ) -> Self {
        let environment = environment.filter(|_| plan.has(Effect::Environment));
        let layers = LayerSwitches {
            sheen: plan.has(Effect::Sheen),
            clearcoat: plan.has(Effect::Clearcoat),
            iridescence: plan.has(Effect::Iridescence),
            anisotropy: plan.has(Effect::Anisotropy),
        };
        Self {
            scene,
            accel,
            // The default sun comes with the default sky.
            lights: LightSet::new(
                scene,
                plan.default_environment.then(|| crate::default_lighting::render_sun(settings)).as_slice(),
                plan.has(Effect::Emission),
                environment,
            ),
            environment,
            background: settings.background,
            environment_in_view: !matches!(settings.default_lighting, crate::DefaultLighting::Reflections(_)),
            max_depth: plan.max_depth,
            strategy: settings.direct_strategy,
            indirect_clamp: settings.indirect_clamp,
            filter_glossy: plan.filter_glossy,
            russian_roulette: settings.russian_roulette,
            roulette_start: settings.roulette_start,
            bounce_sampling: settings.bounce_sampling,
            glossy: plan.has(Effect::Glossy),
            refraction: plan.has(Effect::Refraction),
            normal_maps: plan.has(Effect::NormalMaps),
            layers,
            layered_materials: scene
                .materials
                .iter()
                .map(|m| m.model == SurfaceModel::MetallicRoughness && needs_layers(m, layers))
                .collect(),
            cut_outs: plan.has(Effect::Alpha).then(|| AlphaTest::new(scene)),
            shapes: scene
                .triangles
                .iter()
                .map(|t| TriangleShape::of(&t.vertices.map(|v| scene.vertices[v as usize].position)))
                .collect(),
            flat_normals: scene
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.vertices.map(|v| scene.vertices[v as usize].normal);
                    (a == b && b == c).then(|| a.try_normalize()).flatten()
                })
                .collect(),
            vertex_colors: scene.vertices.iter().any(|v| v.color != Vec4::ONE),
        }
    }

    /// The alpha test with the sample's number, in loops compiled for cut-outs.
    #[inline]
    fn cut_outs<const S: u16>(&self, u_alpha: f32) -> Option<(&AlphaTest<'a>, f32)> {
        compiled(S, Effect::Alpha).then_some(())?;
        self.cut_outs.as_ref().map(|test| (test, u_alpha))
    }

    fn closest<const S: u16>(&self, ray: &Ray, u_alpha: f32) -> Option<Hit> {
        closest_hit(self.accel, ray, self.cut_outs::<S>(u_alpha))
    }

    fn occluded<const S: u16>(&self, ray: &Ray, u_alpha: f32) -> bool {
        match self.cut_outs::<S>(u_alpha) {
            Some((test, u)) => self.accel.occluded_filtered(ray, &|t, b, g| test.accepts(t, b, g, u)),
            None => self.accel.occluded(ray),
        }
    }

    /// The radiance arriving along `ray` (a camera ray); adds the rays it
    /// traces to `rays`.
    pub(crate) fn radiance<const S: u16>(&self, start: &PathStart, rng: &mut Rng, rays: &mut u64) -> Vec3 {
        let (mut ray, mut first_hit) = (start.ray, start.first_hit);
        let scene = self.scene;
        let mut radiance = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        // The density of the BSDF sample that produced `ray`; None for the
        // camera ray and specular bounces, whose emitters count in full.
        let mut previous_pdf: Option<f32> = None;
        // The product of the η² of the refractions so far (pbrt's etaScale).
        let mut radiance_scale = 1.0f32;
        // The least density of the path's bounces so far (not counting
        // deltas), which path regularisation widens later lobes by.
        let mut least_pdf = f32::INFINITY;
        // The absorption of the medium the ray travels in (KHR_materials_volume),
        // set where a path refracts into a mesh with a volume and cleared where
        // it leaves one; a medium inside another is not tracked.
        let mut medium: Option<Vec3> = None;
        let mut depth = 0;
        loop {
            let mut u: [f32; dim::COUNT] = std::array::from_fn(|_| rng.next_f32());
            if depth < SAMPLED_VERTICES {
                // The first vertices take the sampler's numbers, spread over the pixel's samples.
                let first = start.pattern.vertex(start.index, depth, rng);
                [u[dim::LIGHT_CHOICE], u[dim::LOBE]] = first.choices.to_array();
                [u[dim::LIGHT], u[dim::LIGHT + 1]] = first.light.to_array();
                [u[dim::BSDF], u[dim::BSDF + 1]] = first.bsdf.to_array();
            }
            *rays += 1;
            // The camera ray's hit may have been found already, with others
            // of its block (never where alpha masks filter hits).
            let hit = match first_hit.take() {
                Some(hit) => hit,
                None => self.closest::<S>(&ray, u[dim::ALPHA]),
            };
            if let (Some(absorption), Some(hit)) = (medium, &hit) {
                // Beer–Lambert: the light reaching here lost exp(−σ d) on the way.
                let distance = hit.t * ray.direction.length();
                throughput *= Vec3::new(
                    (-absorption.x * distance).exp(),
                    (-absorption.y * distance).exp(),
                    (-absorption.z * distance).exp(),
                );
            }
            let Some(hit) = hit else {
                match self.environment {
                    Some(environment) if compiled(S, Effect::Emission) && (depth > 0 || self.environment_in_view) => {
                        let direction = ray.direction.normalize();
                        let weight = self
                            .emitted_weight::<S>(previous_pdf, || self.lights.pdf_environment(environment, direction));
                        radiance += self.clamp(depth, throughput * environment.radiance(direction) * weight);
                    }
                    _ if depth == 0 => radiance += self.background,
                    _ => {}
                }
                break;
            };
            let triangle = &scene.triangles[hit.triangle as usize];
            let material = &scene.materials[triangle.material as usize];
            let direction_length = ray.direction.length();
            let wo = -ray.direction / direction_length;
            if compiled(S, Effect::Emission)
                && let Some(emitter) = self.lights.emitter(hit.triangle)
            {
                let emitted = emitter.radiance(scene, hit.beta, hit.gamma, wo);
                let weight = self.emitted_weight::<S>(previous_pdf, || {
                    self.lights.pdf_emitter(hit.triangle, wo, hit.t * direction_length)
                });
                radiance += self.clamp(depth, throughput * emitted * weight);
            }
            if material.unlit {
                // KHR_materials_unlit: the surface shows its colour as it is
                // and reflects nothing. Its colour is not a light to sample,
                // so a ray that finds it counts in full.
                if compiled(S, Effect::Emission) {
                    let color = crate::shade::albedo(scene, &hit, compiled(S, Effect::Textures));
                    radiance += self.clamp(depth, throughput * color);
                }
                break;
            }
            if depth == self.max_depth {
                break;
            }
            let mut interaction = self.interact::<S>(&hit, triangle, material, wo, u[dim::LOBE]);
            if compiled(S, Effect::Glossy)
                && let Some(filter) = &self.filter_glossy
            {
                interaction.bsdf = filter.apply(interaction.bsdf, least_pdf);
            }
            let (frame, bsdf) = (&interaction.frame, &interaction.bsdf);
            let wo_local = frame.to_local(wo);
            let reflects_only = !bsdf.transmits();
            let geometric = interaction.point.normal;
            let wo_side = wo.dot(geometric);

            if compiled(S, Effect::DirectLight) && self.strategy != DirectStrategy::Bsdf && !bsdf.is_delta() {
                let u_light = Vec2::new(u[dim::LIGHT], u[dim::LIGHT + 1]);
                if let Some(light) =
                    self.lights.sample(scene, self.environment, &interaction.point, u[dim::LIGHT_CHOICE], u_light)
                    && (!reflects_only || light.wi.dot(geometric) * wo_side > 0.0)
                {
                    let wi_local = frame.to_local(light.wi);
                    let f = bsdf.eval(wo_local, wi_local);
                    if f != Vec3::ZERO {
                        *rays += 1;
                        if !self.occluded::<S>(&light.shadow_ray, u[dim::ALPHA]) {
                            let weight = if light.delta || self.strategy == DirectStrategy::Light {
                                1.0
                            } else {
                                power_heuristic(light.pdf, self.bounce_sampling.pdf(bsdf, wo_local, wi_local))
                            };
                            let contribution = throughput
                                * interaction.weight
                                * f
                                * light.radiance
                                * (wi_local.z.abs() * weight / light.pdf);
                            radiance += self.clamp(depth + 1, contribution);
                        }
                    }
                }
            }

            let u_bsdf = Vec2::new(u[dim::BSDF], u[dim::BSDF + 1]);
            let Some(sample) = self.bounce_sampling.sample(bsdf, wo_local, u_bsdf) else { break };
            let wi = frame.to_world(sample.wi);
            // Reflection must stay on the side it came from, by the true
            // surface as well as by the shading normal.
            if reflects_only && wi.dot(geometric) * wo_side <= 0.0 {
                break;
            }
            throughput *= interaction.weight * sample.value * (sample.wi.z.abs() / sample.pdf);
            // Refraction scaled the radiance by 1/η²; the roulette must not
            // see that, or paths inside glass die for nothing.
            radiance_scale *= sample.eta * sample.eta;
            previous_pdf = (!sample.delta).then_some(sample.pdf);
            if !sample.delta {
                least_pdf = least_pdf.min(sample.pdf);
            }
            depth += 1;
            // Russian roulette ends paths that carry little, in proportion;
            // paths that lose nothing (mirrors, glass) are left to the depth limit.
            let survival = (throughput * radiance_scale).max_element();
            if self.russian_roulette && depth >= self.roulette_start && survival < 1.0 {
                if u[dim::ROULETTE] >= survival {
                    break;
                }
                throughput /= survival;
            }
            if !throughput.is_finite() || throughput.max_element() <= 0.0 {
                break;
            }
            if !reflects_only && wi.dot(geometric) * wo_side < 0.0 {
                // Refracted: into the mesh's medium (against the outward
                // normal, which the shading normal gives) or out of it.
                let entering = wi.dot(frame.z) < 0.0;
                medium = if entering { material.volume.as_ref().map(|v| v.absorption()) } else { None };
            }
            ray = interaction.point.spawn_ray(wi);
        }
        radiance
    }

    /// Limits the light a path brings in after `depth` bounces (≥ 2 is
    /// indirect light) to `indirect_clamp` in its brightest channel, if set.
    #[inline]
    fn clamp(&self, depth: u32, contribution: Vec3) -> Vec3 {
        match self.indirect_clamp {
            Some(limit) if depth >= 2 && contribution.max_element() > limit => {
                contribution * (limit / contribution.max_element())
            }
            _ => contribution,
        }
    }

    /// The weight of emitted light found by a BSDF-sampled ray, given the
    /// BSDF's density for it (`None` after the camera or a specular bounce)
    /// and the density with which light sampling would have found it.
    #[inline]
    fn emitted_weight<const S: u16>(&self, bsdf_pdf: Option<f32>, light_pdf: impl FnOnce() -> f32) -> f32 {
        match bsdf_pdf {
            None => 1.0,
            // Without light sampling, BSDF sampling is the only estimator.
            Some(_) if !compiled(S, Effect::DirectLight) => 1.0,
            Some(pdf) => match self.strategy {
                DirectStrategy::Light => 0.0,
                DirectStrategy::Bsdf => 1.0,
                DirectStrategy::Mis => power_heuristic(pdf, light_pdf()),
            },
        }
    }

    /// The shading frame and BSDF at a hit.
    fn interact<const S: u16>(
        &self,
        hit: &Hit,
        triangle: &Triangle,
        material: &Material,
        wo: Vec3,
        u_lobe: f32,
    ) -> Interaction {
        let scene = self.scene;
        let corners = triangle.vertices.map(|v| scene.vertices[v as usize].position);
        let point =
            SurfacePoint::on_triangle_with_shape(&corners, hit.beta, hit.gamma, self.shapes[hit.triangle as usize]);
        let flat_normal = self.flat_normals[hit.triangle as usize];
        let mut unit = flat_normal.is_some();
        let mut normal = flat_normal.unwrap_or_else(|| scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.normal));
        // Before any normal map: a clear coat without a map of its own follows it.
        let geometry_normal = normal;
        // COLOR_0 multiplies the base colour (white where a file has none).
        let mut base_color = material.base_color;
        if self.vertex_colors {
            base_color *= scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.color).truncate();
        }
        let mut roughness = material.roughness;
        let mut metallic = material.metallic;
        let mut transmission = material.transmission;
        if compiled(S, Effect::Textures) {
            let coords = scene.texture_coords(triangle, hit.beta, hit.gamma);
            let texture = |id: rtgi_scene::TextureId| scene.textures[id.0 as usize].lookup(coords);
            if let Some(id) = material.base_color_texture {
                base_color *= texture(id).truncate();
            }
            if let Some(id) = material.metallic_roughness_texture {
                let t = texture(id);
                roughness *= t.y;
                metallic *= t.z;
            }
            if let Some(id) = material.transmission_texture {
                transmission *= texture(id).x;
            }
            if self.normal_maps
                && let Some((id, scale)) = material.normal_texture
            {
                let tangent: Vec4 = scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.tangent);
                normal = perturb(normal, tangent, texture(id).truncate(), scale);
                unit = false;
            }
        }
        // A flat face's normal is a unit vector already, unless a normal map bent it.
        let mut normal = if unit { normal } else { normal.try_normalize().unwrap_or(point.normal) };
        // Keep the geometric normal on the shading normal's side: the shading
        // normal says where "outside" is (for refraction).
        let mut point = point;
        if point.normal.dot(normal) < 0.0 {
            point.normal = -point.normal;
        }
        if !normal.is_finite() {
            normal = point.normal;
        }
        // A viewer in front of the true surface must not be behind the
        // shading normal (black fringes along smooth silhouettes).
        if wo.dot(point.normal) > 0.0 {
            normal = bent_towards_view(normal, point.normal, wo);
        }
        let mut frame = Frame::from_z(normal);
        let layered = (compiled(S, Effect::Glossy)
            && self.glossy
            && self.layered_materials[triangle.material as usize])
            .then(|| {
                let coords = scene.texture_coords(triangle, hit.beta, hit.gamma);
                let lookup = |id: rtgi_scene::TextureId| scene.textures[id.0 as usize].lookup(coords);
                let geometry_normal = geometry_normal.normalize_or(normal);
                let inputs = LayerInputs {
                    texture: compiled(S, Effect::Textures).then_some(&lookup as &dyn Fn(rtgi_scene::TextureId) -> Vec4),
                    base_color,
                    metallic,
                    roughness,
                    frame,
                    geometry_normal: if geometry_normal.dot(normal) < 0.0 { -geometry_normal } else { geometry_normal },
                    tangent: scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.tangent),
                    perturb,
                };
                pbr_layers(material, self.layers, &inputs)
            });
        let surface = SurfaceValues { base_color, roughness, metallic, transmission };
        let (bsdf, weight) = self.choose_bsdf::<S>(material, &surface, u_lobe, layered.map(|(layers, _)| layers));
        if let (Bsdf::Layered(_), Some((_, turned))) = (&bsdf, layered) {
            // Turned about the normal towards the direction of anisotropy.
            frame = turned;
        }
        Interaction { point, frame, bsdf, weight }
    }

    /// The material's BSDF; layered materials choose one lobe at random
    /// (by `u`), with the weight that keeps the estimate unbiased.
    fn choose_bsdf<const S: u16>(
        &self,
        material: &Material,
        surface: &SurfaceValues,
        u: f32,
        layered: Option<crate::layered::PbrLayers>,
    ) -> (Bsdf, Vec3) {
        let SurfaceValues { base_color, roughness, metallic, transmission } = *surface;
        let lambert = (Bsdf::Lambert { albedo: base_color }, Vec3::ONE);
        if !compiled(S, Effect::Glossy) {
            return lambert;
        }
        let transmission = if self.refraction && transmits(material) {
            match material.model {
                SurfaceModel::DiffuseSpecular => transmission,
                SurfaceModel::MetallicRoughness => transmission * (1.0 - metallic),
            }
        } else {
            0.0
        };
        if u < transmission {
            let ior = material.ior.max(1.0 + 1e-4);
            // MTL's refracting materials are solid glass, as are glTF's with
            // KHR_materials_volume; glTF's transmission without it is a
            // thin-walled surface.
            let lobe = match material.model {
                SurfaceModel::DiffuseSpecular => Bsdf::Dielectric { ior, tint: Vec3::ONE },
                // KHR_materials_volume: the mesh is a solid of the medium,
                // refracting where light enters and leaves it.
                SurfaceModel::MetallicRoughness if material.volume.is_some() => {
                    if self.glossy && roughness * roughness >= MIN_ALPHA {
                        Bsdf::RoughDielectric { ior, tint: base_color, alpha: roughness * roughness }
                    } else {
                        Bsdf::Dielectric { ior, tint: base_color }
                    }
                }
                SurfaceModel::MetallicRoughness if self.glossy && roughness * roughness >= MIN_ALPHA => {
                    Bsdf::RoughThinDielectric { ior, tint: base_color, alpha: roughness * roughness }
                }
                SurfaceModel::MetallicRoughness => Bsdf::ThinDielectric { ior, tint: base_color },
            };
            return (lobe, Vec3::ONE);
        }
        if !self.glossy || !is_glossy(material) {
            return lambert;
        }
        let u = (u - transmission) / (1.0 - transmission);
        let alpha = roughness * roughness;
        if let Some(layers) = layered {
            return (Bsdf::Layered(layers), Vec3::ONE);
        }
        match material.model {
            SurfaceModel::MetallicRoughness => {
                if alpha < MIN_ALPHA && metallic >= 1.0 {
                    (Bsdf::Mirror { reflectance: base_color }, Vec3::ONE)
                } else {
                    (Bsdf::MetallicRoughness { base_color, metallic, alpha: alpha.max(MIN_ALPHA) }, Vec3::ONE)
                }
            }
            SurfaceModel::DiffuseSpecular if alpha >= MIN_ALPHA => {
                let (albedo, reflectance) = energy_conserving(base_color, material.specular);
                (Bsdf::DiffuseGlossy { albedo, reflectance, alpha }, Vec3::ONE)
            }
            SurfaceModel::DiffuseSpecular => {
                // A mirror is a delta: it cannot be summed with the diffuse
                // lobe, so one of the two is chosen per hit.
                let (base_color, specular) = energy_conserving(base_color, material.specular);
                let p_specular = luminance(specular) / (luminance(specular) + luminance(base_color)).max(1e-12);
                if u < p_specular {
                    (Bsdf::Mirror { reflectance: specular }, Vec3::splat(1.0 / p_specular))
                } else {
                    (Bsdf::Lambert { albedo: base_color }, Vec3::splat(1.0 / (1.0 - p_specular)))
                }
            }
        }
    }
}

/// A material's parameters at one point, after its textures.
struct SurfaceValues {
    base_color: Vec3,
    roughness: f32,
    metallic: f32,
    transmission: f32,
}

/// The shading normal bent by a tangent-space normal map texel (glTF:
/// stored as (n + 1) / 2, x and y scaled by `scale`).
fn perturb(normal: Vec3, tangent: Vec4, texel: Vec3, scale: f32) -> Vec3 {
    let n = normal.normalize_or_zero();
    let t = (tangent.truncate() - n * n.dot(tangent.truncate())).normalize_or_zero();
    if n == Vec3::ZERO || t == Vec3::ZERO {
        return normal;
    }
    let b = n.cross(t) * if tangent.w < 0.0 { -1.0 } else { 1.0 };
    let m = texel * 2.0 - Vec3::ONE;
    let m = Vec3::new(m.x * scale, m.y * scale, m.z);
    let bent = (t * m.x + b * m.y + n * m.z).normalize_or_zero();
    if bent == Vec3::ZERO { normal } else { bent }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_normal_map_texel_keeps_the_normal() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let t = Vec4::new(1.0, 0.0, 0.0, 1.0);
        assert!((perturb(n, t, Vec3::new(0.5, 0.5, 1.0), 1.0) - n).length() < 1e-6);
        // Tilting towards +u tilts the normal towards the tangent.
        let bent = perturb(Vec3::Z, t, Vec3::new(1.0, 0.5, 0.5 + 0.5f32.sqrt() * 0.5), 1.0);
        assert!(bent.x > 0.5 && bent.z > 0.5, "{bent}");
        assert!((power_heuristic(1.0, 1.0) - 0.5).abs() < 1e-6);
        assert_eq!(power_heuristic(1.0, 0.0), 1.0);
    }
}
