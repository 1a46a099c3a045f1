//! The host side (paper §4): scene, photon tracing, kd-tree build and packing,
//! software kNN reference, renderer and the gather backends.

pub mod cpu_ref;
pub mod csvio;
pub mod error;
pub mod gather;
pub mod geometry;
pub mod kdtree;
pub mod knn;
pub mod limits;
pub mod output;
pub mod photons;
pub mod quantize;
pub mod render;
pub mod scene;
pub mod scene_file;
pub mod scene_scale;
pub mod stages;
pub mod workload;
