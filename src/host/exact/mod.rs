//! `--exact`: the float gather's answers from the quantized core, by certified
//! re-ranking on the host.
//!
//! The core (or its software model, `sw`) searches the k′ = k + m nearest photons
//! on the grid; the host re-ranks them by their exact f64 distances and keeps the k
//! best when a certificate proves that no photon the core did not return is nearer
//! ([`rerank`], with the grid's error bound δ derived in [`bound`]). A query that
//! is not certified — or lies outside the photon box, where the core cannot take
//! it — is answered by the float search itself, so every answer is exactly
//! `--backend float`'s: the same photons, distances and ties, within the float
//! gather's radius. Vector search re-ranks quantized candidates the same way (the
//! refine step of FAISS), without a certificate.
//!
//! # Why the float search, not a retry on the core
//! An uncertified query could go back to the core with a larger k′. That second
//! search starts again from the root, so it costs at least the reads of the first
//! one and more (a larger k′ keeps a larger radius longer), it is capped by the
//! core's found-list depth (its controller's K limit), and it can fail again: a query
//! whose candidates tie at rank k needs the float search in any case. The float
//! search of the same query reads about as many photons as the first core pass
//! did, once, and is exact by definition. So the fallback is the float search.
//!
//! # Choosing m
//! Without `--refine`, m is chosen per gather on an even sample of its queries
//! (inside the photon box) by the software model of the core, which returns the
//! core's very candidates. For each m of a ladder (0, 1, 2, 3, 4, 6, 8, 12, …, up to
//! max(k, 8) and no more than the core's found list allows) it counts the sample's
//! core reads plus the float reads of its uncertified queries; the cheapest m wins,
//! the smaller on a tie. Both are counted as photon reads with equal weight, the
//! measure the run summary and the study report (reads per query), which depends on
//! no clock and no thread count, so the choice is the same on every run.

pub mod bound;
pub mod rerank;
pub mod stats;

use crate::host::error::{Error, Result};
use crate::host::gather::{
    run_core, BackendKind, FloatBackend, GatherBackend, GatherParams, Gathered, QuantizedMap,
};
use crate::host::map::knn::{self, FloatDist, Scalar};
use crate::host::map::quantize::{GridPoint, Point};
use crate::hw::config::metric::Metric;
use crate::hw::sim::driver::{HwQuery, SimStats};
use crate::hw::sim::native::{Engine, SimOptions};
use bound::Bound;
use rayon::prelude::*;
use rerank::{Rerank, Verdict};
pub use stats::ExactStats;
use std::sync::Mutex;

/// One query's candidates, (photon index, grid distance), and the core's reads.
type Candidates = (Vec<(u32, u64)>, u32);

/// Queries of a gather that choose m.
const SAMPLE: usize = 256;

/// Why `--exact` cannot run on `kind` with `k` and `refine`, if it cannot, on a
/// core whose found lists hold at most `max_k` (its controller's); checked before
/// any work.
pub fn check(kind: BackendKind, k: usize, refine: Option<usize>, max_k: usize) -> Result<()> {
    if kind == BackendKind::Float {
        return Err(Error::new(
            "--exact refines a quantized backend's answers to the float search's; \
             --backend float is exact already (give --backend sw, native or verilator)",
        ));
    }
    if let Some(m) = refine {
        if kind.simulates() && k + m > max_k {
            return Err(Error::new(format!(
                "--refine {m} with --k {k} asks the core for {} candidates per query; its \
                 found list holds at most {max_k} (give --refine {} or less)",
                k + m,
                max_k.saturating_sub(k)
            )));
        }
    }
    Ok(())
}

/// The most candidates per query an exact gather of `k` may ask for (k + the given
/// m, or + the largest m the choice tries): what its memory must hold.
pub fn largest_k_prime(
    kind: BackendKind,
    k: usize,
    refine: Option<usize>,
    max_k: usize,
) -> Result<usize> {
    let m = refine.unwrap_or_else(|| max_refine(kind, k, max_k));
    k.checked_add(m)
        .ok_or_else(|| Error::new(format!("--refine {m} with --k {k} is too large")))
}

