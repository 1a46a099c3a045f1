//! The paper's profiling figures (§3, Figs. 3–6) from the project's own runs, on
//! the study's first scene with the paper core's configuration (L1, 10-bit, and
//! k = 10 except where k is the axis): the software search's measured time on one
//! thread and photon reads per query (the core makes the very same reads), and the
//! core's time from those reads at the simulated reads per cycle and REPORT.md's
//! clock.

use crate::study::plan::Plan;
use crate::study::sweep::{self, Eye};
use photon_fpga::host::error::Result;
use photon_fpga::host::gather::GatherParams;
use photon_fpga::host::gather::QuantizedMap;
use photon_fpga::host::map::knn::Scalar;
use photon_fpga::hw::config::core_config::{CoreConfig, MAX_K_MODULES};
use photon_fpga::hw::config::metric::Metric;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::hint::black_box;
use std::time::Instant;

/// One point of Figs. 3–5.
#[derive(Clone, Debug, PartialEq)]
pub struct FigPoint {
    pub x: f64,
    /// Measured: one thread, all of the point's queries (best of three).
    pub seconds: f64,
    pub reads_per_query: f64,
    /// The core: total reads / (simulated reads per cycle × clock), where known.
    pub hw_seconds: Option<f64>,
}

/// One bar pair of Fig. 6 (per query).
#[derive(Clone, Debug, PartialEq)]
pub struct Breakdown {
    pub k: usize,
    /// Software, ns per query: axis distance, distance, photon fetch, max finding
    /// (operation counts of the search × unit costs measured by micro-benchmark).
    pub sw_ns: [f64; 4],
    /// Software, measured ns per query of the whole search (the rest is control).
    pub sw_measured_ns: f64,
    /// Core, QueryModule cycles per query: photon read (port slot), waiting for the
    /// BlockRAM and SearchModule, max finding, climbing (`CoreConfig`'s cycle costs on
    /// the search's counts); `None` above the core's K.
    pub hw_cycles: Option<[f64; 4]>,
}

pub const SW_PARTS: [&str; 4] = ["axis distance", "distance", "photon fetch", "max finding"];
pub const HW_PARTS: [&str; 4] = [
    "photon read",
    "waiting for BlockRAM + SearchModule",
    "max finding",
    "climbing",
];

pub struct Figures {
    pub scene: String,
    pub fig3: Vec<FigPoint>,
    pub fig4: Vec<FigPoint>,
    pub fig5: Vec<FigPoint>,
    pub fig6: Vec<Breakdown>,
}

/// The figures' fixed configuration: the paper core's.
pub const FIG_BITS: u32 = 10;
pub const FIG_METRIC: Metric = Metric::L1;
pub const FIG_K: usize = 10;

/// The figures' gather: the plan's traversal (the core's reads follow it).
fn params(plan: &Plan, k: usize) -> GatherParams {
    GatherParams {
        k,
        bits: FIG_BITS,
        metric: FIG_METRIC,
        traversal: plan.traversal,
        ..GatherParams::default()
    }
}

/// Time and reads of the search of all `queries` of `eye` on `map`.
fn point(x: f64, m: &QuantizedMap, queries: &[[u32; 3]], hw_reads_per_s: Option<f64>) -> FigPoint {
    let seconds = sweep::time_search(m, queries);
    let p = &m.params;
    let reads: u64 = queries
        .iter()
        .map(|&c| {
            photon_fpga::host::map::knn::search_with(
                &m.tree,
                c,
                p.k,
                m.radius_bound,
                p.metric,
                p.traversal,
            )
            .visited as u64
        })
        .sum();
    FigPoint {
        x,
        seconds,
        reads_per_query: reads as f64 / queries.len().max(1) as f64,
        hw_seconds: hw_reads_per_s.map(|r| reads as f64 / r),
    }
}

/// Nanoseconds per call of `f` over `n` calls.
fn ns_per(n: usize, mut f: impl FnMut(usize) -> u64) -> f64 {
    let t = Instant::now();
    let mut acc = 0u64;
    for i in 0..n {
        acc = acc.wrapping_add(f(i));
    }
    black_box(acc);
    t.elapsed().as_secs_f64() * 1e9 / n as f64
}

