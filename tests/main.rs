//! The host-side tests in one test binary: the banked store's model, the software
//! kNN against brute force, the exact re-ranking against the float search, the
//! renderer, the CLI (end to end through the binary, with its error paths), the
//! `rtl` backend through the CLI, the layering of the source tree, numerical
//! stability of the radiance estimate, `photon-fpga study` and the two-pass render.

mod banking;
mod cli;
mod exact;
mod knn;
mod layers;
mod render;
mod rtl;
mod stability;
mod study;
mod study_exact;
mod two_pass;