/// The largest m a core of found lists up to `max_k` can take with `k`.
fn max_refine(kind: BackendKind, k: usize, max_k: usize) -> usize {
    let ladder_top = k.max(8);
    if kind.simulates() {
        ladder_top.min(max_k.saturating_sub(k))
    } else {
        ladder_top
    }
}

/// Which core searches the candidates.
enum Core {
    /// The software model on the packed tree.
    Sw,
    /// A simulation of the core.
    Hw {
        options: SimOptions,
        fit_q: bool,
        stats: Mutex<Vec<SimStats>>,
    },
}

/// The exact backend over a quantized one (sw, rtl or verilator).
pub struct ExactBackend {
    kind: BackendKind,
    photons: Vec<Point>,
    pub map: QuantizedMap,
    float: FloatBackend,
    pub bound: Bound,
    r0: FloatDist,
    /// The core's inclusive grid radius: every photon within `r0` is inside it.
    grid_radius: u64,
    refine: Option<usize>,
    core: Core,
    stats: Mutex<ExactStats>,
}

impl ExactBackend {
    /// `params` as for `kind`, and m if given (`--refine`).
    pub fn new(
        kind: BackendKind,
        photons: &[Point],
        params: &GatherParams,
        refine: Option<usize>,
        sim: &SimOptions,
    ) -> Result<Self> {
        let max_k = params.core.chosen_controller().max_k();
        check(kind, params.k, refine, max_k)?;
        if let Some(f) = &params.fixed {
            return Err(Error::new(format!(
                "--exact sizes the core's found list to k + m; it does not run on the fixed \
                 core of {} (--core)",
                f.file.display()
            )));
        }
        let k_max = largest_k_prime(kind, params.k, refine, max_k)?;
        let map = QuantizedMap::new(photons, params)?;
        let float = FloatBackend::new(photons, params)?;
        let r0 = match params.radius {
            None => f64::MAX_DIST,
            Some(r) => FloatDist::new(match params.metric {
                Metric::L2 => r * r,
                Metric::L1 => r,
            }),
        };
        let bound = Bound::new(params.metric, &map.quant);
        let max = params.metric.max_dist(map.quant.axis_bits());
        let grid_radius = if params.radius.is_none() {
            max
        } else {
            bound.grid_radius(r0, max)
        };
        let core = if kind.simulates() {
            // The core must be buildable for this map at the largest k′ it may get.
            params
                .core
                .k(k_max)
                .metric(params.metric)
                .traversal(params.traversal)
                .build_for(map.tree.image())?;
            let engine = match kind {
                BackendKind::Verilator => Engine::Verilator,
                _ => sim.engine,
            };
            Core::Hw {
                options: SimOptions {
                    engine,
                    ..sim.clone()
                },
                fit_q: params.core.given_queries_per_port().is_none(),
                stats: Mutex::new(Vec::new()),
            }
        } else {
            if sim.vcd.is_some() {
                return Err(Error::new("--vcd needs --backend native or verilator"));
            }
            Core::Sw
        };
        Ok(ExactBackend {
            kind,
            photons: photons.to_vec(),
            map,
            float,
            bound,
            r0,
            grid_radius,
            refine,
            core,
            stats: Mutex::new(ExactStats::default()),
        })
    }

    /// What the exact gathers so far did.
    pub fn stats(&self) -> ExactStats {
        self.stats.lock().expect("stats lock").clone()
    }

    /// The m of the last gather.
    pub fn last_m(&self) -> usize {
        self.stats().m
    }

    /// Whether the software model's k′ candidates for `q` (grid point `c`) certify
    /// it, and the model's reads: the study's probe of other k′.
    pub fn certify(&self, q: Point, c: [u32; 3], k_prime: usize) -> (bool, u32) {
        let (found, reads) = self.sw_candidates(c, k_prime);
        let ok = matches!(
            self.reranker().verdict(q, c, &found, k_prime),
            Verdict::Exact(_)
        );
        (ok, reads)
    }

