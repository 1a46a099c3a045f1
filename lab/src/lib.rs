//! The photon-fpga lab: the measurements behind the docs, built on the product
//! crate (`photon_fpga`) and never imported by it. The workloads (`workload`, and
//! the two-pass render's lookups, `lookups`), the
//! CPU yardstick (`cpu_ref`, kiddo), the banked store's bank-conflict model and its
//! simulated sweeps (`banking`), and the speed-against-error study (`study`).
//!
//! Layers, lowest first (tests/layers.rs checks them): `workload`, `cpu_ref`,
//! `lookups`, `core_run` →
//! `banking`, `study` → `cli`.

pub mod banking;
pub mod cli;
pub mod core_run;
pub mod cpu_ref;
pub mod lookups;
pub mod memory;
pub mod study;
pub mod workload;
