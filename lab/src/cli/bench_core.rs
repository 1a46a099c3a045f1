//! `photon-fpga-lab bench-core`: a core simulated on a workload, checked query by query
//! against the software search, with reads per cycle and per query, and (on request)
//! kiddo and the software search timed on the same queries.

use crate::banking::order::{order_queries, StreamOrder};
use clap::{Args, ValueEnum};
use photon_fpga::cli::core_args::CoreArgs;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::limits;
use photon_fpga::host::render::irradiance::IRRADIANCE_K;
use photon_fpga::hw::config::core_spec::DEFAULT_K;
use photon_fpga::hw::sim::axi_memory::AxiTiming;
use photon_fpga::hw::sim::native::{Engine, SimOptions};

/// Final-gather rays per eye hit of the `two-pass` workload: the render's default
/// (`render --gather-rays`).
const FINAL_GATHER_RAYS: u32 = 16;

/// The query streams `bench-core` can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WorkloadKind {
    /// Uniform random photons and queries on the core's grid (the paper's workload).
    Uniform,
    /// A Cornell-box photon map with eye-ray queries.
    Cornell,
    /// The same map queried by the two-pass render's final gathers (16 gather rays
    /// per eye hit, capped at the render's default radius unless --radius is given).
    TwoPass,
    /// The final gathers of `render --method two-pass-irradiance`: 1-nearest lookups
    /// (give --k 1) in the irradiance points precomputed at every 4th photon of the
    /// map, 16 per eye hit, capped as `two-pass`; the map is those points.
    TwoPassIrradiance,
}

#[derive(Args)]
pub struct BenchCoreArgs {
    #[command(flatten)]
    core: CoreArgs,
    /// Queries to stream through the core, at least 1 [default: 400 uniform ones; with
    /// `--workload cornell` or `two-pass` every query of the image, or an even sample
    /// of this many].
    #[arg(long)]
    queries: Option<usize>,
    /// Seed of the random photon map (2^H − 1 photons) and queries.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The workload (with `cornell`, the map comes from --cornell-photons emitted
    /// photons on a --bits grid, queried at the eye-ray hits of a --cornell-size
    /// image; H and the per-axis widths follow the map, or with --core the map is
    /// put on the file's grid and must fit its H).
    #[arg(long, value_enum, default_value_t = WorkloadKind::Uniform)]
    workload: WorkloadKind,
    /// Emitted photons of the `cornell` workload.
    #[arg(long, default_value_t = 20_000)]
    cornell_photons: usize,
    /// Image of the `cornell` workload: width x height (one query per eye sample
    /// that hits a diffuse surface). `--cornell-size 256x256 --cornell-spp 4
    /// --cornell-photons 200000` is the direct render's whole stream.
    #[arg(long, default_value = "64x64", value_parser = photon_fpga::cli::render::parse_size)]
    cornell_size: (u32, u32),
    /// Eye samples per pixel of the `cornell` workload.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    cornell_spp: u32,
    /// Gather radius of every query in world units (inclusive; the uniform
    /// workload's world is its grid), as render's --radius; kiddo and the software
    /// search are timed with it too. A core built with --radius-bits needs one it
    /// answers [default: unbounded k nearest].
    #[arg(long)]
    radius: Option<f64>,
    /// Clock of the core in MHz, a finite number > 0 (e.g. a placed-and-routed fmax
    /// from synth/REPORT.md): prints the core's queries/s = reads/cycle × fmax /
    /// reads per query. The external-memory core's memory model then runs at this
    /// clock: the modelled DDR3's latency and sustained bytes, counted in its
    /// controller's cycles (`axi_memory::ECP5_DDR3_MHZ`), become the core's
    /// cycles [default: the memory at the controller's clock].
    #[arg(long)]
    fmax_mhz: Option<f64>,
    /// Also time kiddo (ImmutableKdTree, f32) and the software search on the same
    /// points, queries and k, one thread each, side by side.
    #[arg(long)]
    cpu: bool,
    /// Size Q from this stream (`CoreConfig::fit_queries_per_port`: the mean read
    /// interval of the software model plus slack) instead of the worst case.
    #[arg(
        long,
        conflicts_with_all = ["queries_per_port", "core"]
    )]
    fit_q: bool,
    /// The order of the queries (the core and kiddo get the same stream).
    #[arg(long, value_enum, default_value_t = StreamOrder::Given)]
    order: StreamOrder,
    /// The simulator.
    #[arg(long, value_enum, default_value_t = Engine::Native)]
    engine: Engine,
    /// Also run the stream on the other engine and report both speeds (the results
    /// and cycle counts must agree).
    #[arg(long)]
    both_engines: bool,
}

