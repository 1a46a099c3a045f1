//! The renderer: scene (geometry, the TOML scene file, its scale), photon tracing,
//! eye rays to gather queries and images from the gathered photons; the two-pass
//! method (direct light, caustics, final gathering) beside the direct one.

pub mod caustics;
pub mod direct_light;
pub mod final_gather;
pub mod geometry;
pub mod irradiance;
pub mod l1_area;
pub mod lookup;
pub mod pfm;
pub mod photons;
pub mod renderer;
pub mod scene;
pub mod scene_file;
pub mod scene_scale;
pub mod two_pass;

pub use renderer::*;
