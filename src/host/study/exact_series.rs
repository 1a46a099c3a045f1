//! The study's `--exact` series: for each coordinate width and each m, what share of
//! the queries the certificate proves (`host::exact`), how many photon reads a query
//! costs the core and the host's float fallbacks, and what a retry on the core would
//! have cost instead of the fallback.
//!
//! The core's candidates are the software model's (`sw`), which the simulated core
//! equals read for read; a point's hardware queries/s is the core's photon reads per
//! second (simulated reads per cycle × the clock, `hwcost`) over its reads per query
//! with the fallbacks' reads included, as if the fallbacks ran at the core's rate.

use crate::host::error::Result;
use crate::host::exact::ExactBackend;
use crate::host::gather::{BackendKind, GatherParams};
use crate::host::map::quantize::{GridPoint, Point};
use crate::hw::config::MAX_K;
use crate::hw::rtl::native::SimOptions;

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
    /// retried query (the first pass not counted).
    pub retry_certified: u64,
    pub retry_reads: f64,
    /// The float search's reads per fallback query.
    pub fallback_reads: f64,
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
    let mut out = vec![];
    for &b in bits {
        let params = GatherParams {
            bits: b,
            ..base.clone()
        };
        for &refine in ms.iter().filter(|m| m.is_none_or(|m| base.k + m <= MAX_K)) {
            let exact = ExactBackend::new(
                BackendKind::Rtl,
                photons,
                &params,
                refine,
                &SimOptions::default(),
            )?;
            exact.gather_with_model(queries)?;
            let s = exact.stats();
            let q = s.queries.max(1) as f64;
            let fallbacks = s.uncertified + s.ties;
            let (retry_certified, retry_reads) = retry(&exact, queries, MAX_K);
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
                retry_certified,
                retry_reads: retry_reads as f64 / (fallbacks.max(1)) as f64,
                fallback_reads: s.host_reads as f64 / (fallbacks + s.outside).max(1) as f64,
            });
        }
    }
    Ok(out)
}

/// The uncertified queries of `exact`'s last gather retried at `k_retry`: how many a
/// retry certifies and the retries' core reads.
fn retry(exact: &ExactBackend, queries: &[Point], k_retry: usize) -> (u64, u64) {
    let m = exact.last_m();
    let k = exact.map.params.k;
    let (mut certified, mut reads) = (0, 0u64);
    for &q in queries {
        let Ok(GridPoint::Inside(c)) = exact.map.locate(q) else {
            continue;
        };
        if exact.certify(q, c, k + m).0 {
            continue;
        }
        let (ok, r) = exact.certify(q, c, k_retry.max(k + m));
        certified += ok as u64;
        reads += r as u64;
    }
    (certified, reads)
}

/// The series as a Markdown table; `reads_per_s` (the core's photon reads per second
/// and where that figure comes from) adds hardware queries/s.
pub fn markdown(points: &[ExactPoint], reads_per_s: Option<(f64, &str)>) -> String {
    let mut s = String::from(
        "| bits | k | m | certified | fallbacks | core reads/query | fallback reads/query | \
         reads/query | retry at K = 64: certifies / reads | queries/s |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for p in points {
        let qps = reads_per_s.map_or("".into(), |(r, _)| {
            format!("{:.2} M", p.queries_per_s(r) / 1e6)
        });
        s.push_str(&format!(
            "| {} | {} | {} | {:.2} % | {} | {:.1} | {:.2} | {:.1} | {} of {} / {:.1} | {qps} |\n",
            p.bits,
            p.k,
            p.m,
            100.0 * p.certified_share(),
            p.fallbacks,
            p.core_reads,
            p.host_reads,
            p.reads(),
            p.retry_certified,
            p.fallbacks,
            p.retry_reads,
        ));
    }
    if let Some((_, source)) = reads_per_s {
        s.push_str(&format!(
            "\nqueries/s: {source}, over reads/query with the fallbacks'.\n"
        ));
    }
    s
}

/// The study's section: at `bits`, the exact configuration with the m the backend
/// chooses against the unrefined core (the m = 0 point's core reads: the same search
/// at k′ = k, without re-ranking), then the whole series.
pub fn section(points: &[ExactPoint], bits: u32, reads_per_s: Option<(f64, &str)>) -> String {
    let mut s = String::new();
    let at = |chosen: bool, m: Option<usize>| {
        points
            .iter()
            .find(|p| p.bits == bits && p.chosen == chosen && m.is_none_or(|m| p.m == m))
    };
    if let (Some(e), Some(u)) = (at(true, None), at(false, Some(0))) {
        let qps = |reads: f64| {
            reads_per_s.map_or(String::new(), |(r, _)| {
                format!(", {:.2} M queries/s", r / reads.max(1.0) / 1e6)
            })
        };
        s.push_str(&format!(
            "At {bits} bits, k = {}: `--exact` (m = {} chosen, {:.2} % certified) reads {:.1} \
             photons per query with its fallbacks{}; the unrefined core reads {:.1}{}.\n\n",
            e.k,
            e.m,
            100.0 * e.certified_share(),
            e.reads(),
            qps(e.reads()),
            u.core_reads,
            qps(u.core_reads),
        ));
    }
    s.push_str(&markdown(points, reads_per_s));
    s
}
