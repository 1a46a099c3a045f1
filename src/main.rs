//! `photon-fpga`: render with photon mapping whose gathers run on the software
//! reference or the simulated FPGA core, or gather a user's own photon map.

use clap::{Args, Parser, Subcommand};
use photon_fpga::host::csvio;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{make_backend, BackendKind, GatherParams, DEFAULT_CAPACITY};
use photon_fpga::host::photons;
use photon_fpga::host::render::{self, RenderSettings};
use photon_fpga::host::scene::Scene;
use photon_fpga::host::stages::StageTimes;
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
    /// Render a scene with photon mapping (the default command).
    Render(RenderArgs),
    /// Gather the k nearest photons of every query in a CSV photon map.
    Gather(GatherArgs),
}

/// Options every gather shares.
#[derive(Args, Clone, Debug)]
struct GatherOpts {
    /// Photons gathered per query [default: 10 for gather, 32 for render: the core's largest found list].
    #[arg(long)]
    k: Option<usize>,
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
    fn params(&self, default_k: usize) -> GatherParams {
        GatherParams {
            k: self.k.unwrap_or(default_k),
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

/// `WxH`, e.g. `256x256`.
fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("invalid size '{s}' (expected WxH, e.g. 256x256)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(bad());
    }
    Ok((w, h))
}

#[derive(Args)]
struct RenderArgs {
    /// Scene file (TOML); the built-in Cornell box if absent.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Photons emitted from the light.
    #[arg(long, default_value_t = 200_000)]
    photons: usize,
    #[command(flatten)]
    opts: GatherOpts,
    /// Image size.
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    size: (u32, u32),
    /// Eye samples per pixel.
    #[arg(long, default_value_t = 4)]
    spp: u32,
    /// Seed of every random choice; the same seed gives the same image.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Exposure multiplier applied before tone mapping.
    #[arg(long)]
    exposure: Option<f32>,
    /// Output PNG.
    #[arg(long, default_value = "render.png")]
    out: PathBuf,
}

impl Default for RenderArgs {
    fn default() -> Self {
        // The defaults clap gives a bare `render`.
        match Cli::parse_from(["photon-fpga", "render"]).cmd {
            Some(Cmd::Render(a)) => a,
            _ => unreachable!("render parses with its defaults"),
        }
    }
}

fn render(args: &RenderArgs) -> Result<()> {
    set_threads(args.opts.threads)?;
    // A radiance estimate wants more photons than a plain gather.
    let params = args.opts.params(32);
    params.validate(1)?;
    if args.photons == 0 {
        return Err(Error::new("--photons must be at least 1, got 0"));
    }
    let scene = match &args.scene {
        Some(p) => Scene::from_file(p)?,
        None => Scene::cornell_box(),
    };
    let mut settings = RenderSettings {
        width: args.size.0,
        height: args.size.1,
        spp: args.spp.max(1),
        seed: args.seed,
        ..RenderSettings::default()
    };
    if let Some(e) = args.exposure {
        settings.exposure = e;
    }
    let mut t = StageTimes::default();
    let photons = t.time("photon emission", || {
        photons::trace_photons(&scene, args.photons, args.seed, true)
    });
    if photons.is_empty() {
        return Err(Error::new("no photon reached a diffuse surface"));
    }
    let positions = render::photon_points(&photons);
    let backend = t.time("kd-tree build", || {
        make_backend(args.opts.backend, &positions, &[], &params)
    })?;
    let (queries, emitted) = t.time("ray emission", || render::eye_queries(&scene, &settings));
    let qpos = render::query_points(&queries);
    let gathered = t.time("kd-tree search", || backend.gather(&qpos))?;
    t.time("other", || {
        let radiance = render::radiance(
            &queries,
            &photons,
            &gathered,
            params.k,
            params.radius,
            params.metric,
        );
        let img = render::resolve(
            settings.width,
            settings.height,
            &queries,
            &radiance,
            &emitted,
            settings.exposure,
        );
        render::save_png(&img, &args.out)
    })?;
    let visited: u64 = gathered.iter().map(|g| g.visited as u64).sum();
    println!(
        "{} photons stored from {} emitted; {} queries; backend {}; k = {}",
        photons.len(),
        args.photons,
        queries.len(),
        backend.name(),
        params.k
    );
    if let Some(info) = backend.describe() {
        println!("{info}");
    }
    println!(
        "photons visited per query: {:.1}",
        visited as f64 / queries.len().max(1) as f64
    );
    println!("{t}");
    println!("wrote {}", args.out.display());
    Ok(())
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
    let params = args.opts.params(10);
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
    let backend = make_backend(args.opts.backend, &photons, &queries, &params)?;
    let results = backend.gather(&queries)?;
    csvio::write_neighbours(&args.out, &results)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.cmd {
        Some(Cmd::Gather(a)) => gather(a),
        Some(Cmd::Render(a)) => render(a),
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
