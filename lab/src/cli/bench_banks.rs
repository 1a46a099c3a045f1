//! `photon-fpga-lab bench-banks`: the banked core simulated over D datapaths × B banks
//! on one query stream (the bank-conflict curve) and over map sizes for a device's
//! plan (`host::banking::rtl_sweep`), every answer checked against the software
//! search; writes the report, the CSV and the plots (`rtl_report`).

use crate::banking::rtl_report::{self, RtlSweeps};
use crate::banking::rtl_sweep::{self, MapPoint, RtlPoint, GRID_BITS};
use crate::workload;
use clap::Args;
use photon_fpga::cli::render::{check_photons_and_spp, parse_size};
use photon_fpga::cli::values::DeviceArg;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::limits;
use photon_fpga::host::render::RenderSettings;
use photon_fpga::hw::config::bank_config::BankPorts;
use photon_fpga::hw::config::core_config::{Banking, MAX_BANKED_TREES, MAX_K};
use photon_fpga::hw::sim::native::Engine;
use std::path::PathBuf;

#[derive(Args)]
pub struct BenchBanksArgs {
    /// Photons emitted for the conflict curve's map (the default render's).
    #[arg(long, default_value_t = 200_000)]
    pub photons: usize,
    /// Image of the queries (the direct render's).
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Eye samples per pixel (the direct render's).
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
    /// Photons gathered per query (the direct render's).
    #[arg(long, default_value_t = 32)]
    pub k: usize,
    /// Seed of the photon map and the eye rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The conflict curve's datapaths D (even: two a replica of the top levels).
    #[arg(long, value_delimiter = ',', default_value = "2,4,8,16")]
    pub datapaths: Vec<usize>,
    /// The conflict curve's banks B (powers of two; 1: one whole copy, with D = 2).
    #[arg(long, value_delimiter = ',', default_value = "1,8,16,32,64")]
    pub banks: Vec<u64>,
    /// The conflict curve's bank-port modes (one, shared, split).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "shared")]
    pub bank_ports: Vec<BankPorts>,
    /// Queries of the conflict curve: an even sample of the image's [default: all].
    #[arg(long)]
    pub queries: Option<usize>,
    /// Emitted photons of each map of the map-size sweep (`--map-photons` with no
    /// value: no sweep).
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 0..,
        default_value = "500,2000,8000,32000,128000,512000"
    )]
    pub map_photons: Vec<usize>,
    /// Queries per map of the map-size sweep (an even sample of the image's).
    #[arg(long, default_value_t = 20_000)]
    pub map_queries: usize,
    /// The device whose plan (`device::plan`) sizes the core for each map.
    #[arg(long, value_enum, default_value_t = DeviceArg::Xc6vsx475t)]
    pub device: DeviceArg,
    /// Clock of the queries/s figures in MHz, *assumed* [default: 215, the paper's].
    #[arg(long, default_value_t = 215.0)]
    pub fmax_mhz: f64,
    /// Who simulates the core.
    #[arg(long, value_enum, default_value_t = Engine::Verilator)]
    pub engine: Engine,
    /// Directory of BANKED_CORE.md, banked_core.csv and the two PNG plots.
    #[arg(long, default_value = "docs")]
    pub out: PathBuf,
}

