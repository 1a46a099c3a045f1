//! `photon-fpga-lab study`: the accuracy/throughput sweep, its table and
//! Pareto plot, and the paper's Figs. 3–6 from the project's own runs.

use crate::study::hwcost::SynthResults;
use crate::study::plan::{Plan, STUDY_CONTROLLER};
use crate::study::report::{self, OutDir};
use crate::study::{exact_series, figures, sweep};
use clap::Args;
use indicatif::ProgressBar;
use photon_fpga::cli::core_args::flags;
use photon_fpga::cli::set_threads;
use photon_fpga::host::error::Result;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::core_spec::{CoreChoice, CoreSpec};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::sim::native::Engine;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub struct StudyArgs {
    /// Scene file (TOML); the built-in Cornell box and corridor if absent.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// A reduced sweep for tests (under a minute in a debug build): one scene,
    /// 32x32, 3000 photons, bits 6/10/16, k = 10 (the --exact series: k = 10).
    #[arg(long)]
    pub quick: bool,
    /// The synthesis results the clocks and areas come from (synth/report.py's
    /// data; REPORT.md is rendered from it).
    #[arg(long, default_value = "synth/results.json")]
    pub report: PathBuf,
    /// Simulator for the core's reads per cycle (default: Verilator when installed
    /// and not --quick, else rust-hdl's native simulation).
    #[arg(long, value_enum)]
    pub engine: Option<Engine>,
    /// Worker threads (results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// The core simulated and costed [default: the barrel controller, cell
    /// traversal; `--controller modules` is the paper's core]. Its clock and area come from the rows of --report
    /// with these options (one tree, pipelined); K, grid and metric follow each
    /// point of the sweep.
    #[command(flatten)]
    pub core: CoreChoice,
    /// Output directory: study.csv, STUDY.md, exact.csv, pareto.png, exact.png,
    /// fig3.png … fig6.png.
    #[arg(long)]
    pub out: PathBuf,
}

fn on_path(tool: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| Path::new(&d).join(tool).is_file()))
}

pub fn study(args: &StudyArgs) -> Result<()> {
    set_threads(args.threads)?;
    // Everything that can be refused is refused before the sweep: the report, the
    // scene, the output directory.
    // The study simulates the chosen core: only rows of that core give it a clock
    // and an area.
    let controller = args.core.controller.unwrap_or(STUDY_CONTROLLER);
    let traversal = args
        .core
        .traversal
        .unwrap_or(controller.default_traversal());
    let choice = CoreSpec {
        choice: CoreChoice {
            controller: Some(controller),
            traversal: Some(traversal),
            ..args.core.clone()
        },
        ..CoreSpec::default()
    };
    let core = CoreConfig::builder().with_spec(&choice)?;
    core.build()?;
    let rows = SynthResults::read(&args.report)?.study_rows(traversal, controller);
    let scene = match &args.scene {
        Some(p) => {
            let name = p
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            Some((name, Scene::from_file(p)?))
        }
        None => None,
    };
    let out = OutDir::check(&args.out)?;
    let engine = args
        .engine
        .unwrap_or(if !args.quick && on_path("verilator") {
            Engine::Verilator
        } else {
            Engine::Native
        });
    let mut plan = if args.quick {
        Plan::quick(scene)
    } else {
        Plan::full(scene, engine)
    };
    plan.engine = engine;
    plan.core = core;
    plan.traversal = traversal;
    let bar = ProgressBar::new(0);
    let result = sweep::run(&plan, &rows, &bar)?;
    bar.set_message("the --exact series");
    let exact = exact_series::study(&plan, &result, &rows)?;
    bar.set_message("figures 3-6");
    // The core's reads per second at the figures' configuration, where simulated.
    let hw_rate = |k: usize| -> Option<f64> {
        if k > plan.hw_max_k() {
            return None;
        }
        result
            .rows
            .iter()
            .find(|r| {
                r.scene == plan.scenes[0].0
                    && r.emitted == plan.photons[0]
                    && r.metric == Metric::L1
                    && r.k == k
                    && r.bits == figures::FIG_BITS
            })
            .and_then(|r| r.hw.as_ref())
            .and_then(|h| Some(h.sim.reads_per_cycle() * h.cost.fmax_mhz? * 1e6))
            .filter(|rate| *rate > 0.0)
    };
    let figs = figures::run(&plan, &hw_rate)?;
    bar.finish_and_clear();
    let mut command = "photon-fpga-lab study".to_string();
    if let Some(s) = &args.scene {
        command += &format!(" --scene {}", s.display());
    }
    if args.quick {
        command += " --quick";
    }
    command += &flags(&CoreSpec {
        choice: args.core.clone(),
        ..CoreSpec::default()
    });
    command += &format!(" --out {}", args.out.display());
    report::write_all(out.staging(), &plan, &result, &exact, &figs, &command)?;
    out.commit()?;
    println!(
        "{} points; wrote {} in {}",
        result.rows.len(),
        report::FILES.join(", "),
        args.out.display()
    );
    Ok(())
}