    fn reranker(&self) -> Rerank<'_> {
        Rerank {
            photons: &self.photons,
            metric: self.map.params.metric,
            k: self.map.params.k,
            r0: self.r0,
            bound: self.bound,
        }
    }

    /// The software model's candidates for grid query `c` at `k_prime`: (photon
    /// index, grid distance) and the reads.
    fn sw_candidates(&self, c: [u32; 3], k_prime: usize) -> Candidates {
        let m = &self.map;
        let f = knn::search_with(
            &m.tree,
            c,
            k_prime,
            self.grid_radius,
            m.params.metric,
            m.params.traversal,
        );
        let found = f
            .slots
            .iter()
            .map(|&(a, d)| (m.tree.perm[a as usize], d))
            .collect();
        (found, f.visited)
    }

    /// m for these queries: the cheapest on an even sample (module docs).
    fn choose_m(&self, inside: &[(usize, [u32; 3])], queries: &[Point]) -> usize {
        let top = max_refine(
            self.kind,
            self.map.params.k,
            self.map.params.core.chosen_controller().max_k(),
        );
        // 0, 1, 2, 3, 4, 6, 8, 12, 16, 24, ...: steps of about √2.
        let mut ladder: Vec<usize> = (0..usize::BITS)
            .flat_map(|i| [1usize << i, 3usize.saturating_mul(1 << i) / 2])
            .take_while(|&m| m < top)
            .collect();
        ladder.insert(0, 0);
        ladder.push(top);
        ladder.dedup();
        let sample: Vec<(usize, [u32; 3])> = inside
            .iter()
            .step_by(inside.len().div_ceil(SAMPLE).max(1))
            .copied()
            .collect();
        let pts: Vec<Point> = sample.iter().map(|s| queries[s.0]).collect();
        let float_reads: Vec<u64> = match self.float.gather(&pts) {
            Ok(g) => g.iter().map(|g| g.visited as u64).collect(),
            Err(_) => return top,
        };
        let rr = self.reranker();
        let k = self.map.params.k;
        let cost = |m: usize| -> u64 {
            sample
                .par_iter()
                .zip(&pts)
                .zip(&float_reads)
                .map(|((&(_, c), &q), &fr)| {
                    let (found, reads) = self.sw_candidates(c, k + m);
                    match rr.verdict(q, c, &found, k + m) {
                        Verdict::Exact(_) => reads as u64,
                        _ => reads as u64 + fr,
                    }
                })
                .sum()
        };
        let costs: Vec<(u64, usize)> = ladder.iter().map(|&m| (cost(m), m)).collect();
        costs.iter().min().map_or(top, |c| c.1)
    }

    /// `core`'s candidates for `inside` at `k_prime`, in `inside`'s order.
    fn candidates(
        &self,
        core: &Core,
        inside: &[(usize, [u32; 3])],
        k_prime: usize,
    ) -> Result<Vec<Candidates>> {
        match core {
            Core::Sw => Ok(inside
                .par_iter()
                .map(|&(_, c)| self.sw_candidates(c, k_prime))
                .collect()),
            Core::Hw {
                options,
                fit_q,
                stats,
            } => {
                let p = &self.map.params;
                let config = p
                    .core
                    .k(k_prime)
                    .metric(p.metric)
                    .traversal(p.traversal)
                    .build_for(self.map.tree.image())?;
                let hw: Vec<HwQuery> = inside
                    .iter()
                    .enumerate()
                    .map(|(i, &(_, c))| HwQuery {
                        id: i as u32,
                        coords: c,
                        radius: self.grid_radius,
                        k: k_prime as u32,
                    })
                    .collect();
                let mut out = vec![(Vec::new(), 0); inside.len()];
                for r in run_core(&self.map, config, *fit_q, options, &hw, stats)? {
                    let found = r
                        .found
                        .iter()
                        .map(|&(a, d)| (self.map.tree.perm[a as usize], d))
                        .collect();
                    out[r.id as usize] = (found, r.visited);
                }
                Ok(out)
            }
        }
    }
}

