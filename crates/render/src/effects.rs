//! The effects planner: from a scene and the render settings, decide which
//! effects a render has to simulate, and say why.
//!
//! Each effect is either needed by the scene (there are lights to shadow,
//! materials that refract, textures to look up...) or not; the user can
//! force any effect on or off with [`EffectOverrides`]. The renderer then
//! runs code specialised to the plan (one compiled version per set of effects):
//! what the plan leaves out is compiled out, not skipped by a test per sample.

use std::fmt;
use std::str::FromStr;

use rtgi_scene::{AlphaMode, Material, Scene, SurfaceModel};
use serde::Serialize;

use crate::{EffectSet, Integrator, RenderSettings};

/// Something a render may simulate. Sets of effects are [`EffectSet`]s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Effect {
    /// Light sampled from lights, emitters and the environment at every
    /// surface, with shadow rays (next-event estimation).
    DirectLight,
    /// Light emitted by surfaces, seen directly or after bounces.
    Emission,
    /// Light from the environment, for rays that leave the scene.
    Environment,
    /// Light that has bounced off more than one surface.
    Indirect,
    /// Specular and glossy reflection (microfacet lobes, mirrors).
    Glossy,
    /// Refraction through transmitting materials.
    Refraction,
    /// Texture lookups for colour, emission, metal and roughness.
    Textures,
    /// Normal maps perturbing the shading normal.
    NormalMaps,
    /// Alpha tests: cut-outs and blended surfaces let rays through.
    Alpha,
    /// A fabric's sheen over the base (glTF's KHR_materials_sheen).
    Sheen,
    /// A clear coat over the base (KHR_materials_clearcoat).
    Clearcoat,
    /// Thin-film interference colouring reflections (KHR_materials_iridescence).
    Iridescence,
    /// Highlights stretched along a direction (KHR_materials_anisotropy).
    Anisotropy,
}

impl Effect {
    /// Every effect, in declaration order (the order of [`EffectSet`]'s bits).
    pub const ALL: &'static [Effect] = &[
        Effect::DirectLight,
        Effect::Emission,
        Effect::Environment,
        Effect::Indirect,
        Effect::Glossy,
        Effect::Refraction,
        Effect::Textures,
        Effect::NormalMaps,
        Effect::Alpha,
        Effect::Sheen,
        Effect::Clearcoat,
        Effect::Iridescence,
        Effect::Anisotropy,
    ];

    /// The effect's name in plans and overrides (`direct-light`, `glossy`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Effect::DirectLight => "direct-light",
            Effect::Emission => "emission",
            Effect::Environment => "environment",
            Effect::Indirect => "indirect",
            Effect::Glossy => "glossy",
            Effect::Refraction => "refraction",
            Effect::Textures => "textures",
            Effect::NormalMaps => "normal-maps",
            Effect::Alpha => "alpha",
            Effect::Sheen => "sheen",
            Effect::Clearcoat => "clearcoat",
            Effect::Iridescence => "iridescence",
            Effect::Anisotropy => "anisotropy",
        }
    }

    /// The layers of glTF's material besides its base: each is simulated
    /// only where a material has it, and forcing one on where none has it
    /// changes nothing.
    pub const LAYERS: &'static [Effect] = &[Effect::Sheen, Effect::Clearcoat, Effect::Iridescence, Effect::Anisotropy];

    /// Whether `material` has the layer `self` (false for effects that are not layers).
    pub fn layer_of(self, material: &Material) -> bool {
        match self {
            Effect::Sheen => material.sheen.is_some(),
            Effect::Clearcoat => material.clearcoat.is_some(),
            Effect::Iridescence => material.iridescence.is_some(),
            Effect::Anisotropy => material.anisotropy.is_some(),
            _ => false,
        }
    }
}

impl rtgi_math::NamedChoice for Effect {
    const KIND: &'static str = "effect";
    const ALL: &'static [Self] = Effect::ALL;
    fn name(self) -> &'static str {
        Effect::name(self)
    }
}

