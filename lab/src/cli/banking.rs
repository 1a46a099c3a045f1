//! `photon-fpga-lab banking`: the banked photon store's bank-conflict measurements
//! (`host::banking`) on the direct render's whole query stream, written to
//! docs/BANKING.md.

use crate::banking::report::{report, Sweep};
use crate::banking::stream::ImageStream;
use clap::Args;
use photon_fpga::cli::render::parse_size;
use photon_fpga::cli::set_threads;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::output::Output;
use photon_fpga::host::render::RenderSettings;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use std::path::PathBuf;

/// Largest k and query count measured: every query's reads are kept in memory
/// (about 120 reads of 4 bytes per query at k = 32 on the default map).
const MAX_K: usize = 1024;
const MAX_QUERIES: u64 = 1 << 22;

#[derive(Args)]
pub struct BankingArgs {
    /// Photons emitted from the light (the default render's).
    #[arg(long, default_value_t = 200_000)]
    pub photons: usize,
    /// Image size (the direct render's).
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Eye samples per pixel (the direct render's).
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
    /// Photons gathered per query (the direct render's).
    #[arg(long, default_value_t = 32)]
    pub k: usize,
    /// Seed of the photon map and the eye rays (the direct render's).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A reduced sweep (for tests).
    #[arg(long)]
    pub quick: bool,
    /// Worker threads (results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// The report.
    #[arg(long, default_value = "docs/BANKING.md")]
    pub out: PathBuf,
}

pub fn banking(args: &BankingArgs) -> Result<()> {
    set_threads(args.threads)?;
    photon_fpga::cli::render::check_photons_and_spp(args.photons, args.spp)?;
    if args.k == 0 || args.k > MAX_K {
        return Err(Error::new(format!(
            "--k must be in 1..={MAX_K}, got {}",
            args.k
        )));
    }
    let queries = args.size.0 as u64 * args.size.1 as u64 * args.spp as u64;
    if queries > MAX_QUERIES {
        return Err(Error::new(format!(
            "--size {}x{} × --spp {} is {queries} queries; the read streams are held in \
             memory, at most {MAX_QUERIES} queries",
            args.size.0, args.size.1, args.spp
        )));
    }
    let out = Output::check(&args.out, &[])?;
    let settings = RenderSettings {
        width: args.size.0,
        height: args.size.1,
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::default()
    };
    let stream = ImageStream::cornell(
        args.photons,
        10,
        &settings,
        args.k,
        Metric::L2,
        Traversal::Cell,
    );
    if stream.queries.is_empty() {
        return Err(Error::new("the image has no queries"));
    }
    let how = format!(
        "Regenerate: `photon-fpga-lab banking --photons {} --size {}x{} --spp {} --k {} --seed {}{} \
         --out {}` (the built-in Cornell box, {} photons emitted, 10-bit grid, k = {}, \
         squared L2, the whole {}×{} image at {} samples per pixel).",
        args.photons,
        args.size.0,
        args.size.1,
        args.spp,
        args.k,
        args.seed,
        if args.quick { " --quick" } else { "" },
        args.out.display(),
        args.photons,
        args.k,
        args.size.0,
        args.size.1,
        args.spp
    );
    let sweep = if args.quick {
        Sweep::quick()
    } else {
        Sweep::full()
    };
    let r = report(&stream, &sweep, &how);
    out.write(|w| w.write_all(r.text.as_bytes()))?;
    println!(
        "{} photons, {} queries, {} reads; best: {}, {} order; wrote {}",
        stream.tree.len(),
        stream.queries.len(),
        stream.total_reads(),
        r.best.0.name(),
        r.best.1.name(),
        args.out.display()
    );
    Ok(())
}
