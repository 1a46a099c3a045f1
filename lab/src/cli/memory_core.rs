//! `photon-fpga-lab memory-core`: the external-memory core simulated (Verilator,
//! the memory model) against map size, memory bandwidth, k and query order, kiddo
//! beside it; writes docs/memory_core.{csv,md}, docs/memory_core_sizes.png and
//! docs/memory_core_bandwidth.png.

use crate::memory::core_report::{bandwidth_plot, csv, parse_csv, size_plot, table};
use crate::memory::core_sweep::{measure, specs};
use clap::Args;
use photon_fpga::cli::render::check_photons_and_spp;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::limits;
use photon_fpga::host::output::Output;
use std::path::PathBuf;

#[derive(Args)]
pub struct MemoryCoreArgs {
    /// Photons emitted for each map of the k = 32 series (the Cornell box stores
    /// about 1.95 a photon emitted).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "32000,128000,512000,1000000,2000000"
    )]
    pub photons: Vec<usize>,
    /// Photons emitted for each map of the k = 500 series.
    #[arg(long, value_delimiter = ',', default_value = "128000,1000000,2000000")]
    pub k500_photons: Vec<usize>,
    /// The map of the bandwidth series (the paper's 1 M emitted, §3).
    #[arg(long, default_value_t = 1_000_000)]
    pub paper_photons: usize,
    /// The image of the k = 32 series (square; its eye-ray hits are the queries):
    /// the direct render's.
    #[arg(long, default_value_t = 256)]
    pub side: u32,
    /// The image of the k = 500 series.
    #[arg(long, default_value_t = 128)]
    pub k500_side: u32,
    /// The cache's lines [default: the ECP5-85k's plan for each map].
    #[arg(long)]
    pub cache_lines: Option<u32>,
    /// The core's clock in MHz for queries/s (a placed-and-routed fmax, or the
    /// memory controller's clock; labelled assumed in the report).
    #[arg(long, default_value_t = 75.0)]
    pub fmax_mhz: f64,
    /// Do not time kiddo (the ratio columns stay empty).
    #[arg(long)]
    pub no_cpu: bool,
    /// Seed of the photon maps and the eye rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Render the table and the plots again from this CSV (an earlier run's
    /// docs/memory_core.csv) instead of simulating; the other options must be
    /// the ones that run was given (its command line is in the table).
    #[arg(long)]
    pub from_csv: Option<PathBuf>,
    /// Where the CSV, the table and the plots go.
    #[arg(long, default_value = "docs")]
    pub out_dir: PathBuf,
}

pub fn memory_core(args: &MemoryCoreArgs) -> Result<()> {
    limits::check_positive("--fmax-mhz", args.fmax_mhz)?;
    for &n in args
        .photons
        .iter()
        .chain(&args.k500_photons)
        .chain([&args.paper_photons])
    {
        check_photons_and_spp(n, 1)?;
    }
    if args.photons.is_empty() {
        return Err(Error::new("--photons: give at least one map"));
    }
    let dir = &args.out_dir;
    let outs = [
        "memory_core.csv",
        "memory_core.md",
        "memory_core_sizes.png",
        "memory_core_bandwidth.png",
    ]
    .map(|f| Output::check(&dir.join(f), &[]));
    let [o_csv, o_md, o_sizes, o_bw] = outs;
    let (o_csv, o_md, _, _) = (o_csv?, o_md?, o_sizes?, o_bw?);
    let mut photons = args.photons.clone();
    if !photons.contains(&args.paper_photons) {
        photons.push(args.paper_photons);
    }
    let mut points = vec![];
    for side in [args.side, args.k500_side] {
        if !(1..=4096).contains(&side) {
            return Err(Error::new(format!(
                "--side and --k500-side must be in 1..=4096, got {side}"
            )));
        }
    }
    let sides = (args.side, args.k500_side);
    if let Some(f) = &args.from_csv {
        let text =
            std::fs::read_to_string(f).map_err(|e| Error::new(format!("{}: {e}", f.display())))?;
        points = parse_csv(&text).ok_or_else(|| {
            Error::new(format!(
                "{}: not a CSV of photon-fpga-lab memory-core",
                f.display()
            ))
        })?;
    }
    let planned = if args.from_csv.is_some() {
        vec![]
    } else {
        specs(
            &photons,
            &args.k500_photons,
            args.paper_photons,
            sides,
            args.cache_lines,
        )
    };
    for s in planned {
        let p = measure(&s, args.seed, !args.no_cpu)?;
        eprintln!(
            "{} emitted, {} photons, k = {}, {:?}, {} B/cycle: {} queries, {:.3} reads/cycle, \
             hit rate {:.2} %, {:.0} DRAM bytes/query",
            p.emitted,
            p.photons,
            p.k,
            p.order,
            p.bytes_per_cycle(),
            p.queries,
            p.reads_per_cycle(),
            100.0 * p.hit_rate(),
            p.dram_bytes_per_query()
        );
        points.push(p);
    }
    let list = |v: &[usize]| {
        v.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(",")
    };
    let command = format!(
        "photon-fpga-lab memory-core --photons {} --k500-photons {} --paper-photons {} \
         --side {} --k500-side {}{} --fmax-mhz {} --seed {}{} --out-dir {}",
        list(&args.photons),
        list(&args.k500_photons),
        args.paper_photons,
        args.side,
        args.k500_side,
        args.cache_lines
            .map_or(String::new(), |n| format!(" --cache-lines {n}")),
        args.fmax_mhz,
        args.seed,
        if args.no_cpu { " --no-cpu" } else { "" },
        dir.display()
    );
    o_csv.write(|w| w.write_all(csv(&points).as_bytes()))?;
    o_md.write(|w| w.write_all(table(&points, args.fmax_mhz, &command).as_bytes()))?;
    size_plot(&dir.join("memory_core_sizes.png"), &points, args.fmax_mhz)?;
    bandwidth_plot(
        &dir.join("memory_core_bandwidth.png"),
        &points,
        args.paper_photons,
    )?;
    println!(
        "wrote {}/memory_core.{{csv,md}} and its two plots",
        dir.display()
    );
    Ok(())
}