impl std::fmt::Display for Effect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Effect {
    type Err = String;

    /// The choice named `text` ([`rtgi_math::parse_choice`]).
    fn from_str(text: &str) -> Result<Self, String> {
        rtgi_math::parse_choice(text)
    }
}

/// Effects the user forces on (`+name`) or off (`-name`), parsed from a
/// comma-separated list such as `+glossy,-textures`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EffectOverrides {
    /// Effects forced on, whatever the scene needs.
    pub on: EffectSet,
    /// Effects forced off, whatever the scene needs.
    pub off: EffectSet,
}

impl FromStr for EffectOverrides {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let mut overrides = EffectOverrides::default();
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (set, name) = if let Some(name) = item.strip_prefix('+') {
                (&mut overrides.on, name)
            } else if let Some(name) = item.strip_prefix('-') {
                (&mut overrides.off, name)
            } else {
                return Err(format!("'{item}': write +effect to force an effect on, -effect to force it off"));
            };
            let effect: Effect = name.parse()?;
            set.insert(effect);
        }
        if let Some(both) = overrides.on.intersection(overrides.off).iter().next() {
            return Err(format!("effect '{both}' is forced both on and off"));
        }
        Ok(overrides)
    }
}

/// Serialises a named choice by its name, as the command line spells it.
fn as_name<S: serde::Serializer>(value: &impl fmt::Display, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_str(value)
}

/// One line of a plan.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PlannedEffect {
    #[serde(serialize_with = "as_name")]
    /// The effect decided on.
    pub effect: Effect,
    /// Whether the render simulates it.
    pub enabled: bool,
    /// Whether the user's override decided, against what the scene needs.
    pub forced: bool,
    /// Why the effect is simulated or not.
    pub reason: String,
    /// Whether anything in the scene calls for the effect at all: false for
    /// a material layer no material has, which the printed plan leaves out.
    #[serde(skip)]
    pub applies: bool,
}

/// Which effects a render simulates, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectPlan {
    #[serde(serialize_with = "as_name")]
    /// The integrator the plan is for (only light transport simulates light).
    pub integrator: Integrator,
    /// Every effect with the decision and its reason, in the order of [`Effect::ALL`].
    pub effects: Vec<PlannedEffect>,
    /// The scene has no light of its own, so a uniform white environment
    /// lights it (unless the environment is forced off).
    pub default_environment: bool,
    /// Bounces the integrator follows after the camera ray.
    pub max_depth: u32,
    /// The clamp on light brought in after two or more bounces
    /// ([`RenderSettings::indirect_clamp`]), when indirect light is simulated.
    pub indirect_clamp: Option<f32>,
    /// Path regularisation ([`RenderSettings::filter_glossy`]),
    /// when indirect light is simulated and some lobe is sharp enough to widen.
    pub filter_glossy: Option<crate::FilterGlossy>,
}

/// The effects whose code the light-transport loop is compiled with or
/// without: the renderer has one loop per subset of them
/// ([`EffectPlan::specialisation`]). The other effects are tested at run
/// time, where their cost is small. Two of the set stand for more than
/// themselves: [`Effect::Glossy`] for every lobe besides Lambert's
/// (refraction too), [`Effect::Emission`] for every light picked up where a
/// ray ends (the environment's too).
pub const SPECIALISED: EffectSet =
    EffectSet::of(&[Effect::Alpha, Effect::Textures, Effect::Glossy, Effect::DirectLight, Effect::Emission]);

/// One decision of a plan reversed: an effect the plan simulates, forced
/// off, or one it leaves out, forced on.
#[derive(Clone, Debug, PartialEq)]
pub struct Reversal {
    /// The effect whose decision is reversed.
    pub effect: Effect,
    /// Whether the plan simulates the effect (and the reversal forces it off).
    pub planned: bool,
    /// The render's settings with the reversing override added.
    pub settings: RenderSettings,
}

