//! The host-side tests in one test binary: the software kNN against brute force,
//! the exact re-ranking against the float search, the renderer, the CLI (end to
//! end through the binary, with its error paths), the simulated backends through
//! the CLI, the layering of the source tree, numerical
//! stability of the radiance estimate and the two-pass render (its final gather by
//! photon lookups and by precomputed irradiance).

mod cli;
mod exact;
mod knn;
mod layers;
mod refusals;
mod render;
mod rtl;
mod stability;
mod two_pass;
mod two_pass_irradiance;
