//! A [`RenderRequest`] as the `rtgi render` command that makes it: what a
//! script prints beside its render (`the same as  rtgi render ...`), so
//! that the command can be run, split or put on a cluster. Only options
//! that differ from their defaults are written; parsing the words back
//! gives the same request (a test checks it).

use rtgi_job::{Denoise, RenderRequest, SceneSource, Structure, default_lighting};
use rtgi_math::Vec3;
use rtgi_render::EnvironmentSpec;

/// The `rtgi render` command of a request, as words (without `rtgi`).
pub(crate) trait CommandLine {
    fn to_command_line(&self) -> Vec<String>;
}

fn comma(v: Vec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

impl CommandLine for RenderRequest {
    fn to_command_line(&self) -> Vec<String> {
        let mut words: Vec<String> = vec!["render".into()];
        let mut push = |option: &str, value: Option<String>| {
            words.push(format!("--{option}"));
            words.extend(value);
        };
        let defaults = RenderRequest::new(SceneSource::BuiltIn, "");
        if let SceneSource::File { options, .. } = &self.scene {
            if options.allow_outside_folder {
                push("allow-outside-scene", None);
            }
            if let Some(variant) = &options.gltf_variant {
                push("variant", Some(variant.clone()));
            }
        }
        push("output", Some(self.output.display().to_string()));
        if let Some(width) = self.size.width {
            push("width", Some(width.to_string()));
        }
        if let Some(height) = self.size.height {
            push("height", Some(height.to_string()));
        }
        let sampling = &self.sampling;
        if let Some(spp) = sampling.samples_per_pixel {
            push("spp", Some(spp.to_string()));
        }
        if let Some(noise) = sampling.noise {
            push("noise", Some(noise.to_string()));
        }
        if let Some(time) = sampling.time {
            push("time", Some(time.to_string()));
        }
        if let Some(sampler) = sampling.sampler {
            push("sampler", Some(sampler.name().into()));
        }
        if sampling.seed != 0 {
            push("seed", Some(sampling.seed.to_string()));
        }

        let (l, d) = (&self.lighting, default_lighting());
        if l.integrator != d.integrator {
            push("integrator", Some(l.integrator.name().into()));
        }
        if l.max_depth != d.max_depth {
            push("max-depth", Some(l.max_depth.to_string()));
        }
        if l.roulette_start != d.roulette_start {
            push("roulette-start", Some(l.roulette_start.to_string()));
        }
        if l.bounce_sampling != d.bounce_sampling {
            push("bounce-sampling", Some(l.bounce_sampling.name().into()));
        }
        if l.direct_strategy != d.direct_strategy {
            push("direct-strategy", Some(l.direct_strategy.name().into()));
        }
        if let Some(clamp) = l.indirect_clamp {
            push("clamp-indirect", Some(clamp.to_string()));
        }
        if let Some(filter) = l.filter_glossy {
            push("filter-glossy", Some(filter.threshold.to_string()));
        }
        match &l.environment {
            Some(EnvironmentSpec::Uniform(radiance)) => push("environment", Some(comma(*radiance))),
            Some(EnvironmentSpec::File(path)) => push("environment", Some(path.display().to_string())),
            None => {}
        }
        if l.environment_scale != d.environment_scale {
            push("environment-scale", Some(l.environment_scale.to_string()));
        }
        for light in &l.lights {
            // A light made from a specification is named by it.
            push("light", Some(light.name.clone()));
        }
        let effects: Vec<String> = (l.effects.on.iter().map(|e| format!("+{e}")))
            .chain(l.effects.off.iter().map(|e| format!("-{e}")))
            .collect();
        if !effects.is_empty() {
            push("effects", Some(effects.join(",")));
        }
        if l.no_default_lighting {
            push("no-default-lighting", None);
        }
        if !self.aovs.is_empty() {
            let aovs: Vec<&str> = self.aovs.iter().map(|a| a.name()).collect();
            push("aov", Some(aovs.join(",")));
        }
        if self.background != defaults.background {
            push("background", Some(comma(self.background)));
        }

        let camera = &self.camera;
        if let Some(index) = camera.index {
            push("camera", Some(index.to_string()));
        }
        for (option, value) in [("at", camera.at), ("look", camera.look), ("up", camera.up)] {
            if let Some(value) = value {
                push(option, Some(comma(value)));
            }
        }
        if let Some(fov) = camera.fov_degrees {
            push("fov", Some(fov.to_string()));
        }

        let (s, sd) = (&self.structure, Structure::of(self.structure.kind));
        if s.kind != defaults.structure.kind {
            push("accel", Some(s.kind.name().into()));
        }
        if let Some(leaf) = s.leaf_size {
            push("leaf-size", Some(leaf.to_string()));
        }
        if s.sah_bins != sd.sah_bins {
            push("sah-bins", Some(s.sah_bins.to_string()));
        }
        if s.sah_axes != sd.sah_axes {
            push("sah-axes", Some(s.sah_axes.name().into()));
        }
        if let Some(cost) = s.traversal_cost {
            push("traversal-cost", Some(cost.to_string()));
        }
        if s.intersector != sd.intersector {
            push("intersector", Some(s.intersector.name().into()));
        }
        if s.traversal != sd.traversal {
            push("traversal", Some(s.traversal.name().into()));
        }

        if let Some(operator) = self.tone.operator {
            push("tonemap", Some(operator.name().into()));
        }
        if let Some(exposure) = self.tone.exposure {
            push("exposure", Some(exposure.to_string()));
        }
        match self.denoise {
            Denoise::Auto => {}
            Denoise::On => push("denoise", Some("on".into())),
            Denoise::Off => push("denoise", Some("off".into())),
        }
        if let Some(samples) = &self.split.samples {
            push("samples", Some(format!("{}..{}", samples.start, samples.end)));
        }
        if let Some((index, count)) = self.split.tile {
            push("tile", Some(format!("{index}/{count}")));
        }
        let checkpoints = &self.checkpoints;
        if let Some(limit) = checkpoints.time_limit {
            push("time-limit", Some(limit.to_string()));
        }
        if let Some(path) = &checkpoints.checkpoint {
            push("checkpoint", Some(path.display().to_string()));
        }
        if checkpoints.every_seconds != defaults.checkpoints.every_seconds {
            push("checkpoint-every", Some(checkpoints.every_seconds.to_string()));
        }
        if let Some(path) = &checkpoints.resume {
            push("resume", Some(path.display().to_string()));
        }
        if let Some(threads) = self.threads {
            push("threads", Some(threads.to_string()));
        }
        if let Some(path) = self.scene.path() {
            words.insert(1, path.display().to_string());
        }
        words
    }
}

/// Words as a shell would need them: quoted where they hold spaces or
/// characters the shell reads.
pub(crate) fn shell_words(words: &[String]) -> String {
    let quote = |word: &String| {
        if !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || "-_.,/:+=@%".contains(c)) {
            word.clone()
        } else {
            format!("'{}'", word.replace('\'', r"'\''"))
        }
    };
    words.iter().map(quote).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_quoted_for_the_shell() {
        let words: Vec<String> = ["render", "a b.obj", "--at", "1,-2,3", "it's"].map(String::from).into();
        assert_eq!(shell_words(&words), r"render 'a b.obj' --at 1,-2,3 'it'\''s'");
    }
}
