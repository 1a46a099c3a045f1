//! `photon-fpga`: render with photon mapping whose gathers run on the software
//! reference or the simulated FPGA core, or gather a user's own photon map.

use clap::{Args, Parser, Subcommand};
use photon_fpga::host::csvio;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{make_backend, BackendKind, GatherParams, DEFAULT_CAPACITY};
use photon_fpga::host::limits::{self, MAX_EMITTED};
use photon_fpga::host::output::{Output, Staged};
use photon_fpga::host::render::photons;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, RenderSettings};
use photon_fpga::host::stages::StageTimes;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::rtl::export::export_verilog;
use photon_fpga::hw::rtl::native::SimOptions;
use photon_fpga::hw::rtl::shell::registered_shell;
use photon_fpga::hw::traversal::Traversal;
use std::path::PathBuf;

mod cli;
use cli::bench_core::{bench_core, BenchCoreArgs};
use cli::core_args::CoreArgs;
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
    /// Write the photon-search core's Verilog (top module `top`).
    ExportVerilog(ExportArgs),
    /// Simulate a core on a workload (random map or Cornell box): reads per cycle and
    /// per query against the software search, cycles/s; --cpu times kiddo beside it.
    BenchCore(BenchCoreArgs),
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
    /// Coordinate bits on the longest axis of the photon bounding box [default: 10]
    /// (the quantized backends sw and rtl; an error with --backend float).
    #[arg(long)]
    bits: Option<u32>,
    /// Distance metric: l2 (squared Euclidean) or l1 (Manhattan).
    #[arg(long, default_value_t = Metric::L2)]
    metric: Metric,
    /// How the search climbs back up: remember (each level's axis distance, no
    /// re-reads) or reread (the paper's). Changes read counts, never neighbours.
    #[arg(long, default_value_t = Traversal::default())]
    traversal: Traversal,
    /// Who answers the gathers: float, sw or rtl.
    #[arg(long, default_value_t = BackendKind::Sw)]
    backend: BackendKind,
    /// Largest photon map accepted.
    #[arg(long, default_value_t = DEFAULT_CAPACITY)]
    capacity: usize,
    /// With --backend rtl: stream the simulation's waveform to this VCD file
    /// (also: env PHOTON_FPGA_VCD=path).
    #[arg(long)]
    vcd: Option<PathBuf>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
}

impl GatherOpts {
    /// The waveform output (`--vcd` or env PHOTON_FPGA_VCD, rtl only), checked now
    /// and staged: the simulator writes a temporary file that becomes the VCD only
    /// when the whole run succeeds.
    fn vcd(&self, inputs: &[&std::path::Path]) -> Result<Option<Staged>> {
        let path = match &self.vcd {
            Some(p) => p.clone(),
            None if self.backend == BackendKind::Rtl => {
                match std::env::var_os(photon_fpga::hw::rtl::native::VCD_ENV) {
                    Some(p) => PathBuf::from(p),
                    None => return Ok(None),
                }
            }
            None => return Ok(None),
        };
        if self.backend != BackendKind::Rtl {
            return Err(Error::new("--vcd needs --backend rtl"));
        }
        Ok(Some(Output::check(&path, inputs)?.stage()?))
    }

    fn sim(&self, vcd: &Option<Staged>) -> SimOptions {
        SimOptions {
            vcd: vcd.as_ref().map(|v| v.path().to_path_buf()),
            ..SimOptions::default()
        }
    }

    /// Options the chosen backend would ignore are errors, not silently dropped.
    fn check(&self) -> Result<()> {
        if self.backend == BackendKind::Float && self.bits.is_some() {
            return Err(Error::new(
                "--bits sets the grid of the quantized backends (sw, rtl); \
                 --backend float searches the unquantized positions",
            ));
        }
        Ok(())
    }

