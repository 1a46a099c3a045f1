//! The external-memory core measured on the Cornell box against map size, memory
//! bandwidth, k and query order: the core the ECP5-85k's plan gives
//! (`banked_core::memory_core`, docs/MEMORY_CORE.md) under Verilator with the
//! memory model, every answer checked against the software search, and kiddo
//! timed on the same map and queries in the same run. What `photon-fpga-lab
//! memory-core` writes to docs/memory_core.{csv,md} and its two plots.

use crate::banking::order::{order_queries, StreamOrder};
use crate::banking::stream::read_stream;
use crate::core_run::run_checked;
use crate::cpu_ref;
use crate::workload;
use photon_fpga::host::device::banked_core::memory_core;
use photon_fpga::host::device::plan::ECP5_85K;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::render::RenderSettings;
use photon_fpga::hw::config::config_builder::CoreBuilder;
use photon_fpga::hw::config::core_spec::{CoreBuild, CoreSpec};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::sim::axi_memory::AxiTiming;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{Engine, SimOptions};
use std::time::Duration;

/// Bytes of a query beat and of a result beat on the AXI4-Stream top (its
/// tdata layout, docs/AXIS.md): what the host link carries per query.
pub const QUERY_BEAT_BYTES: u64 = 16;
pub const RESULT_BEAT_BYTES: u64 = 32;

/// One measured point.
#[derive(Clone, Debug, PartialEq)]
pub struct CorePoint {
    pub emitted: usize,
    pub photons: usize,
    pub k: usize,
    pub order: StreamOrder,
    /// The memory's beats: `beat_bytes` each (its data width), one every
    /// `beat_interval` cycles at most.
    pub beat_bytes: u64,
    pub beat_interval: u64,
    /// The cache's lines.
    pub cache_lines: u32,
    pub queries: usize,
    pub reads: u64,
    /// Reads below the on-chip levels (the ones the cache serves).
    pub cached_reads: u64,
    pub cycles: u64,
    pub fills: u64,
    pub beats: u64,
    pub result_beats: u64,
    /// kiddo on the same map and queries: one thread, all threads.
    pub kiddo: f64,
    pub kiddo_all: f64,
    pub threads: usize,
}

impl CorePoint {
    /// The memory's bandwidth: its beats' rate, at most the DRAM's sustained
    /// rate (`AxiTiming::ecp5_ddr3`).
    pub fn bytes_per_cycle(&self) -> f64 {
        (self.beat_bytes as f64 / self.beat_interval as f64)
            .min(AxiTiming::ecp5_ddr3().sustained_bytes)
    }
    pub fn reads_per_cycle(&self) -> f64 {
        self.reads as f64 / self.cycles.max(1) as f64
    }
    pub fn reads_per_query(&self) -> f64 {
        self.reads as f64 / self.queries.max(1) as f64
    }
    /// Cached reads served without a line fill of their own.
    pub fn hit_rate(&self) -> f64 {
        1.0 - self.fills as f64 / self.cached_reads.max(1) as f64
    }
    pub fn dram_bytes_per_query(&self) -> f64 {
        (self.beats * self.beat_bytes) as f64 / self.queries.max(1) as f64
    }
    /// The share of the memory's bandwidth used: bytes taken against the bytes
    /// it could give.
    pub fn channel_busy(&self) -> f64 {
        (self.beats * self.beat_bytes) as f64 / (self.cycles.max(1) as f64 * self.bytes_per_cycle())
    }
    /// Queries/s at `mhz`.
    pub fn queries_per_s(&self, mhz: f64) -> f64 {
        self.queries as f64 / self.cycles.max(1) as f64 * mhz * 1e6
    }
    /// Host-link bytes a query: its query beat and its result packet.
    pub fn link_bytes_per_query(&self) -> f64 {
        QUERY_BEAT_BYTES as f64
            + (self.result_beats * RESULT_BEAT_BYTES) as f64 / self.queries.max(1) as f64
    }
}

/// What one point asks for.
#[derive(Clone, Copy, Debug)]
pub struct PointSpec {
    pub emitted: usize,
    pub k: usize,
    pub order: StreamOrder,
    pub beat_interval: u64,
    /// The image whose eye-ray hits are the queries (square).
    pub side: u32,
    /// The cache's lines, if not the plan's.
    pub cache_lines: Option<u32>,
}

