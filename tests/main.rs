//! The host-side tests in one test binary: the software kNN against brute force,
//! the renderer, the CLI (end to end through the binary, with its error paths), the
//! `rtl` backend through the CLI, and the layering of the source tree.

mod cli;
mod knn;
mod layers;
mod render;
mod rtl;
