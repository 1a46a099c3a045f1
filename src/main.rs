//! `photon-fpga`: render with photon mapping whose gathers run on the software
//! reference or the simulated FPGA core, or gather a user's own photon map.

use clap::{Args, Parser, Subcommand};
use photon_fpga::host::csvio;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{
    BackendKind, FloatBackend, GatherBackend, GatherParams, SwBackend, DEFAULT_CAPACITY,
};
use photon_fpga::hw::metric::Metric;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "photon-fpga", version, about)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
}

#[derive(Subcommand)]
enum Cmd {
    /// Gather the k nearest photons of every query in a CSV photon map.
    Gather(GatherArgs),
}

/// Options every gather shares.
#[derive(Args, Clone, Debug)]
struct GatherOpts {
    /// Photons gathered per query.
    #[arg(long, default_value_t = 10)]
    k: usize,
    /// Upper search radius in world units (inclusive); unbounded if absent.
    #[arg(long, allow_negative_numbers = true)]
    radius: Option<f64>,
    /// Coordinate bits on the longest axis of the photon bounding box.
    #[arg(long, default_value_t = 10)]
    bits: u32,
    /// Distance metric: l2 (squared Euclidean) or l1 (Manhattan).
    #[arg(long, default_value_t = Metric::L2)]
    metric: Metric,
    /// Who answers the gathers: float, sw or rtl.
    #[arg(long, default_value_t = BackendKind::Sw)]
    backend: BackendKind,
    /// Largest photon map accepted.
    #[arg(long, default_value_t = DEFAULT_CAPACITY)]
    capacity: usize,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
}

impl GatherOpts {
    fn params(&self) -> GatherParams {
        GatherParams {
            k: self.k,
            radius: self.radius,
            bits: self.bits,
            metric: self.metric,
            capacity: self.capacity,
        }
    }
}

#[derive(Args)]
struct GatherArgs {
    /// Photon positions: `x,y,z` per line (optional header, extra columns ignored).
    #[arg(long)]
    photons: PathBuf,
    /// Query positions, same format.
    #[arg(long)]
    queries: PathBuf,
    #[command(flatten)]
    opts: GatherOpts,
    /// Output CSV: `query,rank,photon,distance`, nearest first.
    #[arg(long)]
    out: PathBuf,
}

fn set_threads(threads: Option<usize>) -> Result<()> {
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

fn gather(args: &GatherArgs) -> Result<()> {
    set_threads(args.opts.threads)?;
    let params = args.opts.params();
    params.validate(1)?;
    let photons = csvio::read_points(&args.photons)?;
    let queries = csvio::read_points(&args.queries)?;
    if photons.is_empty() {
        return Err(Error::new(format!(
            "{}: the photon set is empty",
            args.photons.display()
        )));
    }
    // The grid covers the queries too, so every query keeps its own position.
    let backend: Box<dyn GatherBackend> = match args.opts.backend {
        BackendKind::Float => Box::new(FloatBackend::new(&photons, &params)?),
        BackendKind::Sw => Box::new(SwBackend::covering(&photons, &queries, &params)?),
        BackendKind::Rtl => {
            return Err(Error::new("--backend rtl is not available yet"));
        }
    };
    let results = backend.gather(&queries)?;
    csvio::write_neighbours(&args.out, &results)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.cmd {
        Some(Cmd::Gather(a)) => gather(a),
        None => Err(Error::new("render: not yet available")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