impl Reversal {
    /// `-effect` for an effect forced off, `+effect` for one forced on.
    pub fn label(&self) -> String {
        format!("{}{}", if self.planned { '-' } else { '+' }, self.effect)
    }
}

fn names(materials: &[&Material]) -> String {
    let mut list: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
    list.dedup();
    let shown = list.iter().take(4).map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ");
    if list.len() > 4 { format!("{shown} and {} more", list.len() - 4) } else { shown }
}

/// `verb` in the singular for one subject, else its plural (the form without the final s).
fn agree(n: usize, verb: &str) -> &str {
    if n == 1 { verb } else { verb.strip_suffix('s').unwrap_or(verb) }
}

fn count(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

/// The materials that some triangle uses: an unused material needs nothing.
pub(crate) fn materials_in_use(scene: &Scene) -> Vec<&Material> {
    let mut used = vec![false; scene.materials.len()];
    for t in &scene.triangles {
        if let Some(u) = used.get_mut(t.material as usize) {
            *u = true;
        }
    }
    scene.materials.iter().zip(&used).filter(|(_, u)| **u).map(|(m, _)| m).collect()
}

/// Whether a material shows its surroundings: a specular lobe, metal, or
/// smooth (stricter than [`is_glossy`], for which every metallic-roughness
/// material has a lobe besides diffuse).
pub(crate) fn reflects_surroundings(m: &Material) -> bool {
    match m.model {
        SurfaceModel::DiffuseSpecular => m.specular.max_element() > 0.0,
        SurfaceModel::MetallicRoughness => m.metallic >= 0.5 || m.roughness < 0.5,
    }
}

/// Whether a material has a lobe besides diffuse reflection.
pub(crate) fn is_glossy(m: &Material) -> bool {
    match m.model {
        SurfaceModel::DiffuseSpecular => m.specular.max_element() > 0.0,
        SurfaceModel::MetallicRoughness => true,
    }
}

pub(crate) fn transmits(m: &Material) -> bool {
    match m.model {
        SurfaceModel::DiffuseSpecular => m.transmission > 0.0,
        // A metallic-roughness texture can make parts of a "metal" dielectric.
        SurfaceModel::MetallicRoughness => {
            m.transmission > 0.0 && (m.metallic < 1.0 || m.metallic_roughness_texture.is_some())
        }
    }
}

fn is_textured(m: &Material) -> bool {
    !m.textures().is_empty()
}

/// The materials (of those in use) that have the layer `layer`.
fn with_layer<'m>(used: &[&'m Material], layer: Effect) -> Vec<&'m Material> {
    used.iter().copied().filter(|m| layer.layer_of(m)).collect()
}

/// Emitters whose power is below this fraction of what the default sky
/// would bring to the scene do not count as lighting it.
pub const WEAK_EMITTERS: f32 = 0.01;

/// The power (luminance, in the scene's units × area) that the scene's
/// untextured emissive triangles give off from their front faces.
fn emitted_power(scene: &Scene) -> f32 {
    let luminance = |c: rtgi_math::Vec3| c.dot(rtgi_math::Vec3::new(0.2126, 0.7152, 0.0722));
    scene
        .triangles
        .iter()
        .filter_map(|t| {
            let material = scene.materials.get(t.material as usize)?;
            if !material.is_emissive() || material.emission_texture.is_some() {
                return None;
            }
            let [a, b, c] = t.vertices.map(|v| scene.vertices[v as usize].position);
            let area = 0.5 * (b - a).cross(c - a).length();
            Some(std::f32::consts::PI * area * luminance(material.emission)).filter(|p| p.is_finite())
        })
        .sum()
}