/// The sweep: every map size at both k and both orders, and the memory's
/// bandwidth at the paper's map (1 M emitted), both k, the coherent order.
/// `side32` and `side500`: the images of the k = 32 and k = 500 series.
pub fn specs(
    sizes: &[usize],
    k500_sizes: &[usize],
    paper: usize,
    (side32, side500): (u32, u32),
    cache_lines: Option<u32>,
) -> Vec<PointSpec> {
    let mut v = vec![];
    let series = [(32, sizes, side32), (500, k500_sizes, side500)];
    for (k, sizes, side) in series {
        for &emitted in sizes {
            for order in [StreamOrder::Given, StreamOrder::Morton] {
                v.push(PointSpec {
                    emitted,
                    k,
                    order,
                    beat_interval: 1,
                    side,
                    cache_lines,
                });
            }
        }
    }
    for (k, _, side) in series {
        for beat_interval in [2, 4] {
            v.push(PointSpec {
                emitted: paper,
                k,
                order: StreamOrder::Morton,
                beat_interval,
                side,
                cache_lines,
            });
        }
    }
    v
}

/// Measure one point (`cpu`: time kiddo too).
pub fn measure(p: &PointSpec, seed: u64, cpu: bool) -> Result<CorePoint> {
    let settings = RenderSettings {
        width: p.side,
        height: p.side,
        spp: 1,
        seed,
        ..RenderSettings::default()
    };
    let bits = 10;
    let mut w = workload::cornell_image(p.emitted, usize::MAX, bits, &settings);
    order_queries(&mut w.queries, p.order, bits);
    let map = w.tree.image();
    let cfg = memory_core(
        CoreBuilder::from_spec(&CoreSpec {
            build: CoreBuild {
                k: Some(p.k),
                metric: Some(Metric::L2),
                ..CoreBuild::default()
            },
            ..CoreSpec::default()
        })?,
        map.len(),
        map.layout.word_bits(),
        &ECP5_85K,
    )?;
    let cfg = match p.cache_lines {
        Some(n) => cfg.cache_lines(Some(n)),
        None => cfg,
    }
    .build_for(map)?;
    let on_chip = cfg
        .memory_layout()
        .ok_or_else(|| Error::new("the planned core keeps the map on chip"))?
        .on_chip_levels;
    eprintln!("core: {cfg}");
    let max = cfg.max_dist();
    let queries = HwQuery::within(&cfg, &w.queries, max);
    let opts = SimOptions {
        engine: Engine::Verilator,
        memory: Some(AxiTiming::ecp5_ddr3().with_beat_interval(p.beat_interval)),
        ..SimOptions::default()
    };
    let run = run_checked(&cfg, &w.tree, &queries, max, &opts)?;
    let cached_reads = w
        .queries
        .iter()
        .map(|&q| {
            read_stream(&w.tree, q, cfg.k, cfg.metric, cfg.traversal)
                .iter()
                .filter(|&&a| a >= 1 << on_chip)
                .count() as u64
        })
        .sum();
    let rates = if cpu {
        let r = cpu_ref::measure(
            &w.points,
            &w.tree,
            &w.queries,
            cfg.k,
            cfg.metric,
            max,
            Duration::from_millis(200),
        )
        .map_err(Error::new)?;
        (r.kiddo, r.kiddo_all, r.threads)
    } else {
        (0.0, 0.0, 0)
    };
    Ok(CorePoint {
        emitted: p.emitted,
        photons: w.tree.len(),
        k: p.k,
        order: p.order,
        beat_bytes: cfg.memory.map_or(0, |m| u64::from(m.data_bits / 8)),
        beat_interval: p.beat_interval,
        cache_lines: cfg.memory.map_or(0, |m| m.cache_lines),
        queries: queries.len(),
        reads: run.reads(),
        cached_reads,
        cycles: run.cycles(),
        fills: run.stats.memory.bursts,
        beats: run.stats.memory.beats,
        result_beats: run.stats.result_beats,
        kiddo: rates.0,
        kiddo_all: rates.1,
        threads: rates.2,
    })
}
