//! The study's `--exact` series: for each coordinate width and each m, what share of
//! the queries the certificate proves (`host::exact`), how many photon reads a query
//! costs the core and the host's float fallbacks, what a retry on the core would
//! have cost instead of the fallback, and whether every answer is the float
//! search's (it must be: that is what `--exact` promises).
//!
//! The core's candidates are the software model's (`sw`), which the simulated core
//! equals read for read; a point's hardware queries/s is the core's photon reads per
//! second (simulated reads per cycle × the clock, `hwcost`) over its reads per query
//! with the fallbacks' reads included, as if the fallbacks ran at the core's rate.

use crate::study::hwcost::{self, Cost, ReportRow};
use crate::study::plan::Plan;
use crate::study::sweep::{self, Sweep};
use photon_fpga::host::error::Result;
use photon_fpga::host::exact::ExactBackend;
use photon_fpga::host::gather::{BackendKind, FloatBackend, GatherBackend, GatherParams, Gathered};
use photon_fpga::host::map::quantize::{GridPoint, Point};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::sim::native::SimOptions;
use rayon::prelude::*;

/// The core's photon reads per second behind a point: simulated reads per cycle
/// and the clock, each with where it comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactHw {
    pub reads_per_cycle: f64,
    /// `HwSim::source` of the simulation the reads per cycle come from.
    pub reads_source: String,
    /// The clock and area `synth/results.json` has for the core with K = k′.
    pub cost: Cost,
}

impl ExactHw {
    pub fn reads_per_s(&self) -> Option<f64> {
        self.cost.fmax_mhz.map(|f| self.reads_per_cycle * f * 1e6)
    }
}

/// One (bits, m) point of the series.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactPoint {
    pub bits: u32,
    pub k: usize,
    pub m: usize,
    /// m was chosen by the exact backend (`--exact` without `--refine`).
    pub chosen: bool,
    pub queries: u64,
    /// Queries inside the photon box (the core's).
    pub core_queries: u64,
    pub certified: u64,
    /// Float fallbacks (uncertified or tied at rank k).
    pub fallbacks: u64,
    /// Photon reads per query: the core's, and the float fallbacks'.
    pub core_reads: f64,
    pub host_reads: f64,
    /// A retry of each uncertified query on the core at the largest k′ it holds
    /// instead of the float search: how many it would certify, and its reads per
    /// retried query (the first pass not counted), and that k′ (the core's K).
    pub retry_k: usize,
    pub retry_certified: u64,
    pub retry_reads: f64,
    /// The float search's reads per fallback query.
    pub fallback_reads: f64,
    /// Queries whose answer (photons and distances, bit for bit) differs from the
    /// float search's: 0, or `--exact` is wrong.
    pub differ: u64,
    /// Where the core's reads per second come from, if simulated (the study).
    pub hw: Option<ExactHw>,
}

impl ExactPoint {
    pub fn certified_share(&self) -> f64 {
        self.certified as f64 / self.core_queries.max(1) as f64
    }

    /// Photon reads per query, fallbacks included.
    pub fn reads(&self) -> f64 {
        self.core_reads + self.host_reads
    }

    /// Queries per second at `reads_per_s` core reads per second, fallbacks included.
    pub fn queries_per_s(&self, reads_per_s: f64) -> f64 {
        reads_per_s / self.reads().max(1.0)
    }

    /// Hardware queries per second, fallbacks included, where simulated and clocked.
    pub fn hw_queries_per_s(&self) -> Option<f64> {
        Some(self.queries_per_s(self.hw.as_ref()?.reads_per_s()?))
    }
}

/// Whether two answers are the same photons at the same distances, bit for bit.
fn same(a: &Gathered, b: &Gathered) -> bool {
    a.neighbours.len() == b.neighbours.len()
        && a.neighbours
            .iter()
            .zip(&b.neighbours)
            .all(|(x, y)| x.photon == y.photon && x.distance.to_bits() == y.distance.to_bits())
}

