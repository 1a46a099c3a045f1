//! The subcommands that are more than a call into the library; `main.rs` parses
//! and dispatches.

pub mod banking;
pub mod bench_banks;
pub mod bench_core;
pub mod core_args;
pub mod export;
pub mod gather;
pub mod gather_opts;
pub mod render;
pub mod study;
pub mod values;

#[cfg(test)]
mod help_test;

use photon_fpga::host::error::{Error, Result};

/// `--threads`: the size of rayon's global pool (results do not depend on it).
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    if let Some(t) = threads {
        if t == 0 {
            return Err(Error::new("--threads must be at least 1, got 0"));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build_global()
            .map_err(|e| Error::new(format!("cannot start {t} threads: {e}")))?;
    }
    Ok(())
}
