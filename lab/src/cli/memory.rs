//! `photon-fpga-lab memory`: the photon map in external memory behind an on-chip
//! cache, modelled (`memory`) on the Cornell box's eye-ray read streams at the
//! paper's regime and a smaller map, at two k; writes docs/MEMORY.md.

use crate::banking::stream::ImageStream;
use crate::memory::report::{report, Sweep};
use crate::memory::sweep::Stream;
use clap::Args;
use photon_fpga::cli::render::{check_photons_and_spp, parse_size};
use photon_fpga::cli::set_threads;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::output::Output;
use photon_fpga::host::render::RenderSettings;
use photon_fpga::hw::config::core_config::MAX_K;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use std::path::PathBuf;

/// Reads held in memory at most (every query's reads are kept, 4 bytes each).
const MAX_READS_ESTIMATE: u64 = 1 << 31;

#[derive(Args)]
pub struct MemoryArgs {
    /// Photons emitted for the main map (the paper's high-quality regime, §3).
    #[arg(long, default_value_t = 1_000_000)]
    pub photons: usize,
    /// Photons emitted for the smaller map.
    #[arg(long, default_value_t = 100_000)]
    pub small_photons: usize,
    /// Image of the queries (the direct render's size).
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Eye samples per pixel.
    #[arg(long, default_value_t = 1)]
    pub spp: u32,
    /// The two k measured: the direct render's and the paper's high-quality one.
    #[arg(long, value_delimiter = ',', default_value = "32,500")]
    pub k: Vec<usize>,
    /// Seed of the photon maps and the eye rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A small map, a small image and a reduced sweep (for tests): 5K and 2K
    /// photons emitted, 24x24 pixels, k = 8 and 64.
    #[arg(long)]
    pub quick: bool,
    /// Worker threads (results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// The report.
    #[arg(long, default_value = "docs/MEMORY.md")]
    pub out: PathBuf,
}

pub fn memory(args: &MemoryArgs) -> Result<()> {
    set_threads(args.threads)?;
    let (photons, small, size, ks) = if args.quick {
        (5_000, 2_000, (24, 24), vec![8, 64])
    } else {
        (args.photons, args.small_photons, args.size, args.k.clone())
    };
    check_photons_and_spp(photons, args.spp)?;
    check_photons_and_spp(small, args.spp)?;
    if ks.is_empty() || ks.iter().any(|&k| k == 0 || k > MAX_K) {
        return Err(Error::new(format!(
            "--k: each must be in 1..={MAX_K}, got {:?}",
            ks
        )));
    }
    let queries = u64::from(size.0) * u64::from(size.1) * u64::from(args.spp);
    // About 4k reads a query at most on these maps (k = 500: 2,000).
    let estimate = queries * 4 * *ks.iter().max().unwrap() as u64;
    if estimate > MAX_READS_ESTIMATE {
        return Err(Error::new(format!(
            "--size {}x{} × --spp {} at k = {} may read about {estimate} photons; the \
             read streams are held in memory, at most {MAX_READS_ESTIMATE}",
            size.0,
            size.1,
            args.spp,
            ks.iter().max().unwrap()
        )));
    }
    let out = Output::check(&args.out, &[])?;
    let settings = RenderSettings {
        width: size.0,
        height: size.1,
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::default()
    };
    let mut streams = vec![];
    for &emitted in &[photons, small] {
        for &k in &ks {
            let image =
                ImageStream::cornell(emitted, 10, &settings, k, Metric::L2, Traversal::Cell);
            if image.queries.is_empty() {
                return Err(Error::new("the image has no queries"));
            }
            eprintln!(
                "stream: {emitted} emitted, {} photons, k = {k}: {} queries, {} reads",
                image.tree.len(),
                image.queries.len(),
                image.total_reads()
            );
            streams.push(Stream::new(emitted, k, image));
        }
    }
    let how = if args.quick {
        format!(
            "Regenerate: `photon-fpga-lab memory --quick --seed {} --spp {} --out {}` (a \
             test's run: the built-in Cornell box at {photons} and {small} photons \
             emitted, 10-bit grid, a 24×24 image, k = 8 and 64).",
            args.seed,
            args.spp,
            args.out.display()
        )
    } else {
        format!(
            "Regenerate: `photon-fpga-lab memory --photons {photons} --small-photons {small} \
             --size {}x{} --spp {} --k {} --seed {} --out {}` (the built-in Cornell box, \
             10-bit grid, squared L2, the whole {}×{} image at {} sample(s) per pixel).",
            size.0,
            size.1,
            args.spp,
            ks.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(","),
            args.seed,
            args.out.display(),
            size.0,
            size.1,
            args.spp
        )
    };
    let sweep = if args.quick {
        Sweep::quick()
    } else {
        Sweep::full()
    };
    let r = report(&streams, &sweep, &how);
    out.write(|w| w.write_all(r.text.as_bytes()))?;
    println!(
        "{} order, s = {:?}, {:?} ways {}, {}, T = {:?}, S = {:?}; wrote {}",
        r.choice.order.name(),
        r.choice.block_levels,
        r.choice.ways,
        r.choice.policy.name(),
        r.choice.sharing.name(),
        r.choice.on_chip,
        r.choice.slots,
        args.out.display()
    );
    Ok(())
}