/// The power a sky of radiance 1 would bring onto the scene's bounding
/// box: π times its surface area (each face facing open sky receives an
/// irradiance of π).
fn default_sky_power(scene: &Scene) -> f32 {
    let bounds = scene.bounds();
    if bounds.is_empty() {
        return 0.0;
    }
    let e = bounds.extent();
    std::f32::consts::PI * 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

impl EffectPlan {
    /// Plans a render of `scene` with `settings`.
    pub fn new(scene: &Scene, settings: &RenderSettings) -> Self {
        let used = materials_in_use(scene);
        let with =
            |test: fn(&Material) -> bool| -> Vec<&Material> { used.iter().copied().filter(|m| test(m)).collect() };
        let lighting = settings.integrator.simulates_light();
        let integrator = settings.integrator;
        let not_lit = || format!("the {integrator} integrator computes no lighting");
        let overrides = &settings.effects;
        let mut effects = Vec::new();
        let mut decide = |effect: Effect, needed: bool, reason: String| {
            let forced_on = overrides.on.contains(effect);
            let forced_off = overrides.off.contains(effect);
            let enabled = (needed || forced_on) && !forced_off;
            let forced = enabled != needed;
            let reason = match (forced_on, forced_off) {
                (true, _) if !needed => format!("forced on ({reason})"),
                (_, true) if needed => format!("forced off ({reason})"),
                _ => reason,
            };
            effects.push(PlannedEffect { effect, enabled, forced, reason, applies: true });
            enabled
        };

        let emitters = with(Material::is_emissive);
        let triangles_with = |test: fn(&Material) -> bool| {
            scene.triangles.iter().filter(|t| scene.materials.get(t.material as usize).is_some_and(test)).count()
        };
        let emissive_triangles = triangles_with(Material::is_emissive);
        let unlit = with(|m| m.unlit);
        let unlit_triangles = triangles_with(|m| m.unlit);
        let emission = if !lighting {
            decide(Effect::Emission, false, not_lit())
        } else if emissive_triangles > 0 || unlit_triangles > 0 {
            let mut reasons = Vec::new();
            if emissive_triangles > 0 {
                reasons.push(format!(
                    "{} of {} {}",
                    count(emissive_triangles, "triangle"),
                    names(&emitters),
                    agree(emissive_triangles, "emits")
                ));
            }
            if unlit_triangles > 0 {
                reasons.push(format!(
                    "{} of {} {} unlit (KHR_materials_unlit): the view sees their colour unshaded",
                    count(unlit_triangles, "triangle"),
                    names(&unlit),
                    if unlit_triangles == 1 { "is" } else { "are" }
                ));
            }
            decide(Effect::Emission, true, reasons.join("; "))
        } else {
            decide(Effect::Emission, false, "no material emits".into())
        };

        let lights = scene.lights.len();
        let environment_given = settings.environment.is_some();
        // Emission through a texture is how glTF models glowing details (a
        // helmet's displays), not how they light a scene; such scenes are
        // meant to be seen under an environment.
        // Emitters too weak to light the view (a few glowing blocks in a
        // world) keep the default sky and sun, as if there were none.
        let emitted = emitted_power(scene);
        let sky_power = default_sky_power(scene);
        let weak_emitters = emitted > 0.0 && emitted < WEAK_EMITTERS * sky_power;
        let lit_by_emitters = emitters.iter().any(|m| m.emission_texture.is_none()) && !weak_emitters;
        let view_unlit = match settings.default_lighting {
            crate::DefaultLighting::ViewUnlit(fraction) => Some(fraction),
            _ => None,
        };
        let default_lighting_off = settings.default_lighting == crate::DefaultLighting::Off;
        let wants_default = (lights == 0 && !lit_by_emitters) || view_unlit.is_some();
        let default_environment = lighting && !environment_given && !default_lighting_off && wants_default;
        let environment = if !lighting {
            decide(Effect::Environment, false, not_lit())
        } else if let crate::DefaultLighting::Reflections(radiance) = settings.default_lighting {
            let reason = format!(
                "the scene's lights are all punctual and glossy or metal surfaces would reflect black, so a dim \
                 grey environment (radiance {radiance:.3}, a tenth of their light on the view) gives them \
                 something to reflect; --environment or --no-default-lighting chooses otherwise"
            );
            decide(Effect::Environment, true, reason)
        } else if environment_given {
            decide(Effect::Environment, true, "an environment is set".into())
        } else if default_environment {
            let why = if let Some(fraction) = view_unlit {
                format!(
                    "the scene's own lights give the surfaces in view {:.1}% of the light a sky and sun would, too \
                     little to see them by (--no-default-lighting keeps to the scene's own)",
                    100.0 * fraction
                )
            } else if weak_emitters {
                format!(
                    "the scene's emitters give {:.2}% of the light a sky would, too little to light it",
                    100.0 * emitted / sky_power
                )
            } else if emissive_triangles > 0 {
                "the scene has no lights or untextured emitters".to_owned()
            } else {
                "the scene has no lights or emitters".to_owned()
            };
            let reason = format!(
                "{why}, so a default sky (blue overhead, grey ground) and a sun from the upper front right light \
                 it; --environment or --light chooses others"
            );
            decide(Effect::Environment, true, reason)
        } else if default_lighting_off && lighting && wants_default {
            decide(
                Effect::Environment,
                false,
                "the scene brings too little light of its own, but default lighting is off (--no-default-lighting)"
                    .into(),
            )
        } else {
            decide(Effect::Environment, false, "no environment is set (--environment sets one)".into())
        };

        let direct = if !lighting {
            decide(Effect::DirectLight, false, not_lit())
        } else {
            let mut sources = Vec::new();
            if lights > 0 {
                sources.push(count(lights, "light"));
            }
            if emission {
                sources.push(count(emissive_triangles, "emissive triangle"));
            }
            if environment {
                sources.push(if default_environment { "the default sun and sky" } else { "the environment" }.into());
            }
            if sources.is_empty() {
                decide(Effect::DirectLight, false, "nothing emits light".into())
            } else {
                decide(Effect::DirectLight, true, format!("shadow rays towards {}", sources.join(", ")))
            }
        };

        let reflective: Vec<&Material> = used
            .iter()
            .copied()
            .filter(|m| m.base_color.max_element() > 0.0 || m.specular.max_element() > 0.0 || transmits(m))
            .collect();
        let max_depth = settings.max_depth;
        let indirect = if integrator != Integrator::Path {
            decide(Effect::Indirect, false, format!("the {integrator} integrator stops at the first surface"))
        } else if max_depth < 2 {
            decide(Effect::Indirect, false, "--max-depth is below 2".into())
        } else if !(direct || emission || environment) {
            decide(Effect::Indirect, false, "there is no light to bounce".into())
        } else if reflective.is_empty() {
            decide(Effect::Indirect, false, "no surface reflects or transmits light".into())
        } else {
            decide(
                Effect::Indirect,
                true,
                format!("up to {max_depth} bounces off {}", count(reflective.len(), "material")),
            )
        };

        let glossy = with(is_glossy);
        let glossy_enabled = if !lighting {
            decide(Effect::Glossy, false, not_lit())
        } else if glossy.is_empty() {
            decide(Effect::Glossy, false, "every material is diffuse".into())
        } else {
            // MTL sums beyond 1 are scaled down as the surfaces are shaded (`energy_conserving`); say so.
            let excess = |m: &Material| (m.base_color + m.specular).max_element();
            let bright: Vec<&Material> = glossy
                .iter()
                .copied()
                .filter(|m| m.model == SurfaceModel::DiffuseSpecular && excess(m) > 1.0)
                .collect();
            let scaled = match bright.iter().map(|m| excess(m)).reduce(f32::max) {
                Some(most) => format!(
                    "; {} of them {} more than {} {} (Kd + Ks up to {most:.2}), scaled down to reflect at most all: {}",
                    bright.len(),
                    agree(bright.len(), "reflects"),
                    if bright.len() == 1 { "it" } else { "they" },
                    agree(bright.len(), "receives"),
                    names(&bright)
                ),
                None => String::new(),
            };
            decide(
                Effect::Glossy,
                true,
                format!(
                    "{} {} specularly: {}{scaled}",
                    count(glossy.len(), "material"),
                    agree(glossy.len(), "reflects"),
                    names(&glossy)
                ),
            )
        };

        let refracting = with(transmits);
        if !lighting {
            decide(Effect::Refraction, false, not_lit());
        } else if refracting.is_empty() {
            decide(Effect::Refraction, false, "no material transmits".into());
        } else {
            let n = refracting.len();
            let reason = format!("{} {}: {}", count(n, "material"), agree(n, "transmits"), names(&refracting));
            decide(Effect::Refraction, true, reason);
        }

        let textured = with(is_textured);
        let textures = if textured.is_empty() {
            decide(Effect::Textures, false, "no material is textured".into())
        } else {
            decide(
                Effect::Textures,
                true,
                format!("{} textured: {}", count(textured.len(), "material"), names(&textured)),
            )
        };

        let normal_mapped = with(|m| m.normal_texture.is_some());
        if !lighting {
            decide(Effect::NormalMaps, false, not_lit());
        } else if !textures {
            decide(Effect::NormalMaps, false, "textures are off".into());
        } else if normal_mapped.is_empty() {
            decide(Effect::NormalMaps, false, "no material has a normal map".into());
        } else {
            let reason = format!("{} normal-mapped: {}", count(normal_mapped.len(), "material"), names(&normal_mapped));
            decide(Effect::NormalMaps, true, reason);
        }

        let masked = with(|m| m.alpha_mode != AlphaMode::Opaque);
        if masked.is_empty() {
            decide(Effect::Alpha, false, "every material is opaque".into());
        } else {
            decide(
                Effect::Alpha,
                true,
                format!("{} with alpha (mask or blend): {}", count(masked.len(), "material"), names(&masked)),
            );
        }

        for &layer in Effect::LAYERS {
            let layered = with_layer(&used, layer);
            if !lighting {
                decide(layer, false, not_lit());
            } else if layered.is_empty() {
                decide(layer, false, format!("no material has {layer}"));
            } else if !glossy_enabled {
                decide(layer, false, format!("glossy reflection is off, and {layer} is a glossy layer"));
            } else {
                let n = layered.len();
                decide(
                    layer,
                    true,
                    format!(
                        "{} {} {layer}: {}",
                        count(n, "material"),
                        if n == 1 { "has" } else { "have" },
                        names(&layered)
                    ),
                );
            }
        }

        for e in effects.iter_mut() {
            if Effect::LAYERS.contains(&e.effect) && !e.forced && with_layer(&used, e.effect).is_empty() {
                e.applies = false;
            }
        }

        let default_environment = default_environment && environment;
        let max_depth = if indirect { max_depth } else { max_depth.min(1) };
        let indirect_clamp = settings.indirect_clamp.filter(|_| indirect);
        // Only glossy and transmitting lobes can be widened.
        let sharp_lobes = effects.iter().any(|e| e.enabled && matches!(e.effect, Effect::Glossy | Effect::Refraction));
        let filter_glossy = settings.filter_glossy.filter(|_| indirect && sharp_lobes);
        Self { integrator, effects, default_environment, max_depth, indirect_clamp, filter_glossy }
    }

    /// The effects the plan simulates.
    pub fn enabled(&self) -> EffectSet {
        self.effects.iter().filter(|e| e.enabled).map(|e| e.effect).collect()
    }

    /// Whether the plan simulates `effect`.
    pub fn has(&self, effect: Effect) -> bool {
        self.enabled().contains(effect)
    }

    /// The effects the plan leaves out.
    pub fn omitted(&self) -> EffectSet {
        EffectSet::ALL.difference(self.enabled())
    }

    /// The loop the renderer runs for this plan: the subset of
    /// [`SPECIALISED`] whose code it needs.
    pub fn specialisation(&self) -> EffectSet {
        let enabled = self.enabled();
        let mut loop_effects = enabled.intersection(SPECIALISED);
        // Refraction runs in the same non-Lambert code as glossy lobes.
        if enabled.contains(Effect::Refraction) {
            loop_effects.insert(Effect::Glossy);
        }
        // The environment is light picked up where a ray leaves the scene, as emission is where it ends on an emitter.
        if enabled.contains(Effect::Environment) {
            loop_effects.insert(Effect::Emission);
        }
        loop_effects
    }

    /// Every decision of the plan (for `scene` and `settings`) that the
    /// user did not force, reversed, in the order of [`Effect::ALL`].
    /// Decisions that cannot be reversed alone (normal maps while textures
    /// are off) are left out.
    pub fn reversals(&self, scene: &Scene, settings: &RenderSettings) -> Vec<Reversal> {
        let forced = settings.effects.on.union(settings.effects.off);
        let enabled = self.enabled();
        EffectSet::ALL
            .difference(forced)
            .iter()
            .filter_map(|effect| {
                let planned = enabled.contains(effect);
                // Forcing on a layer no material has would change nothing.
                if !planned && Effect::LAYERS.contains(&effect) && !scene.materials.iter().any(|m| effect.layer_of(m)) {
                    return None;
                }
                let mut effects = settings.effects.clone();
                if planned {
                    effects.off.insert(effect);
                } else {
                    effects.on.insert(effect);
                }
                let settings = RenderSettings { effects, ..settings.clone() };
                (EffectPlan::new(scene, &settings).has(effect) != planned).then_some(Reversal {
                    effect,
                    planned,
                    settings,
                })
            })
            .collect()
    }
}

impl fmt::Display for EffectPlan {
    /// One line per effect: `+` simulated, `-` left out, `!` where an
    /// override decided, with the reason.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let depth = match self.integrator {
            Integrator::Path => format!(", up to {} bounces", self.max_depth),
            _ => String::new(),
        };
        writeln!(f, "plan: {} integrator{depth}", self.integrator)?;
        for e in self.effects.iter().filter(|e| e.applies) {
            let sign = if e.enabled { '+' } else { '-' };
            let forced = if e.forced { '!' } else { ' ' };
            writeln!(f, "  {sign}{forced}{:<13} {}", e.effect.name(), e.reason)?;
        }
        if let Some(clamp) = self.indirect_clamp {
            writeln!(
                f,
                "  clamp         light brought in after two or more bounces is clamped at {clamp}: fewer fireflies, \
                 but caustics and glossy highlights come out darker (biased; leave out --clamp for the exact image)"
            )?;
        }
        if let Some(filter) = self.filter_glossy {
            writeln!(
                f,
                "  filter-glossy after a bounce of density below {}, {} are widened: fewer fireflies from \
                 caustics, but they come out blurred (biased; --filter-glossy 0 keeps the exact image)",
                filter.threshold,
                filter.lobes()
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_parse() {
        let o: EffectOverrides = "+glossy, -textures,+alpha".parse().unwrap();
        assert_eq!(o.on, EffectSet::of(&[Effect::Glossy, Effect::Alpha]));
        assert_eq!(o.off, EffectSet::of(&[Effect::Textures]));
        assert!("glossy".parse::<EffectOverrides>().unwrap_err().contains("+effect"));
        assert!("+shiny".parse::<EffectOverrides>().unwrap_err().contains("unknown effect 'shiny'"));
        assert!("+alpha,-alpha".parse::<EffectOverrides>().is_err());
        assert_eq!("".parse::<EffectOverrides>().unwrap(), EffectOverrides::default());
    }
}
