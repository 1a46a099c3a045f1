//! What a configuration costs in hardware: reads per cycle from a simulation of the
//! core on a sample of the study's own queries, and the clock and area that
//! `synth/results.json` (rendered as `synth/REPORT.md`) has for it, read with serde
//! and selected by the rows' core options (never invented: a configuration the
//! results lack says so, and a clock borrowed from another row is labelled
//! *assumed*).

use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{GatherBackend, GatherParams, SimBackend};
use photon_fpga::host::map::knn;
use photon_fpga::host::map::quantize::{GridPoint, Point};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{ReadProfile, PORTS};
use photon_fpga::hw::config::core_spec::CoreSpec;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::native::{Engine, SimOptions};
use serde::Deserialize;
use std::path::Path;

/// One simulated gather of a sample of queries.
#[derive(Clone, Debug, PartialEq)]
pub struct HwSim {
    pub engine: Engine,
    pub bits: u32,
    pub emitted: usize,
    pub sample: usize,
    /// The controller and trees simulated, and its Q per port (QueryModules or
    /// query slots), fitted to the sample unless given (as the rtl backend does).
    pub controller: Controller,
    pub trees: usize,
    pub queries_per_port: usize,
    pub cycles: u64,
    /// Cycles from the first query on (without the map's load).
    pub search_cycles: u64,
    pub reads: u64,
    /// Cycles with every QueryModule busy, and both ports' reads in them.
    pub busy_cycles: u64,
    pub busy_reads: u64,
}

impl HwSim {
    /// Photon reads per cycle (both ports) while every QueryModule is busy: the
    /// steady state of a long query stream. Otherwise the rate from the first query
    /// on (fill and drain included, the map's load not): when the sample never
    /// filled the core, and always for the barrel controller, whose slots are
    /// refilled from the dispatcher as they free (all slots occupied at once is not
    /// its steady state, and a handful of such cycles would make a noisy rate).
    pub fn reads_per_cycle(&self) -> f64 {
        if self.steady() {
            self.busy_reads as f64 / self.busy_cycles as f64
        } else {
            self.reads as f64 / self.search_cycles.max(1) as f64
        }
    }

    fn steady(&self) -> bool {
        self.controller == Controller::Modules && self.busy_cycles > 0
    }

    pub fn engine_name(&self) -> &'static str {
        match self.engine {
            Engine::Native => "rust-hdl native",
            Engine::Verilator => "Verilator",
        }
    }

    /// Where [`HwSim::reads_per_cycle`] comes from, for the table.
    pub fn source(&self) -> String {
        let what = if self.steady() {
            "all QueryModules busy"
        } else {
            "from the first query, fill and drain incl."
        };
        let q = match self.controller {
            Controller::Modules => "QueryModules",
            Controller::Barrel => "query slots",
        };
        let trees = if self.trees > 1 {
            format!("{} trees x ", self.trees)
        } else {
            String::new()
        };
        format!(
            "simulated ({}, {} queries, {} bits, {} emitted, {trees}{PORTS} x {} {q}, {what})",
            self.engine_name(),
            self.sample,
            self.bits,
            self.emitted,
            self.queries_per_port
        )
    }
}

/// Simulate the core for `params` on an even sample of `sample` of `queries` (those
/// inside the photon box, which the core takes) and check every answer against the
/// software search. One simulation (a one-thread pool), so every QueryModule of one
/// core is in use.
pub fn simulate(
    photons: &[Point],
    queries: &[Point],
    params: &GatherParams,
    emitted: usize,
    sample: usize,
    engine: Engine,
) -> Result<HwSim> {
    let options = SimOptions {
        engine,
        ..SimOptions::default()
    };
    let backend = SimBackend::new(photons, params, options)?;
    let m = &backend.map;
    let inside: Vec<(Point, [u32; 3])> = queries
        .iter()
        .filter_map(|&q| match m.locate(q) {
            Ok(GridPoint::Inside(c)) => Some((q, c)),
            _ => None,
        })
        .collect();
    let step = inside.len().div_ceil(sample.max(1)).max(1);
    let picked: Vec<(Point, [u32; 3])> = inside.into_iter().step_by(step).collect();
    let points: Vec<Point> = picked.iter().map(|p| p.0).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| Error::new(format!("cannot start a simulation thread: {e}")))?;
    let got = pool.install(|| backend.gather(&points))?;
    // The core runs the software search's very algorithm: same neighbours, same reads.
    let mut profiles = Vec::with_capacity(picked.len());
    for ((_, c), g) in picked.iter().zip(&got) {
        let f = knn::search_with(
            &m.tree,
            *c,
            params.k,
            m.radius_bound,
            params.metric,
            params.traversal,
        );
        if m.neighbours(&f.slots) != g.neighbours || f.visited != g.visited {
            return Err(Error::new(format!(
                "the simulated core and the software search disagree at grid point {c:?}"
            )));
        }
        profiles.push(f.read_profile());
    }
    let profile: ReadProfile = profiles.into_iter().sum();
    let mut config = backend.config;
    if backend.fit_q {
        config.fit_queries_per_port(&profile);
    }
    let stats = backend.stats.lock().expect("stats lock").clone();
    let sum =
        |f: &dyn Fn(&photon_fpga::hw::sim::driver::SimStats) -> u64| stats.iter().map(f).sum();
    Ok(HwSim {
        engine,
        bits: params.bits,
        emitted,
        sample: points.len(),
        controller: config.controller,
        trees: config.trees,
        queries_per_port: config.queries_per_port,
        cycles: sum(&|s| s.cycles),
        search_cycles: sum(&|s| s.search_cycles),
        reads: sum(&|s| s.reads_per_port.iter().sum()),
        busy_cycles: sum(&|s| s.busy_cycles),
        busy_reads: sum(&|s| s.busy_reads_per_port.iter().sum()),
    })
}