    fn params(&self, default_k: usize) -> GatherParams {
        GatherParams {
            k: self.k.unwrap_or(default_k),
            radius: self.radius,
            bits: self.bits.unwrap_or(10),
            metric: self.metric,
            traversal: self.traversal,
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
    #[arg(long, allow_negative_numbers = true)]
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
    args.opts.check()?;
    // Everything that can be refused is refused before any photon is traced.
    if args.photons == 0 || args.photons > MAX_EMITTED {
        return Err(Error::new(format!(
            "--photons must be in 1..={MAX_EMITTED}, got {}",
            args.photons
        )));
    }
    if args.spp == 0 {
        return Err(Error::new("--spp must be at least 1, got 0"));
    }
    limits::check_photon_memory(params.capacity)?;
    if let Some(e) = args.exposure {
        limits::check_positive("--exposure", e as f64)?;
    }
    let (w, h) = args.size;
    limits::check_gather_memory(
        w as u64 * h as u64 * args.spp as u64,
        params.k,
        params.capacity as u64,
        &format!("--size {w}x{h} × --spp {}", args.spp),
    )?;
    let inputs: Vec<&std::path::Path> = args.scene.iter().map(|p| p.as_path()).collect();
    let out = Output::check(&args.out, &inputs)?;
    let vcd = args.opts.vcd(&inputs)?;
    let scene = match &args.scene {
        Some(p) => Scene::from_file(p)?,
        None => Scene::cornell_box(),
    };
    let mut settings = RenderSettings {
        width: w,
        height: h,
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::default()
    };
    if let Some(e) = args.exposure {
        settings.exposure = e;
    }
    let mut t = StageTimes::default();
    let photons = t
        .time("photon emission", || {
            photons::trace_photons_capped(&scene, args.photons, args.seed, true, params.capacity)
        })
        .ok_or_else(|| {
            Error::new(format!(
                "{} emitted photons store more than --capacity {} photons (stopped early)",
                args.photons, params.capacity
            ))
        })?;
    if photons.is_empty() {
        return Err(Error::new("no photon reached a diffuse surface"));
    }
    let positions = render::photon_points(&photons);
    let backend = t.time("kd-tree build", || {
        make_backend(args.opts.backend, &positions, &params, &args.opts.sim(&vcd))
    })?;
    let pass = render::render_image(
        &scene,
        &settings,
        &photons,
        backend.as_ref(),
        &params,
        &mut t,
    )?;
    t.time("other", || render::save_png(&pass.image, &out))?;
    if let Some(v) = vcd {
        v.commit()?;
    }
    println!(
        "{} photons stored from {} emitted; {} queries; backend {}; k = {}",
        photons.len(),
        args.photons,
        pass.queries,
        backend.name(),
        params.k
    );
    if let Some(info) = backend.describe() {
        println!("{info}");
    }
    println!(
        "photons visited per query: {:.1}",
        pass.visited as f64 / pass.queries.max(1) as f64
    );
    println!("{t}");
    println!("wrote {}", args.out.display());
    Ok(())
}

#[derive(Args)]
struct ExportArgs {
    #[command(flatten)]
    core: CoreArgs,
    /// Also write DIR/shell.v: T replicated cores behind registered byte-wide I/O
    /// (for place and route; see src/hw/rtl/shell.rs).
    #[arg(long)]
    shell_trees: Option<usize>,
    /// Output directory; the core goes to DIR/photon_search_core.v.
    #[arg(long)]
    out: PathBuf,
}

fn export(args: &ExportArgs) -> Result<()> {
    let cfg = args.core.config()?;
    if args.shell_trees == Some(0) {
        return Err(Error::new("--shell-trees must be at least 1, got 0"));
    }
    // Everything is generated before the directory is made: a failure leaves nothing.
    let exported = export_verilog(&cfg)?;
    let verilog = &exported.verilog;
    // Event-driven simulators (Icarus, ISim, ModelSim) hang on the raw export's
    // glitch loops; this rewrite is what the CI cross-simulation runs under Icarus.
    let sim_verilog = photon_fpga::hw::rtl::export::glitch_free(verilog)?;
    let shell = match args.shell_trees {
        Some(trees) => Some((trees, registered_shell(&exported, trees)?)),
        None => None,
    };
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::new(format!("{}: cannot create: {e}", args.out.display())))?;
    let path = args.out.join("photon_search_core.v");
    Output::check(&path, &[])?.write(|w| w.write_all(verilog.as_bytes()))?;
    let sim_path = args.out.join("photon_search_core_sim.v");
    Output::check(&sim_path, &[])?.write(|w| w.write_all(sim_verilog.as_bytes()))?;
    println!(
        "wrote {}: the same core for event-driven simulators (glitch-free rewrite)",
        sim_path.display()
    );
    if let Some((trees, shell)) = shell {
        let spath = args.out.join("shell.v");
        Output::check(&spath, &[])?.write(|w| w.write_all(shell.as_bytes()))?;
        println!(
            "wrote {}: {trees} core(s) behind a registered I/O shell",
            spath.display()
        );
    }
    println!(
        "wrote {}: T = {} tree(s), H = {}, K = {}, {} x {} QueryModules per tree, {}-bit coordinates, {} metric, {}-bit distances",
        path.display(),
        cfg.trees,
        cfg.address_bits,
        cfg.k,
        photon_fpga::hw::config::PORTS,
        cfg.queries_per_port,
        cfg.layout.bits[0],
        cfg.metric,
        cfg.dist_bits()
    );
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
    args.opts.check()?;
    let inputs = [args.photons.as_path(), args.queries.as_path()];
    let out = Output::check(&args.out, &inputs)?;
    let vcd = args.opts.vcd(&inputs)?;
    let photons = csvio::read_points(&args.photons)?;
    let queries = csvio::read_points(&args.queries)?;
    if photons.points.is_empty() {
        return Err(Error::new(format!(
            "{}: the photon set is empty",
            args.photons.display()
        )));
    }
    limits::check_gather_memory(
        queries.points.len() as u64,
        params.k,
        photons.points.len() as u64,
        &format!("the lines of {}", args.queries.display()),
    )?;
    // The grid covers the photons alone: a query never changes another's answer.
    let backend = make_backend(
        args.opts.backend,
        &photons.points,
        &params,
        &args.opts.sim(&vcd),
    )?;
    for (q, line) in queries.points.iter().zip(&queries.lines) {
        backend
            .check_query(*q)
            .map_err(|e| Error::new(format!("{}:{line}: {e}", args.queries.display())))?;
    }
    let results = backend.gather(&queries.points)?;
    csvio::write_neighbours(&out, &results)?;
    if let Some(v) = vcd {
        v.commit()?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.cmd {
        Some(Cmd::Gather(a)) => gather(a),
        Some(Cmd::ExportVerilog(a)) => export(a),
        Some(Cmd::BenchCore(a)) => bench_core(a),
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
