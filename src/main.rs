//! `photon-fpga`: render with photon mapping whose gathers run on the software
//! reference or the simulated FPGA core, or gather a user's own photon map.

use clap::{Args, Parser, Subcommand};
use photon_fpga::host::csvio;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{make_backend, BackendKind, GatherParams, DEFAULT_CAPACITY};
use photon_fpga::host::limits::{self, MAX_EMITTED};
use photon_fpga::host::output::{Output, Staged};
use photon_fpga::host::photons;
use photon_fpga::host::render::{self, RenderSettings};
use photon_fpga::host::scene::Scene;
use photon_fpga::host::stages::StageTimes;
use photon_fpga::hw::config::CoreConfig;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::photon_word::PhotonLayout;
use photon_fpga::hw::shell::registered_shell;
use photon_fpga::hw::sim::SimOptions;
use photon_fpga::hw::traversal::Traversal;
use photon_fpga::hw::verilog::export_verilog;
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
    /// Write the photon-search core's Verilog (top module `top`).
    ExportVerilog(ExportArgs),
    /// Simulate a core on a random map: reads per cycle, photons visited, cycles/s.
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
                match std::env::var_os(photon_fpga::hw::sim::VCD_ENV) {
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
    /// (for place and route; see src/hw/shell.rs).
    #[arg(long)]
    shell_trees: Option<usize>,
    /// Output directory; the core goes to DIR/photon_search_core.v.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args)]
struct BenchCoreArgs {
    #[command(flatten)]
    core: CoreArgs,
    /// Queries to stream through the core.
    #[arg(long, default_value_t = 400)]
    queries: usize,
    /// Seed of the random photon map (2^H − 1 photons) and queries.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The workload: `uniform` (a full random map of 2^H − 1 photons on the core's
    /// grid, uniform queries: the paper's) or `cornell` (the Cornell box's photon map
    /// from --cornell-photons emitted photons on a --bits grid, queried at a 64×64
    /// image's eye-ray hits; H and the per-axis widths follow the map).
    #[arg(long, default_value = "uniform", value_parser = ["uniform", "cornell"])]
    workload: String,
    /// Emitted photons of the `cornell` workload.
    #[arg(long, default_value_t = 20_000)]
    cornell_photons: usize,
    /// Clock of the core in MHz (e.g. a placed-and-routed fmax from synth/REPORT.md):
    /// prints the core's queries/s = reads/cycle × fmax / reads per query.
    #[arg(long)]
    fmax_mhz: Option<f64>,
    /// Also time kiddo (ImmutableKdTree, f32) and the software search on the same
    /// points, queries and k, one thread each, side by side.
    #[arg(long)]
    cpu: bool,
}

/// The elaboration-time parameters of a core.
#[derive(Args)]
struct CoreArgs {
    /// Found-list depth K (the largest k a query may ask for).
    #[arg(long, default_value_t = CoreConfig::paper().k)]
    k: usize,
    /// Coordinate bits on every axis.
    #[arg(long, default_value_t = CoreConfig::paper().layout.bits[0])]
    bits: u32,
    /// Tree height H: the TreeModule holds 2^H photon words.
    #[arg(long, default_value_t = CoreConfig::paper().address_bits)]
    address_bits: u32,
    /// QueryModules per TreeModule port [default: the issue interval, so a busy
    /// port reads every cycle].
    #[arg(long)]
    queries_per_port: Option<usize>,
    /// Distance metric: l1 (the paper's 12-bit distance) or l2 (squared Euclidean).
    #[arg(long, default_value_t = CoreConfig::paper().metric)]
    metric: Metric,
    /// Leave out the pipeline registers (BlockRAM read data, result streams): two
    /// cycles less latency, longer critical paths. For before/after timing.
    #[arg(long)]
    unpipelined: bool,
    /// How a QueryModule climbs back up: remember (path memory, no re-reads) or
    /// reread (the paper's re-read of every parent).
    #[arg(long, default_value_t = Traversal::default())]
    traversal: Traversal,
    /// Replicated trees T (the paper's future work): T copies of the core, each with
    /// its own copy of the map, behind one set of streams (src/hw/array.rs).
    #[arg(long, default_value_t = 1)]
    trees: usize,
}

impl CoreArgs {
    fn config(&self) -> Result<CoreConfig> {
        if !(1..=photon_fpga::hw::config::MAX_HW_COORD_BITS).contains(&self.bits) {
            return Err(Error::new(format!(
                "--bits {} is out of range (1..={})",
                self.bits,
                photon_fpga::hw::config::MAX_HW_COORD_BITS
            )));
        }
        let mut cfg = CoreConfig {
            layout: PhotonLayout::new([self.bits; 3]),
            address_bits: self.address_bits,
            k: self.k,
            queries_per_port: 1,
            metric: self.metric,
            pipelined: !self.unpipelined,
            trees: self.trees,
            traversal: self.traversal,
        };
        cfg.queries_per_port = self.queries_per_port.unwrap_or(cfg.issue_interval());
        cfg.validate()?;
        Ok(cfg)
    }
}

/// Stream random queries through the simulated core on a full random map and report
/// reads per port per cycle, photons visited per query (checked against the
/// software search) and simulation speed.
fn bench_core(args: &BenchCoreArgs) -> Result<()> {
    use photon_fpga::host::knn::{search_with, Traversal};
    use photon_fpga::host::workload;
    use photon_fpga::hw::sim::{CoreSim, HwQuery};
    let mut cfg = args.core.config()?;
    let w = if args.workload == "cornell" {
        let w = workload::cornell(
            args.cornell_photons,
            usize::MAX,
            cfg.layout.bits[0],
            64,
            args.seed,
        );
        cfg.layout = w.tree.layout;
        cfg.address_bits = w.tree.address_bits();
        cfg.validate()?;
        cfg.check_map(&w.tree)?;
        // Every query of the image would take too long to simulate: an even sample.
        let step = (w.queries.len() / args.queries.max(1)).max(1);
        let queries = w
            .queries
            .iter()
            .step_by(step)
            .take(args.queries)
            .copied()
            .collect();
        workload::Workload { queries, ..w }
    } else {
        let n = (1usize << cfg.address_bits) - 1;
        workload::uniform(cfg.layout, n, args.queries, args.seed)
    };
    let (points, tree) = (&w.points, &w.tree);
    let n = tree.len();
    let max = cfg.max_dist();
    let queries: Vec<HwQuery> = w
        .queries
        .iter()
        .enumerate()
        .map(|(i, &coords)| HwQuery {
            id: i as u32,
            coords,
            radius: max,
            k: cfg.k as u32,
        })
        .collect();
    let mut sim = CoreSim::new(&cfg, &SimOptions::default())?;
    sim.load_map(tree)?;
    let load_cycles = sim.stats().cycles;
    let t0 = std::time::Instant::now();
    let results = sim.run_queries(&queries)?;
    let secs = t0.elapsed().as_secs_f64();
    let st = sim.stats().clone();
    let mut sw_visited = 0u64;
    let mut sw_tested = 0u64;
    let mut other_visited = 0u64;
    for (q, r) in queries.iter().zip(&results) {
        let f = search_with(tree, q.coords, cfg.k, max, cfg.metric, cfg.traversal);
        if f.visited != r.visited
            || f.sorted_dists() != {
                let mut d: Vec<u64> = r.found.iter().map(|x| x.1).collect();
                d.sort();
                d
            }
        {
            return Err(Error::new(format!(
                "query {}: the core disagrees with the software search",
                q.id
            )));
        }
        sw_visited += f.visited as u64;
        sw_tested += f.tested as u64;
        let other = match cfg.traversal {
            Traversal::Remember => Traversal::Reread,
            Traversal::Reread => Traversal::Remember,
        };
        other_visited += search_with(tree, q.coords, cfg.k, max, cfg.metric, other).visited as u64;
    }
    let cycles = st.cycles - load_cycles;
    let reads: u64 = st.reads_per_port.iter().sum();
    let busy_per_port: Vec<String> = st
        .busy_reads_per_port
        .iter()
        .map(|r| format!("{:.3}", *r as f64 / st.busy_cycles.max(1) as f64))
        .collect();
    println!(
        "core: T = {} tree(s), H = {}, K = {}, {} x {} QueryModules per tree, {} metric, {}-bit distances, {} traversal, issue interval {}",
        cfg.trees,
        cfg.address_bits,
        cfg.k,
        photon_fpga::hw::config::PORTS,
        cfg.queries_per_port,
        cfg.metric,
        cfg.dist_bits(),
        cfg.traversal,
        cfg.issue_interval()
    );
    println!(
        "{} photons, {} queries, {} cycles after the load ({} load cycles)",
        n,
        queries.len(),
        cycles,
        load_cycles
    );
    println!(
        "photons visited per query: {:.1} (software search: {:.1}, equal per query)",
        reads as f64 / queries.len() as f64,
        sw_visited as f64 / queries.len() as f64
    );
    println!(
        "distance tests per query: {:.1}",
        sw_tested as f64 / queries.len() as f64
    );
    println!(
        "photon reads per query with the other ascent (software search, same queries): {:.1}",
        other_visited as f64 / queries.len() as f64
    );
    println!(
        "reads per cycle (all ports of all trees, whole run): {:.3}",
        reads as f64 / cycles.max(1) as f64
    );
    println!(
        "reads per port per cycle while every QueryModule is busy ({} cycles): {}",
        st.busy_cycles,
        busy_per_port.join(", ")
    );
    println!("simulation speed: {:.0} cycles/s", cycles as f64 / secs);
    let reads_per_query = reads as f64 / queries.len() as f64;
    let core_qps = args
        .fmax_mhz
        .map(|f| reads as f64 / cycles.max(1) as f64 * f * 1e6 / reads_per_query);
    if let (Some(f), Some(q)) = (args.fmax_mhz, core_qps) {
        println!(
            "core queries/s at {f} MHz (given): {q:.0} (simulated reads/cycle x fmax / reads per query)"
        );
    }
    if args.cpu {
        let coords: Vec<[u32; 3]> = queries.iter().map(|q| q.coords).collect();
        let min = std::time::Duration::from_millis(200);
        let cpu =
            photon_fpga::host::cpu_ref::measure(points, tree, &coords, cfg.k, cfg.metric, min)
                .map_err(Error::new)?;
        println!(
            "cpu queries/s, 1 thread, same queries: kiddo {:.0}, software search {:.0}",
            cpu.kiddo, cpu.sw
        );
        if let Some(q) = core_qps {
            println!("core / kiddo: {:.2}", q / cpu.kiddo);
        }
    }
    Ok(())
}

fn export(args: &ExportArgs) -> Result<()> {
    let cfg = args.core.config()?;
    if args.shell_trees == Some(0) {
        return Err(Error::new("--shell-trees must be at least 1, got 0"));
    }
    // Everything is generated before the directory is made: a failure leaves nothing.
    let verilog = export_verilog(&cfg)?;
    // Event-driven simulators (Icarus, ISim, ModelSim) hang on the raw export's
    // glitch loops; this rewrite is what the CI cross-simulation runs under Icarus.
    let sim_verilog = photon_fpga::hw::xsim::glitch_free(&verilog)?;
    let shell = match args.shell_trees {
        Some(trees) => Some((trees, registered_shell(&verilog, trees)?)),
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
