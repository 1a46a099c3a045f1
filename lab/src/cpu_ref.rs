//! The CPU baselines the hardware is measured against, timed on the very points,
//! queries and k it gets: kiddo's `ImmutableKdTree` (the current release, f32, one
//! thread) and our own software search (`knn::search_with`, one thread).
//!
//! Timing belongs in benchmarks and subcommands (`photon-fpga-lab bench-core`, `cargo
//! bench`), never in tests; this module only measures when asked to.

use kiddo::{ImmutableKdTree, Manhattan, SquaredEuclidean};
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::{self, Traversal};
use photon_fpga::hw::config::metric::Metric;
use std::hint::black_box;
use std::num::NonZero;
use std::time::{Duration, Instant};

/// Queries per second of both CPU searches on one workload, single thread, and of
/// kiddo on all threads.
#[derive(Clone, Copy, Debug)]
pub struct CpuRates {
    /// kiddo `ImmutableKdTree<f32, 3>`, `nearest_n` in the same metric.
    pub kiddo: f64,
    /// `knn::search_with` on the packed, quantized tree (the hardware's reference).
    pub sw: f64,
    /// kiddo on every thread of rayon's pool (the queries split between them).
    pub kiddo_all: f64,
    pub threads: usize,
}

/// Timing rounds per search (see [`measure`]).
const ROUNDS: usize = 5;

/// Repeat `f` over all queries until at least `min` has passed; queries per second.
fn rate(queries: usize, min: Duration, mut f: impl FnMut()) -> f64 {
    let t0 = Instant::now();
    let mut runs = 0u64;
    while runs == 0 || t0.elapsed() < min {
        f();
        runs += 1;
    }
    (runs * queries as u64) as f64 / t0.elapsed().as_secs_f64()
}

/// kiddo's k nearest distances of `q` within `radius` (inclusive; `None`:
/// unbounded), nearest first (f32: exact for integer coordinates while every
/// distance stays below 2^24).
fn kiddo_dists(
    tree: &ImmutableKdTree<f32, 3>,
    q: &[f32; 3],
    k: NonZero<usize>,
    m: Metric,
    radius: Option<f32>,
) -> Vec<f32> {
    let found = match (m, radius) {
        (Metric::L2, None) => tree
            .query(q)
            .nearest_n::<SquaredEuclidean<f32>>(k)
            .execute(),
        (Metric::L2, Some(r)) => tree
            .query(q)
            .nearest_n::<SquaredEuclidean<f32>>(k)
            .within(r)
            .execute(),
        (Metric::L1, None) => tree.query(q).nearest_n::<Manhattan<f32>>(k).execute(),
        (Metric::L1, Some(r)) => tree
            .query(q)
            .nearest_n::<Manhattan<f32>>(k)
            .within(r)
            .execute(),
    };
    found.into_iter().map(|n| n.distance).collect()
}

/// Time kiddo and the software search on `points` (the grid coordinates `tree` was
/// built from) for k-NN `queries` within the inclusive bound `radius` (unbounded at
/// the grid's diagonal): the best of five interleaved rounds of at least `min` each. Where f32 is
/// exact (every distance < 2^24), kiddo's distances are first checked against the
/// software search's, so both are known to do the same job.
pub fn measure(
    points: &[[u32; 3]],
    tree: &PackedTree,
    queries: &[[u32; 3]],
    k: usize,
    metric: Metric,
    radius: u64,
    min: Duration,
) -> Result<CpuRates, String> {
    // kiddo's bound: none at the grid's diagonal (every photon is within it).
    let kiddo_radius = (radius < metric.max_dist(tree.layout.bits)).then_some(radius as f32);
    let fpoints: Vec<[f32; 3]> = points.iter().map(|p| p.map(|c| c as f32)).collect();
    let kd = ImmutableKdTree::<f32, 3>::new_from_slice(&fpoints)
        .map_err(|e| format!("kiddo: cannot build the tree: {e:?}"))?;
    let fq: Vec<[f32; 3]> = queries.iter().map(|q| q.map(|c| c as f32)).collect();
    let nz = NonZero::new(k).ok_or("k must be at least 1")?;
    if metric.max_dist(tree.layout.bits) < 1 << 24 {
        for (q, f) in queries.iter().zip(&fq).take(200) {
            let sw = knn::search(tree, *q, k, radius, metric).sorted_dists();
            let kd: Vec<u64> = kiddo_dists(&kd, f, nz, metric, kiddo_radius)
                .into_iter()
                .map(|d| d as u64)
                .collect();
            if sw != kd {
                return Err(format!(
                    "kiddo and the software search disagree at query {q:?}: {kd:?} vs {sw:?}"
                ));
            }
        }
    }
    // Interleaved rounds, best of each: another process on the machine slows a round
    // down, never speeds it up, so the best round is the least disturbed one.
    let (mut kiddo, mut sw, mut kiddo_all) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..ROUNDS {
        kiddo_all = kiddo_all.max(rate(queries.len(), min, || {
            use rayon::prelude::*;
            fq.par_iter().for_each(|q| {
                black_box(kiddo_dists(&kd, q, nz, metric, kiddo_radius));
            });
        }));
        kiddo = kiddo.max(rate(queries.len(), min, || {
            for q in &fq {
                black_box(kiddo_dists(&kd, q, nz, metric, kiddo_radius));
            }
        }));
        sw = sw.max(rate(queries.len(), min, || {
            for &q in queries {
                black_box(knn::search_with(
                    tree,
                    q,
                    k,
                    radius,
                    metric,
                    Traversal::default(),
                ));
            }
        }));
    }
    Ok(CpuRates {
        kiddo,
        sw,
        kiddo_all,
        threads: rayon::current_num_threads(),
    })
}