/// `synth/results.json` as `synth/report.py` writes it: the fields the study reads
/// (serde ignores the others).
#[derive(Clone, Debug, Deserialize)]
pub struct SynthResults {
    pub schema: u32,
    pub rows: Vec<SynthRow>,
}

/// One configuration's record.
#[derive(Clone, Debug, Deserialize)]
pub struct SynthRow {
    pub name: String,
    /// The core measured: the core file export-verilog wrote for it.
    pub core: CoreSpec,
    /// yosys xc6v cell counts, if synthesised.
    pub xc6v: Option<SynthXc6v>,
    /// nextpnr ECP5-85k place and route, if run.
    pub ecp5: Option<SynthEcp5>,
    /// Why the row has no results, if it has none.
    pub status: Option<String>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct SynthXc6v {
    pub luts: u64,
    pub lutram: u64,
    pub ffs: u64,
}

#[derive(Clone, Debug, Deserialize)]
pub struct SynthEcp5 {
    /// The fmax (MHz) of every seed that gave one.
    pub fmax_mhz: Vec<f64>,
    /// Why no seed gave a clock.
    pub error: Option<String>,
}

/// The schema of `synth/results.json` this reader understands.
pub const RESULTS_SCHEMA: u32 = 2;

impl SynthResults {
    /// Parse `text`, the contents of `path` (named in the errors).
    pub fn parse(text: &str, path: &Path) -> Result<SynthResults> {
        let r: SynthResults = serde_json::from_str(text)
            .map_err(|e| Error::new(format!("{}: {e}", path.display())))?;
        if r.schema != RESULTS_SCHEMA {
            return Err(Error::new(format!(
                "{}: schema {}, this build reads schema {RESULTS_SCHEMA}",
                path.display(),
                r.schema
            )));
        }
        Ok(r)
    }

    /// Read and parse `path`.
    pub fn read(path: &Path) -> Result<SynthResults> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            Error::new(format!(
                "{}: cannot read the synthesis report ({e}); give --report FILE",
                path.display()
            ))
        })?;
        SynthResults::parse(&text, path)
    }

    /// The single-core rows with results whose core runs the study's search: the
    /// same traversal and controller, pipelined, distances as wide as the grid's
    /// diagonal (the study's gathers are unbounded; the variants kept for
    /// before/after timing are not swept). A core's clock and area depend on these
    /// options, so a row of another traversal or controller would misstate them.
    pub fn study_rows(&self, traversal: Traversal, controller: Controller) -> Vec<ReportRow> {
        self.rows
            .iter()
            .filter(|r| {
                let (c, b) = (&r.core.choice, &r.core.build);
                r.status.is_none()
                    && c.trees == Some(1)
                    && b.banks.is_none()
                    && b.pipelined == Some(true)
                    && b.radius_bits.is_none()
                    && c.traversal == Some(traversal)
                    && c.controller == Some(controller)
            })
            .map(|r| ReportRow {
                name: r.name.clone(),
                k: r.core.build.k.unwrap_or_default(),
                bits: r.core.build.coordinate_bits.map_or(0, |w| w.0[0]),
                metric: r.core.build.metric.unwrap_or_default(),
                queries_per_port: r.core.choice.queries_per_port,
                luts: r.xc6v.as_ref().map_or("?".into(), |x| {
                    let mut s = thousands(x.luts);
                    if x.lutram > 0 {
                        s += &format!(" + {} LUT-RAM", x.lutram);
                    }
                    s
                }),
                ffs: r.xc6v.as_ref().map_or("?".into(), |x| thousands(x.ffs)),
                fmax_mhz: r
                    .ecp5
                    .as_ref()
                    .filter(|e| e.error.is_none())
                    .and_then(|e| e.fmax_mhz.iter().copied().reduce(f64::max)),
            })
            .collect()
    }
}