/// Stream random queries through the simulated core on a full random map and report
/// reads per port per cycle, photons visited per query (checked against the
/// software search) and simulation speed.
pub fn bench_core(args: &BenchCoreArgs) -> Result<()> {
    use crate::workload;
    use photon_fpga::host::map::knn::{search_with, Traversal};
    use photon_fpga::hw::config::core_config::ReadProfile;
    use photon_fpga::hw::sim::driver::HwQuery;
    use photon_fpga::hw::sim::native::CoreSim;
    if args.queries == Some(0) {
        return Err(Error::new("--queries must be at least 1, got 0"));
    }
    if let Some(f) = args.fmax_mhz {
        limits::check_positive("--fmax-mhz", f)?;
    }
    let engine: Engine = args.engine;
    let fixed = args.core.fixed()?;
    let spec = args.core.builder()?;
    let mut cfg = args.core.config_of(spec)?;
    let mut radius = args.radius;
    let mut w = if args.workload != WorkloadKind::Uniform {
        let settings = photon_fpga::host::render::RenderSettings {
            width: args.cornell_size.0,
            height: args.cornell_size.1,
            spp: args.cornell_spp,
            seed: args.seed,
            ..Default::default()
        };
        let w = if args.workload == WorkloadKind::TwoPass {
            let (w, r) = crate::lookups::cornell_final_gathers(
                args.cornell_photons,
                cfg.layout.bits[0],
                &settings,
                FINAL_GATHER_RAYS,
                cfg.k,
            )?;
            radius = radius.or(Some(r));
            w
        } else if args.workload == WorkloadKind::TwoPassIrradiance {
            if cfg.k != IRRADIANCE_K {
                return Err(Error::new(format!(
                    "--workload two-pass-irradiance makes {IRRADIANCE_K}-nearest lookups: give \
                     --k {IRRADIANCE_K}, got {}",
                    cfg.k
                )));
            }
            let (w, r) = crate::lookups::cornell_irradiance_gathers(
                args.cornell_photons,
                cfg.layout.bits[0],
                &settings,
                FINAL_GATHER_RAYS,
                DEFAULT_K,
            )?;
            radius = radius.or(Some(r));
            w
        } else if fixed.is_some() {
            // A fixed core: the map goes onto its grid.
            workload::cornell_image_on(args.cornell_photons, cfg.layout, &settings)
        } else {
            workload::cornell_image(
                args.cornell_photons,
                usize::MAX,
                cfg.layout.bits[0],
                &settings,
            )
        };
        // The map must fit a fixed core's H; else the core is built for it.
        let map = w.tree.image();
        match &fixed {
            Some(f) => {
                f.check_map(map)?;
            }
            None => {
                cfg = args
                    .core
                    .device
                    .for_device(spec, map.len(), map.layout.word_bits())?
                    .build_for(map)?
            }
        }
        // Every query of the image, or an even sample of --queries of them.
        let want = args.queries.unwrap_or(w.queries.len());
        let step = (w.queries.len() / want.max(1)).max(1);
        let queries = w.queries.iter().step_by(step).take(want).copied().collect();
        workload::Workload { queries, ..w }
    } else {
        let n = (1usize << cfg.address_bits) - 1;
        workload::uniform(cfg.layout, n, args.queries.unwrap_or(400), args.seed)
    };
    order_queries(
        &mut w.queries,
        args.order,
        cfg.layout.bits.into_iter().max().unwrap_or(0),
    );
    let (points, tree) = (&w.points, &w.tree);
    let n = tree.len();
    // Every query's initial radius: an inclusive bound on the grid (the search's
    // and the core's), the grid's diagonal when unbounded.
    let max = match radius {
        Some(r) => {
            limits::check_non_negative("--radius", r)?;
            cfg.metric.radius_bound(r, w.step, cfg.max_dist())
        }
        None => cfg.max_dist(),
    };
    if max > cfg.max_radius() {
        return Err(Error::new(format!(
            "{} is beyond the core: {}; give a --radius it answers",
            radius.map_or("an unbounded gather (no --radius)".into(), |r| format!(
                "--radius {r} ({max} on the grid)"
            )),
            cfg.radius_limit()
        )));
    }
    let queries = HwQuery::within(&cfg, &w.queries, max);
    // The stream's cost per read as the software search counts it, for Q.
    let profile: ReadProfile = queries
        .iter()
        .map(|q| search_with(tree, q.coords, cfg.k, max, cfg.metric, cfg.traversal).read_profile())
        .sum();
    if args.fit_q {
        cfg.fit_queries_per_port(&profile);
    }
    println!(
        "mean read interval of a QueryModule on this stream (software model): {:.2} cycles \
         ({:.2} MaxFinder runs, {:.1} climbs per query); fitted Q: {}",
        cfg.mean_read_interval(&profile),
        profile.max_finds as f64 / queries.len().max(1) as f64,
        profile.climbs as f64 / queries.len().max(1) as f64,
        {
            let mut c = cfg;
            c.fit_queries_per_port(&profile);
            c.queries_per_port
        }
    );
    let opts = SimOptions {
        engine,
        memory: args.fmax_mhz.map(AxiTiming::ecp5_ddr3_at),
        ..SimOptions::default()
    };
    let run = crate::core_run::run_checked(&cfg, tree, &queries, max, &opts)?;
    let (results, secs, passes, load_cycles) =
        (&run.results, run.secs, run.passes, run.load_cycles);
    let (sw_visited, sw_tested) = (run.sw_visited, run.sw_tested);
    let st = &run.stats;
    // Every traversal's reads on the same queries (software search).
    let traversals: Vec<Traversal> = Traversal::value_variants().to_vec();
    let mut each_visited = vec![0u64; traversals.len()];
    for q in &queries {
        for (t, v) in traversals.iter().zip(&mut each_visited) {
            *v += search_with(tree, q.coords, cfg.k, max, cfg.metric, *t).visited as u64;
        }
    }
    let cycles = st.cycles - load_cycles;
    let reads: u64 = st.reads_per_port.iter().sum();
    let busy_per_port: Vec<String> = st
        .busy_reads_per_port
        .iter()
        .map(|r| format!("{:.3}", *r as f64 / st.busy_cycles.max(1) as f64))
        .collect();
    println!(
        "core: {cfg}; issue interval {}; radius {} on the grid",
        cfg.issue_interval(),
        radius.map_or("unbounded".to_string(), |r| format!(
            "{max} ({r} world units)"
        ))
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
        "photon reads per query by traversal (software search, same queries): {}",
        traversals
            .iter()
            .zip(&each_visited)
            .map(|(t, v)| format!("{t} {:.1}", *v as f64 / queries.len() as f64))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "reads per cycle (all ports of all trees, whole run): {:.3}",
        reads as f64 / cycles.max(1) as f64
    );
    if cfg.memory.is_some() {
        // What the cache asked of the external memory (its model's count).
        let m = st.memory;
        let q = queries.len().max(1) as f64;
        println!(
            "external memory: {} line fills ({:.3} per query, one per {:.0} reads), {} beats ({:.1} per query; the read data channel busy {:.1} % of the cycles)",
            m.bursts,
            m.bursts as f64 / q,
            reads as f64 / m.bursts.max(1) as f64,
            m.beats,
            m.beats as f64 / q,
            100.0 * m.beats as f64 / cycles.max(1) as f64
        );
    }
    // Per port (a barrel datapath, or a port's QueryModules) over the whole run,
    // fill and drain included: a lower bound on its rate while its slots are busy.
    println!(
        "reads per port per cycle (whole run): {}",
        st.reads_per_port
            .iter()
            .map(|&r| format!("{:.3}", r as f64 / cycles.max(1) as f64))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "reads per port per cycle while every QueryModule is busy ({} cycles): {}",
        st.busy_cycles,
        busy_per_port.join(", ")
    );
    // The result streams' load (paper §4.5: results leave through one port per
    // core): a header and the found photons, one or two a beat; each of the R
    // streams carries at most a beat a cycle.
    let per_stream: Vec<String> = st
        .result_beats_per_stream
        .iter()
        .map(|&b| format!("{:.3}", b as f64 / cycles.max(1) as f64))
        .collect();
    println!(
        "result stream: {:.1} beats per query, {:.3} beats per cycle (of at most {}){}",
        st.result_beats as f64 / queries.len().max(1) as f64,
        st.result_beats as f64 / cycles.max(1) as f64,
        per_stream.len().max(1),
        if per_stream.len() > 1 {
            format!("; per stream {}", per_stream.join(", "))
        } else {
            String::new()
        }
    );
    println!(
        "simulation speed ({:?}): {:.0} cycles/s",
        engine,
        cycles as f64 / secs
    );
    if let Some(p) = passes {
        // The native simulation's profile: two settles a cycle (clock low, rising
        // edge), each a few passes over every block.
        println!(
            "native settle passes per cycle: {:.1} ({:.0} passes/s, every block updated per pass)",
            p as f64 / cycles.max(1) as f64,
            p as f64 / secs
        );
    }
    if args.both_engines {
        // The same stream on the other simulator, side by side in this run: the
        // results and cycle counts must be equal.
        let other = match engine {
            Engine::Native => Engine::Verilator,
            Engine::Verilator => Engine::Native,
        };
        let mut sim2 = CoreSim::new(
            &cfg,
            &SimOptions {
                engine: other,
                ..opts
            },
        )?;
        sim2.load_map(tree.image())?;
        let t0 = std::time::Instant::now();
        let results2 = sim2.run_queries(&queries)?;
        let secs2 = t0.elapsed().as_secs_f64();
        let cycles2 = sim2.stats().cycles - load_cycles;
        if &results2 != results || cycles2 != cycles {
            return Err(Error::new(format!(
                "{other:?} disagrees with {:?}: {cycles2} against {cycles} cycles",
                engine
            )));
        }
        println!(
            "simulation speed ({other:?}, same stream, same results and cycles): {:.0} cycles/s",
            cycles2 as f64 / secs2
        );
    }
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
        let cpu = crate::cpu_ref::measure(points, tree, &coords, cfg.k, cfg.metric, max, min)
            .map_err(Error::new)?;
        println!(
            "cpu queries/s, 1 thread, same queries: kiddo {:.0}, software search {:.0}",
            cpu.kiddo, cpu.sw
        );
        println!(
            "cpu queries/s, all {} threads, same queries: kiddo {:.0}",
            cpu.threads, cpu.kiddo_all
        );
        if let Some(q) = core_qps {
            println!("core / kiddo: {:.2}", q / cpu.kiddo);
        }
    }
    Ok(())
}
