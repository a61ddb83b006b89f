//! Rendering: estimators against references and analytic answers,
//! samplers' convergence, determinism across threads and split renders,
//! cut-outs, camera choice and the light a view is given.
//!
//! One test binary for the theme, a module a file.

mod adaptive_sampling;
mod camera_choice;
mod cornell_reference;
mod cutouts;
mod determinism;
mod khronos_models;
mod light_transport;
mod path_regularisation;
mod render_identity;
mod sampler_convergence;
mod shading_normals;
mod split_render;
mod view_lighting;
