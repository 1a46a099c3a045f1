//! `photon-fpga`: render with photon mapping whose gathers run on the software
//! reference or the simulated FPGA core, or gather a user's own photon map.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod cli;
use cli::banking::{banking, BankingArgs};
use cli::bench_banks::{bench_banks, BenchBanksArgs};
use cli::bench_core::{bench_core, BenchCoreArgs};
use cli::export::{export, ExportArgs};
use cli::gather::{gather, GatherArgs};
use cli::render::{render, RenderArgs};
use cli::study::{study, StudyArgs};

#[derive(Parser)]
#[command(name = "photon-fpga", version, about)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
}

#[derive(Subcommand)]
enum Cmd {
    /// Render a scene with photon mapping (the default command).
    Render(RenderArgs),
    /// Gather the k nearest photons of every query in a CSV photon map.
    Gather(GatherArgs),
    /// Write the photon-search core's Verilog (top module `top`).
    ExportVerilog(ExportArgs),
    /// Simulate a core on a workload (random map or Cornell box): reads per cycle and
    /// per query against the software search, cycles/s; --cpu times kiddo beside it.
    BenchCore(BenchCoreArgs),
    /// Speed against error: sweep bits, metric, k and photons; write the table,
    /// the Pareto plot and the paper's Figs. 3-6.
    Study(StudyArgs),
    /// The banked photon store's bank conflicts, measured on the default render's
    /// read stream (bank mappings, query orders, D datapaths x B banks); writes
    /// docs/BANKING.md.
    Banking(BankingArgs),
    /// The banked core simulated (every answer checked): reads per cycle against D
    /// datapaths x B banks, and queries/s against map size for a device's plan;
    /// writes docs/BANKED_CORE.md, its CSV and two plots.
    BenchBanks(BenchBanksArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.cmd {
        Some(Cmd::Gather(a)) => gather(a),
        Some(Cmd::ExportVerilog(a)) => export(a),
        Some(Cmd::BenchCore(a)) => bench_core(a),
        Some(Cmd::Render(a)) => render(a),
        Some(Cmd::Study(a)) => study(a),
        Some(Cmd::Banking(a)) => banking(a),
        Some(Cmd::BenchBanks(a)) => bench_banks(a),
        None => render(&RenderArgs::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