impl GatherBackend for ExactBackend {
    fn name(&self) -> &'static str {
        match self.kind {
            BackendKind::Native => "native --exact",
            BackendKind::Verilator => "verilator --exact",
            _ => "sw --exact",
        }
    }

    fn describe(&self) -> Option<String> {
        let core = match &self.core {
            Core::Sw => "candidates: the software model of the core (sw)".to_string(),
            Core::Hw { .. } => format!(
                "candidates: the simulated core ({}), its found list K = k' = {} + m, \
                 its other options as for --backend {}",
                self.kind, self.map.params.k, self.kind
            ),
        };
        Some(format!(
            "{}\n{core}\n{}",
            self.map.describe(),
            self.stats().summary()
        ))
    }

    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        self.gather_on(&self.core, queries)
    }
}

impl ExactBackend {
    /// [`GatherBackend::gather`] with the software model of the core in place of a
    /// simulated one (the same candidates, read for read): the study's series.
    pub fn gather_with_model(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        self.gather_on(&Core::Sw, queries)
    }

    fn gather_on(&self, core: &Core, queries: &[Point]) -> Result<Vec<Gathered>> {
        let mut inside: Vec<(usize, [u32; 3])> = Vec::with_capacity(queries.len());
        let mut fallback: Vec<usize> = Vec::new();
        for (i, &q) in queries.iter().enumerate() {
            // Outside the photon box (even beyond the grid's 2^62 steps) the float
            // search answers, as `--backend float` would.
            match self.map.locate(q) {
                Ok(GridPoint::Inside(c)) => inside.push((i, c)),
                _ => fallback.push(i),
            }
        }
        let outside = fallback.len() as u64;
        let chosen = self.refine.is_none();
        let m = match self.refine {
            Some(m) => m,
            None if inside.is_empty() => 0,
            None => self.choose_m(&inside, queries),
        };
        let k_prime = self.map.params.k + m;
        let cands = self.candidates(core, &inside, k_prime)?;
        let rr = self.reranker();
        let verdicts: Vec<Verdict> = inside
            .par_iter()
            .zip(&cands)
            .map(|(&(i, c), (found, _))| rr.verdict(queries[i], c, found, k_prime))
            .collect();
        let mut out: Vec<Gathered> = vec![Gathered::default(); queries.len()];
        let (mut certified, mut uncertified, mut ties, mut core_reads) = (0u64, 0, 0, 0u64);
        for ((&(i, _), (_, reads)), v) in inside.iter().zip(&cands).zip(verdicts) {
            core_reads += *reads as u64;
            out[i].visited = *reads;
            match v {
                Verdict::Exact(n) => {
                    certified += 1;
                    out[i].neighbours = n;
                }
                Verdict::Uncertified => {
                    uncertified += 1;
                    fallback.push(i);
                }
                Verdict::Tie => {
                    ties += 1;
                    fallback.push(i);
                }
            }
        }
        fallback.sort_unstable();
        let pts: Vec<Point> = fallback.iter().map(|&i| queries[i]).collect();
        let mut host_reads = 0u64;
        for (&i, g) in fallback.iter().zip(self.float.gather(&pts)?) {
            host_reads += g.visited as u64;
            out[i].visited += g.visited;
            out[i].neighbours = g.neighbours;
        }
        let mut s = self.stats.lock().expect("stats lock");
        s.m = m;
        s.chosen = chosen;
        s.queries += queries.len() as u64;
        s.certified += certified;
        s.uncertified += uncertified;
        s.ties += ties;
        s.outside += outside;
        s.core_reads += core_reads;
        s.host_reads += host_reads;
        Ok(out)
    }
}
