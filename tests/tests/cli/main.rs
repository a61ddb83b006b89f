//! The `rtgi` command run as a process, as a new user runs it: first looks,
//! outputs, hostile input, long renders, lights, the structures (Embree with
//! the `embree` feature) and the course's scripts.
//!
//! One test binary for the theme, a module a file.

mod accel;
mod basics;
mod embree;
mod first_look;
mod hostile;
mod light;
mod long_render;
mod outputs;
mod script;
