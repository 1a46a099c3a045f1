//! The host side (paper §4): the photon map (`map`), the gather backends that run
//! it in software or on the simulated core (`gather`, `csvio`), their exact
//! re-ranking (`exact`), the renderer
//! (`render`) and the shared plumbing (errors, limits, atomic output, timing).
//!
//! Layers, lowest first (tests/layers.rs checks them): `error`, `limits`,
//! `output`, `stages` → `map` → `gather`, `csvio`, `exact` → `render` → `workload`, `study`, `banking`.

pub mod csvio;
pub mod device;
pub mod error;
pub mod exact;
pub mod gather;
pub mod limits;
pub mod map;
pub mod output;
pub mod render;
pub mod stages;
