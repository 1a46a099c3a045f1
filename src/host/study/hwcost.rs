//! What a configuration costs in hardware: reads per cycle from a simulation of the
//! core on a sample of the study's own queries, and the clock and area that
//! `synth/REPORT.md` has for it (never invented: a configuration REPORT.md lacks
//! says so, and a clock borrowed from another row is labelled *assumed*).

use crate::host::error::{Error, Result};
use crate::host::gather::{GatherBackend, GatherParams, RtlBackend};
use crate::host::map::knn;
use crate::host::map::quantize::{GridPoint, Point};
use crate::hw::config::ReadProfile;
use crate::hw::metric::Metric;
use crate::hw::rtl::native::{Engine, SimOptions};

/// One simulated gather of a sample of queries.
#[derive(Clone, Debug, PartialEq)]
pub struct HwSim {
    pub engine: Engine,
    pub bits: u32,
    pub emitted: usize,
    pub sample: usize,
    /// QueryModules per port, fitted to the sample (as the rtl backend does).
    pub queries_per_port: usize,
    pub cycles: u64,
    pub reads: u64,
    /// Cycles with every QueryModule busy, and both ports' reads in them.
    pub busy_cycles: u64,
    pub busy_reads: u64,
}

impl HwSim {
    /// Photon reads per cycle (both ports) while every QueryModule is busy: the
    /// steady state of a long query stream. The whole run's rate (load, fill and
    /// drain included) when the sample never filled the core.
    pub fn reads_per_cycle(&self) -> f64 {
        if self.busy_cycles > 0 {
            self.busy_reads as f64 / self.busy_cycles as f64
        } else {
            self.reads as f64 / self.cycles.max(1) as f64
        }
    }

    pub fn engine_name(&self) -> &'static str {
        match self.engine {
            Engine::Native => "rust-hdl native",
            Engine::Verilator => "Verilator",
        }
    }

    /// Where [`HwSim::reads_per_cycle`] comes from, for the table.
    pub fn source(&self) -> String {
        let what = if self.busy_cycles > 0 {
            "all QueryModules busy"
        } else {
            "whole run incl. load"
        };
        format!(
            "simulated ({}, {} queries, {} bits, {} emitted, 2 x {} QueryModules, {what})",
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
    let backend = RtlBackend::new(photons, params, options)?;
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
    config.fit_queries_per_port(&profile);
    let stats = backend.stats.lock().expect("stats lock").clone();
    let sum = |f: &dyn Fn(&crate::hw::rtl::driver::SimStats) -> u64| stats.iter().map(f).sum();
    Ok(HwSim {
        engine,
        bits: params.bits,
        emitted,
        sample: points.len(),
        queries_per_port: config.queries_per_port,
        cycles: sum(&|s| s.cycles),
        reads: sum(&|s| s.reads_per_port.iter().sum()),
        busy_cycles: sum(&|s| s.busy_cycles),
        busy_reads: sum(&|s| s.busy_reads_per_port.iter().sum()),
    })
}

/// A configuration row of `synth/REPORT.md` that has results for the current
/// Verilog.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportRow {
    /// The row's name, e.g. `half Q (2x11)`.
    pub name: String,
    pub k: usize,
    pub bits: u32,
    pub metric: Metric,
    pub queries_per_port: usize,
    /// As written (e.g. `14,898 + 88 LUT-RAM`).
    pub luts: String,
    pub ffs: String,
    /// Best placed-and-routed ECP5-85k clock, if the row has one.
    pub fmax_mhz: Option<f64>,
}

/// The paper core's configuration (K = 10, 10-bit, L1, 2 x 21), which REPORT.md's
/// rows name only where they differ from it.
const PAPER: (usize, u32, Metric, usize) = (10, 10, Metric::L1, 21);

/// The number after `key` in `s` (`K=50` → 50), if any.
fn number_after(s: &str, key: &str) -> Option<u64> {
    let at = s.find(key)? + key.len();
    let digits: String = s[at..].chars().take_while(|c| c.is_ascii_digit()).collect();
    digits.parse().ok()
}

/// The configuration rows of REPORT.md's first table that have synthesis results,
/// for one tree, and that the study's sweep can match (the ascent and pipelining
/// variants are not swept and are left out, as is the paper's own Table 2 row).
pub fn parse_report(text: &str) -> Vec<ReportRow> {
    let table: Vec<Vec<String>> = text
        .lines()
        .skip_while(|l| !l.starts_with("| configuration"))
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            l.trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect();
    let Some(header) = table.first() else {
        return vec![];
    };
    let col = |name: &str| header.iter().position(|h| h.starts_with(name));
    let (Some(c_luts), Some(c_ffs), Some(c_fmax), Some(c_t)) =
        (col("LUTs"), col("FFs"), col("ECP5 fmax"), col("T"))
    else {
        return vec![];
    };
    let mut rows = vec![];
    for r in table.iter().skip(2) {
        let name = r[0].trim_matches('*').to_string();
        let skip = ["Table 2", "re-read", "unpipelined", "trees"];
        if r.len() <= c_fmax
            || skip.iter().any(|s| name.contains(s))
            || r[c_t] != "1"
            || r[c_luts].starts_with("n/a")
            || r[c_luts].is_empty()
        {
            continue;
        }
        let (mut k, mut bits, mut metric, mut q) = PAPER;
        if let Some(v) = number_after(&name, "K=") {
            k = v as usize;
        }
        if let Some(at) = name.find("-bit") {
            let head: String = name[..at]
                .chars()
                .rev()
                .take_while(|c| c.is_ascii_digit())
                .collect();
            bits = head
                .chars()
                .rev()
                .collect::<String>()
                .parse()
                .unwrap_or(bits);
        }
        if name.contains("L2") {
            metric = Metric::L2;
        }
        if let Some(v) = number_after(&name, "2x") {
            q = v as usize;
        }
        let fmax_mhz = r[c_fmax]
            .split_whitespace()
            .next()
            .and_then(|v| v.parse::<f64>().ok());
        rows.push(ReportRow {
            name,
            k,
            bits,
            metric,
            queries_per_port: q,
            luts: r[c_luts].clone(),
            ffs: r[c_ffs].clone(),
            fmax_mhz,
        });
    }
    rows
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

/// What REPORT.md says about a core of `k`, `bits`, `metric`: the matching row
/// (one with a clock first); without a matching clock, the first row's clock that
/// has one, labelled assumed.
pub fn cost(rows: &[ReportRow], k: usize, bits: u32, metric: Metric) -> Cost {
    let mut matching: Vec<&ReportRow> = rows
        .iter()
        .filter(|r| r.k == k && r.bits == bits && r.metric == metric)
        .collect();
    matching.sort_by_key(|r| r.fmax_mhz.is_none());
    let none = "not in REPORT.md".to_string();
    let (luts, ffs, area_source) = match matching.first() {
        Some(r) => (
            r.luts.clone(),
            r.ffs.clone(),
            format!(
                "synthesised (yosys xc6v), REPORT.md '{}' (2 x {})",
                r.name, r.queries_per_port
            ),
        ),
        None => (none.clone(), none.clone(), none.clone()),
    };
    let routed = |r: &ReportRow| r.fmax_mhz.map(|f| (f, r.name.clone()));
    let (fmax_mhz, fmax_source) = match matching.iter().find_map(|r| routed(r)) {
        Some((f, name)) => (
            Some(f),
            format!("placed-and-routed (nextpnr ECP5-85k), REPORT.md '{name}'"),
        ),
        None => match rows.iter().find_map(routed) {
            Some((f, name)) => (
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
