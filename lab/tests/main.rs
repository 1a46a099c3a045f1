//! The lab's tests in one test binary: the bank model and its simulated sweeps, the
//! external-memory cache model, the workloads' throughput on the simulated core,
//! bench-core, the study and its exact series.

// The hardware testbenches' helpers (checks against the software search and brute
// force), shared rather than copied.
#[path = "../../testbenches/common/mod.rs"]
mod common;

// The product's check of a refused run, shared.
#[path = "../../tests/refusals.rs"]
mod refusals;

mod bank_map;
mod banking;
mod bench_banks;
mod bench_core;
mod block_map;
mod cli;
mod memory;
mod study;
mod study_exact;
mod throughput;
