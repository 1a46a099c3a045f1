//! The renderer: scene (geometry, the TOML scene file, its scale), photon tracing,
//! eye rays to gather queries and images from the gathered photons.

pub mod geometry;
pub mod l1_area;
pub mod photons;
pub mod renderer;
pub mod scene;
pub mod scene_file;
pub mod scene_scale;

pub use renderer::*;
