//! `photon-fpga-lab`: the measurements behind the docs and synth/REPORT.md.

use clap::{Parser, Subcommand};
use photon_fpga::host::output::remove_on_interrupt;
use photon_fpga_lab::cli::banking::{banking, BankingArgs};
use photon_fpga_lab::cli::bench_banks::{bench_banks, BenchBanksArgs};
use photon_fpga_lab::cli::bench_core::{bench_core, BenchCoreArgs};
use photon_fpga_lab::cli::memory::{memory, MemoryArgs};
use photon_fpga_lab::cli::memory_core::{memory_core, MemoryCoreArgs};
use photon_fpga_lab::cli::study::{study, StudyArgs};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "photon-fpga-lab", version, about)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Simulate a core on a workload (random map or Cornell box): reads per cycle and
    /// per query against the software search, cycles/s; --cpu times kiddo beside it.
    BenchCore(BenchCoreArgs),
    /// Speed against error: sweep bits, metric, k and photons; write the table,
    /// the Pareto plot and the paper's Figs. 3-6.
    Study(StudyArgs),
    /// The banked photon store's bank conflicts, measured on the direct render's
    /// read stream (bank mappings, query orders, D datapaths x B banks); writes
    /// docs/BANKING.md.
    Banking(BankingArgs),
    /// The banked core simulated (every answer checked): reads per cycle against D
    /// datapaths x B banks, and queries/s against map size for a device's plan;
    /// writes docs/BANKED_CORE.md, its CSV and two plots.
    BenchBanks(BenchBanksArgs),
    /// The photon map in external memory behind an on-chip cache, modelled: hit rate,
    /// DRAM bytes and reads per cycle against layout, cache and query order; writes
    /// docs/MEMORY.md.
    Memory(MemoryArgs),
    /// The external-memory core simulated (Verilator, the memory model; every
    /// answer checked) against map size, memory bandwidth, k and query order, kiddo
    /// beside it; writes docs/memory_core.{csv,md} and two plots.
    MemoryCore(MemoryCoreArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = remove_on_interrupt().and_then(|()| match &cli.cmd {
        Cmd::BenchCore(a) => bench_core(a),
        Cmd::Study(a) => study(a),
        Cmd::Banking(a) => banking(a),
        Cmd::BenchBanks(a) => bench_banks(a),
        Cmd::Memory(a) => memory(a),
        Cmd::MemoryCore(a) => memory_core(a),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