/// `n` with a comma every three digits, as REPORT.md prints counts.
fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A configuration of `synth/results.json` with results, as the study uses it.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportRow {
    /// The row's name, e.g. `paper, worst-case Q (2x21)`.
    pub name: String,
    pub k: usize,
    pub bits: u32,
    pub metric: Metric,
    /// None: export-verilog's default (the issue interval).
    pub queries_per_port: Option<usize>,
    /// As REPORT.md prints it (e.g. `9,870 + 206 LUT-RAM`).
    pub luts: String,
    pub ffs: String,
    /// Best placed-and-routed ECP5-85k clock, if the row has one.
    pub fmax_mhz: Option<f64>,
}

/// The clock and area of one study point, each with where it comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct Cost {
    pub fmax_mhz: Option<f64>,
    pub fmax_source: String,
    pub luts: String,
    pub ffs: String,
    pub area_source: String,
}

impl Cost {
    /// The table's tag for the clock: placed and routed for this configuration, or
    /// assumed from another row.
    pub fn clock_tag(&self) -> &'static str {
        if self.fmax_source.starts_with("placed") {
            "[P&R]"
        } else if self.fmax_source.starts_with("assumed") {
            "[assumed]"
        } else {
            ""
        }
    }
}

/// What REPORT.md says about a core of `k`, `bits`, `metric`: the row of that very
/// configuration (one with a clock first); failing that, the row of the same bits
/// and metric with the smallest K above k (a core of K answers any k up to K: the
/// study's k = 500 runs on the K = 512 core). Without a matching clock, the clock of
/// the row nearest in K (the smallest K at or above k, else the largest), labelled
/// assumed: the found list's depth sets the clock of the large-K cores.
pub fn cost(rows: &[ReportRow], k: usize, bits: u32, metric: Metric) -> Cost {
    let same = |r: &&ReportRow| r.bits == bits && r.metric == metric;
    let mut matching: Vec<&ReportRow> = rows.iter().filter(|r| same(r) && r.k == k).collect();
    if matching.is_empty() {
        let holds = rows
            .iter()
            .filter(|r| same(r) && r.k > k)
            .map(|r| r.k)
            .min();
        matching = rows
            .iter()
            .filter(|r| same(r) && Some(r.k) == holds)
            .collect();
    }
    matching.sort_by_key(|r| r.fmax_mhz.is_none());
    let none = "not in REPORT.md".to_string();
    let holds = |r: &ReportRow| {
        if r.k == k {
            String::new()
        } else {
            format!(", K = {} holds k = {k}", r.k)
        }
    };
    let (luts, ffs, area_source) = match matching.first() {
        Some(r) => (
            r.luts.clone(),
            r.ffs.clone(),
            format!(
                "synthesised (yosys xc6v), REPORT.md '{}' (2 x {}{})",
                r.name,
                r.queries_per_port
                    .map_or("the issue interval".into(), |q| q.to_string()),
                holds(r)
            ),
        ),
        None => (none.clone(), none.clone(), none.clone()),
    };
    let routed = |r: &ReportRow| r.fmax_mhz.map(|f| (f, r.name.clone(), holds(r)));
    // Rows with a clock, nearest in K first: the smallest K at or above k, then the
    // rest from the largest K down.
    let mut nearest: Vec<&ReportRow> = rows.iter().filter(|r| r.fmax_mhz.is_some()).collect();
    nearest.sort_by_key(|r| {
        if r.k >= k {
            (0, r.k)
        } else {
            (1, usize::MAX - r.k)
        }
    });
    let (fmax_mhz, fmax_source) = match matching.iter().find_map(|r| routed(r)) {
        Some((f, name, holds)) => (
            Some(f),
            format!("placed-and-routed (nextpnr ECP5-85k), REPORT.md '{name}'{holds}"),
        ),
        None => match nearest.iter().find_map(|r| routed(r)) {
            Some((f, name, _)) => (
                Some(f),
                format!("assumed: the clock of REPORT.md '{name}' (this configuration is not in REPORT.md)"),
            ),
            None => (None, none),
        },
    };
    Cost {
        fmax_mhz,
        fmax_source,
        luts,
        ffs,
        area_source,
    }
}