pub fn bench_banks(args: &BenchBanksArgs) -> Result<()> {
    check_photons_and_spp(args.photons, args.spp)?;
    limits::check_positive("--fmax-mhz", args.fmax_mhz)?;
    if args.k == 0 || args.k > MAX_K {
        return Err(Error::new(format!(
            "--k must be in 1..={MAX_K}, got {}",
            args.k
        )));
    }
    for (name, v) in [
        ("--queries", args.queries),
        ("--map-queries", Some(args.map_queries)),
    ] {
        if v == Some(0) {
            return Err(Error::new(format!("{name} must be at least 1, got 0")));
        }
    }
    if let Some(&e) = args.map_photons.iter().find(|&&e| e == 0) {
        return Err(Error::new(format!(
            "--map-photons: {e} emitted photons make no map"
        )));
    }
    if let Some(d) = args
        .datapaths
        .iter()
        .find(|&&d| d == 0 || d % 2 != 0 || d > 2 * MAX_BANKED_TREES)
    {
        return Err(Error::new(format!(
            "--datapaths {d}: D is two a replica of the top levels (an even number, 2..={})",
            2 * MAX_BANKED_TREES
        )));
    }
    if let Some(b) = args
        .banks
        .iter()
        .find(|&&b| b != 1 && Banking::bank_bits_for(b).is_err())
    {
        return Err(Error::new(format!(
            "--banks {b}: 1 (one whole copy) or a power of two from 2 to 1024"
        )));
    }
    // Every output checked before the long runs (nothing written on a refusal).
    rtl_report::check_outputs(&args.out)?;
    let engine: Engine = args.engine;
    let settings = RenderSettings {
        width: args.size.0,
        height: args.size.1,
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::default()
    };
    let w = workload::cornell_image(args.photons, usize::MAX, GRID_BITS, &settings);
    let all = w.queries.len();
    let queries = rtl_sweep::sample(&w.queries, args.queries.unwrap_or(all));
    let w = workload::Workload { queries, ..w };
    let show = |p: &RtlPoint| {
        println!(
            "{} photons, D = {}, B = {} ({} ports), R = {}: {:.3} reads/cycle ({:.3} per \
             datapath), {:.1} reads/query, {} queries checked",
            p.photons,
            p.datapaths(),
            p.banks(),
            p.ports(),
            p.config.result_streams,
            p.reads_per_cycle(),
            p.per_datapath(),
            p.reads_per_query(),
            p.queries
        )
    };
    let ports: Vec<BankPorts> = args.bank_ports.to_vec();
    let curve = rtl_sweep::conflict_curve(
        &w,
        args.k,
        &args.datapaths,
        &args.banks,
        &ports,
        engine,
        show,
    )?;
    let device = args.device.device();
    let maps = rtl_sweep::map_sizes(
        &args.map_photons,
        &settings,
        args.k,
        args.map_queries,
        device,
        engine,
        |m| match m {
            MapPoint::Measured(p) => show(p),
            MapPoint::Refused { photons, why } => println!("{photons} photons: {why}"),
        },
    )?;
    let list = |v: &[String]| v.join(",");
    let how =
        format!(
        "Regenerate: `photon-fpga-lab bench-banks --photons {} --size {}x{} --spp {} --k {} --seed {} \
         --datapaths {} --banks {} --bank-ports {}{} --map-photons {} --map-queries {} --device {} --fmax-mhz {} \
         --engine {} --out {}`",
        args.photons,
        args.size.0,
        args.size.1,
        args.spp,
        args.k,
        args.seed,
        list(&args.datapaths.iter().map(|d| d.to_string()).collect::<Vec<_>>()),
        list(&args.banks.iter().map(|b| b.to_string()).collect::<Vec<_>>()),
        list(&ports.iter().map(|p| p.name().to_string()).collect::<Vec<_>>()),
        args.queries.map_or(String::new(), |q| format!(" --queries {q}")),
        list(&args.map_photons.iter().map(|e| e.to_string()).collect::<Vec<_>>()),
        args.map_queries,
        {
            use clap::ValueEnum;
            args.device
                .to_possible_value()
                .map_or(String::new(), |v| v.get_name().to_string())
        },
        args.fmax_mhz,
        engine_name(engine),
        args.out.display()
    );
    let sweeps = RtlSweeps {
        curve: &curve,
        curve_stream: format!(
            "The Cornell box, {} photons emitted ({} stored, {GRID_BITS}-bit grid), k = {}, \
             squared L2, {} of the {} eye-ray queries of the {}x{} image at {} samples per pixel",
            args.photons,
            w.tree.len(),
            args.k,
            w.queries.len(),
            all,
            args.size.0,
            args.size.1,
            args.spp
        ),
        maps: &maps,
        device: device.name,
        mhz: args.fmax_mhz,
        engine: engine_name(engine),
        how,
    };
    for p in rtl_report::write(&args.out, &sweeps)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn engine_name(e: Engine) -> &'static str {
    match e {
        Engine::Native => "native",
        Engine::Verilator => "verilator",
    }
}
