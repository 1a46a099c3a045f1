//! The product's command line: its user jobs (render, gather, export-verilog), one
//! module each, and the option groups they share (`core_args`, `gather_opts`,
//! `values`), which the lab's commands take too; `main.rs` calls [`main`].

pub mod core_args;
pub mod export;
pub mod gather;
pub mod gather_opts;
pub mod render;
pub mod values;

#[cfg(test)]
mod help_test;

use crate::cli::export::{export, ExportArgs};
use crate::cli::gather::{gather, GatherArgs};
use crate::cli::render::{render, RenderArgs};
use crate::host::error::{Error, Result};
use clap::{Parser, Subcommand};
use std::process::ExitCode;

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

#[derive(Parser)]
#[command(name = "photon-fpga", version, about)]
pub struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
}

#[derive(Subcommand)]
pub enum Cmd {
    /// Render a scene with photon mapping (the default command).
    Render(RenderArgs),
    /// Gather the k nearest photons of every query in a CSV photon map.
    Gather(GatherArgs),
    /// Write the photon-search core's Verilog (top module `top`).
    ExportVerilog(ExportArgs),
}

/// Parse the command line and run it: exit status 0, or 2 with `error: …`.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = crate::host::output::remove_on_interrupt().and_then(|()| match &cli.cmd {
        Some(Cmd::Gather(a)) => gather(a),
        Some(Cmd::ExportVerilog(a)) => export(a),
        Some(Cmd::Render(a)) => render(a),
        None => render(&RenderArgs::default()),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