/// Unit costs (ns) of the search's four parts on this map: one axis distance, one
/// distance, one photon fetch from the packed tree (pseudo-random addresses), one
/// replacement in a full found list of k (the heap the search keeps).
fn unit_costs(m: &QuantizedMap, queries: &[[u32; 3]], k: usize, n: usize) -> [f64; 4] {
    let len = m.tree.len();
    let addr =
        |i: usize| 1 + (photon_fpga::host::render::photons::splitmix64(i as u64) as usize % len);
    let nodes: Vec<([u32; 3], u8)> = (0..4096).map(|i| m.tree.node(addr(i))).collect();
    let metric = m.params.metric;
    let q = |i: usize| queries[i % queries.len()];
    let axis = ns_per(n, |i| {
        let (p, ax) = nodes[i % nodes.len()];
        u32::axis_dist(metric, q(i)[ax as usize], p[ax as usize])
    });
    let dist = ns_per(n, |i| u32::dist(metric, q(i), nodes[i % nodes.len()].0));
    let fetch = ns_per(n, |i| m.tree.node(addr(i)).0[0] as u64);
    let mut heap: BinaryHeap<(u64, Reverse<u32>)> = (0..k as u32)
        .map(|s| {
            (
                photon_fpga::host::render::photons::splitmix64(s as u64) >> 40,
                Reverse(s),
            )
        })
        .collect();
    let max = ns_per(n, |i| {
        let mut top = heap.peek_mut().expect("k >= 1");
        let d = photon_fpga::host::render::photons::splitmix64(i as u64) >> 40;
        top.0 = d.min(top.0);
        drop(top);
        heap.peek().map_or(0, |t| t.0)
    });
    // The address generator's own cost is part of the fetch loop: take it out.
    let gen = ns_per(n, |i| addr(i) as u64);
    [axis, dist, (fetch - gen).max(0.0), max]
}

/// Figs. 3–6 for `plan`'s first scene. `hw_reads_per_s(k)`: the core's reads per
/// second for k (simulated reads per cycle × clock), where the sweep has one.
pub fn run(plan: &Plan, hw_reads_per_s: &dyn Fn(usize) -> Option<f64>) -> Result<Figures> {
    let (name, scene) = &plan.scenes[0];
    let eye: Eye = sweep::eye(scene, plan);
    let base = plan.photons[0];
    let (_, pts) = sweep::photons(scene, base, plan.seed)?;
    let m = QuantizedMap::new(&pts, &params(plan, FIG_K))?;
    let all = sweep::grid_sample(&m, &eye.points, usize::MAX);
    // Fig. 3: time against the number of queries (every f-th query).
    let fig3 = plan
        .fig_query_fractions
        .iter()
        .map(|&f| {
            let q: Vec<[u32; 3]> = all.iter().copied().step_by(f).collect();
            point(q.len() as f64, &m, &q, hw_reads_per_s(FIG_K))
        })
        .collect();
    // Fig. 4: against emitted photons, the same queries.
    let mut fig4 = vec![];
    for &emitted in &plan.fig_photons {
        let (_, p) = sweep::photons(scene, emitted, plan.seed)?;
        let mm = QuantizedMap::new(&p, &params(plan, FIG_K))?;
        let q = sweep::grid_sample(&mm, &eye.points, usize::MAX);
        fig4.push(point(emitted as f64, &mm, &q, hw_reads_per_s(FIG_K)));
    }
    // Figs. 5 and 6: against k.
    let (mut fig5, mut fig6) = (vec![], vec![]);
    let micro = if plan.quick { 20_000 } else { 2_000_000 };
    for &k in &plan.fig_ks {
        let mm = QuantizedMap::new(&pts, &params(plan, k))?;
        let q = sweep::grid_sample(&mm, &eye.points, usize::MAX);
        let fp = point(k as f64, &mm, &q, hw_reads_per_s(k));
        let counts: Vec<[u32; 4]> = sweep::quantized_gather(&mm, &eye.points)?
            .into_iter()
            .map(|x| x.1)
            .collect();
        let n = counts.len().max(1) as f64;
        let per = |i: usize| counts.iter().map(|c| c[i] as f64).sum::<f64>() / n;
        let (reads, tests, max_finds, climbs) = (per(0), per(1), per(2), per(3));
        let unit = unit_costs(&mm, &q, k, micro);
        let sw_ns = [
            unit[0] * reads,
            unit[1] * tests,
            unit[2] * reads,
            unit[3] * max_finds,
        ];
        // (The QueryModule's cost model: its MaxFinder rows stop at K = 64.)
        let hw_cycles = if k <= MAX_K_MODULES {
            let cfg = CoreConfig::for_map(mm.tree.image(), k, FIG_METRIC)?;
            // CoreConfig::mean_read_interval's parts: the read's round trip (one of
            // its cycles is the port slot itself), a MaxFinder run of one cycle per
            // distance bit plus its priming cycle and the update of R, one cycle
            // per level climbed.
            let round_trip = (cfg.issue_interval() - cfg.dist_bits() as usize - 1) as f64;
            Some([
                reads,
                (round_trip - 1.0) * reads,
                max_finds * (cfg.dist_bits() + 2) as f64,
                climbs,
            ])
        } else {
            None
        };
        fig6.push(Breakdown {
            k,
            sw_ns,
            sw_measured_ns: fp.seconds * 1e9 / q.len().max(1) as f64,
            hw_cycles,
        });
        fig5.push(fp);
    }
    Ok(Figures {
        scene: name.clone(),
        fig3,
        fig4,
        fig5,
        fig6,
    })
}