/// The series on `photons` and `queries` for each width of `bits` and each m of
/// `ms` (`None`: the m the exact backend chooses; an m the core cannot take with
/// `base.k` is skipped).
pub fn run(
    photons: &[Point],
    queries: &[Point],
    base: &GatherParams,
    bits: &[u32],
    ms: &[Option<usize>],
) -> Result<Vec<ExactPoint>> {
    let float = FloatBackend::new(photons, base)?.gather(queries)?;
    let mut out = vec![];
    for &b in bits {
        let params = GatherParams {
            bits: b,
            ..base.clone()
        };
        // The deepest list the study's core (its controller) holds.
        let max_k = base.core.chosen_controller().max_k();
        for &refine in ms.iter().filter(|m| m.is_none_or(|m| base.k + m <= max_k)) {
            let exact = ExactBackend::new(
                BackendKind::Native,
                photons,
                &params,
                refine,
                &SimOptions::default(),
            )?;
            let got = exact.gather_with_model(queries)?;
            let differ = got.iter().zip(&float).filter(|(g, f)| !same(g, f)).count() as u64;
            let s = exact.stats();
            let q = s.queries.max(1) as f64;
            let fallbacks = s.uncertified + s.ties;
            let (retry_certified, retry_reads) = retry(&exact, queries, max_k);
            out.push(ExactPoint {
                bits: b,
                k: base.k,
                m: s.m,
                chosen: s.chosen,
                queries: s.queries,
                core_queries: s.queries - s.outside,
                certified: s.certified,
                fallbacks,
                core_reads: s.core_reads as f64 / q,
                host_reads: s.host_reads as f64 / q,
                retry_k: max_k.max(base.k + s.m),
                retry_certified,
                retry_reads: retry_reads as f64 / (fallbacks.max(1)) as f64,
                fallback_reads: s.host_reads as f64 / (fallbacks + s.outside).max(1) as f64,
                differ,
                hw: None,
            });
        }
    }
    Ok(out)
}

/// The uncertified queries of `exact`'s last gather retried at `k_retry`: how many a
/// retry certifies and the retries' core reads (integer sums: the same on any
/// number of threads).
fn retry(exact: &ExactBackend, queries: &[Point], k_retry: usize) -> (u64, u64) {
    let m = exact.last_m();
    let k = exact.map.params.k;
    queries
        .par_iter()
        .map(|&q| {
            let Ok(GridPoint::Inside(c)) = exact.map.locate(q) else {
                return (0, 0);
            };
            if exact.certify(q, c, k + m).0 {
                return (0, 0);
            }
            let (ok, r) = exact.certify(q, c, k_retry.max(k + m));
            (ok as u64, r as u64)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// The study's series: its scene and photons, and its points.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactSeries {
    pub scene: String,
    pub emitted: usize,
    pub stored: usize,
    pub metric: Metric,
    pub k: usize,
    pub points: Vec<ExactPoint>,
}

/// The series of `plan` (its first scene at the base photon count, the sweep's eye
/// queries), each point with the core's reads per second: the reads per cycle of
/// the sweep's simulation of this scene, metric and k at the nearest simulated bits
/// (as the sweep's own points take theirs), and the clock `report` has for the core
/// with K = k′ = k + m (labelled assumed where it has none).
pub fn study(plan: &Plan, sweep: &Sweep, report: &[ReportRow]) -> Result<ExactSeries> {
    let (name, scene) = &plan.scenes[0];
    let emitted = plan.photons[0];
    let eye = sweep::eye(scene, plan);
    let (ph, pts) = sweep::photons(scene, emitted, plan.seed)?;
    let base = GatherParams {
        k: plan.exact_k,
        metric: plan.exact_metric,
        traversal: plan.traversal,
        core: plan.core,
        ..GatherParams::default()
    };
    let mut points = run(&pts, &eye.points, &base, &plan.exact_bits, &plan.exact_ms)?;
    let metric = plan.exact_metric.to_string();
    for p in &mut points {
        let nearest = sweep
            .sims
            .iter()
            .filter(|((s, m, k, _), _)| s == name && *m == metric && *k == plan.exact_k)
            .min_by_key(|((.., b), _)| (*b as i64 - p.bits as i64).abs());
        p.hw = nearest.map(|(_, sim)| ExactHw {
            reads_per_cycle: sim.reads_per_cycle(),
            reads_source: sim.source(),
            cost: hwcost::cost(report, p.k + p.m, p.bits, plan.exact_metric),
        });
    }
    Ok(ExactSeries {
        scene: name.clone(),
        emitted,
        stored: ph.len(),
        metric: plan.exact_metric,
        k: plan.exact_k,
        points,
    })
}
