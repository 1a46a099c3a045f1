//! `GatherBackend`: every photon gather of the renderer and of `photon-fpga gather`
//! goes through one of these, so the simulated hardware can replace the software
//! search without the caller changing.

use crate::host::device::plan::Device;
use crate::host::error::{Error, Result};
use crate::host::map::kdtree::{KdTree, PackedTree};
use crate::host::map::knn::{self, FloatDist, Scalar};
use crate::host::map::quantize::{GridPoint, Point, Quantizer};
use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::core_config::{CoreConfig, ReadProfile};
use crate::hw::config::memory_config::MAX_MEMORY_ADDRESS_BITS;
use crate::hw::config::metric::Metric;
use crate::hw::config::traversal::Traversal;
use crate::hw::sim::driver::{HwQuery, HwResult, SimStats};
use crate::hw::sim::native::{run_gather, Engine, SimOptions};
use rayon::prelude::*;
use std::fmt;
use std::sync::Mutex;

mod fixed_core;
mod request;
mod sim_backend;
pub use fixed_core::FixedCore;
pub use request::GatherRequest;
pub use sim_backend::{run_core, SimBackend};

/// Which implementation answers the gathers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum BackendKind {
    /// kd-tree search on the unquantized f64 positions (the accuracy baseline).
    Float,
    /// The paper's search on the packed, quantized tree (the hardware's reference).
    #[default]
    Sw,
    /// The photon-search core in rust-hdl's native simulation (`rtl`, its earlier
    /// name, is still accepted).
    #[cfg_attr(feature = "cli", value(alias = "rtl"))]
    Native,
    /// The core's exported Verilog under Verilator (the same results and cycles as
    /// native, much faster).
    Verilator,
}

impl fmt::Display for BackendKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BackendKind::Float => "float",
            BackendKind::Sw => "sw",
            BackendKind::Native => "native",
            BackendKind::Verilator => "verilator",
        })
    }
}

impl BackendKind {
    /// Whether this backend simulates the hardware (and so can dump a waveform).
    pub fn simulates(self) -> bool {
        matches!(self, BackendKind::Native | BackendKind::Verilator)
    }
}

/// Photons a simulated core holds at most: 2^H − 1 for the largest tree height H,
/// the external-memory core's (a map beyond the BlockRAM tree's H goes to the
/// board's memory, `banked_core::for_device_opt`).
pub const HW_CAPACITY: usize = (1 << MAX_MEMORY_ADDRESS_BITS) - 1;
/// Default photon capacity of [`GatherParams`]: what every backend can hold.
pub const DEFAULT_CAPACITY: usize = HW_CAPACITY;

/// What every gather asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct GatherParams {
    /// Photons to gather per query (>= 1).
    pub k: usize,
    /// Upper search radius in world units (inclusive); `None` = unbounded.
    pub radius: Option<f64>,
    /// Coordinate bits on the longest axis (quantized backends).
    pub bits: u32,
    pub metric: Metric,
    /// How the search climbs back up (read counts only; the neighbours are the same).
    pub traversal: Traversal,
    /// Largest photon map accepted.
    pub capacity: usize,
    /// The simulated core's options (native, verilator): controller, Q, trees,
    /// pipelining. Its grid and H follow the map; K, metric and traversal are the
    /// fields above.
    pub core: CoreBuilder,
    /// A core given whole (`--core FILE`): then `core` is unused, every map is
    /// quantized onto this core's layout (by the sw backend too, so that it answers
    /// as the core does) and must fit it, and the metric and traversal are its own.
    pub fixed: Option<FixedCore>,
    /// Plan `core` as the banked barrel core this device holds for each map
    /// (`device::banked_core`).
    pub device: Option<&'static Device>,
}

impl Default for GatherParams {
    fn default() -> Self {
        GatherParams {
            k: 10,
            radius: None,
            bits: 10,
            metric: Metric::L2,
            traversal: Traversal::default(),
            capacity: DEFAULT_CAPACITY,
            core: CoreBuilder::default(),
            fixed: None,
            device: None,
        }
    }
}

impl GatherParams {
    /// Reject parameters no backend can honour.
    pub fn validate(&self, photons: usize) -> Result<()> {
        if self.k == 0 {
            return Err(Error::new("--k must be at least 1, got 0"));
        }
        if let Some(r) = self.radius {
            crate::host::limits::check_non_negative("--radius", r)?;
        }
        if photons == 0 {
            return Err(Error::new("the photon set is empty"));
        }
        if photons > self.capacity {
            return Err(Error::new(format!(
                "{photons} photons exceed {}",
                self.capacity_limit()
            )));
        }
        if let Some(f) = &self.fixed {
            f.check_gather(self.k, self.metric, self.traversal)?;
        }
        Ok(())
    }
}

impl GatherParams {
    /// What bounds the photon count, for a refusal: the fixed core's H, or the
    /// configured capacity.
    pub fn capacity_limit(&self) -> String {
        match &self.fixed {
            Some(f) if f.max_photons() == self.capacity => f.photon_limit(),
            _ => format!("the configured capacity of {}", self.capacity),
        }
    }
}

/// One gathered photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    /// Index of the photon in the caller's photon list.
    pub photon: u32,
    /// Distance in world units in the gather's metric (Euclidean for l2, Manhattan
    /// for l1), measured on the grid for quantized backends.
    pub distance: f64,
}

/// The answer to one query.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Gathered {
    /// Nearest first; ties by photon index.
    pub neighbours: Vec<Neighbour>,
    /// Photons read by the search (0 where a backend does not count).
    pub visited: u32,
}

/// Answers batches of gathers. Results are in query order.
pub trait GatherBackend: Sync {
    fn name(&self) -> &'static str;
    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>>;
    /// A line about the map as this backend holds it (grid, widths, tree height).
    fn describe(&self) -> Option<String> {
        None
    }
    /// Why this backend cannot answer query `q`, if it cannot (checked up front, so
    /// the caller can name the query's file line).
    fn check_query(&self, _q: Point) -> std::result::Result<(), String> {
        Ok(())
    }
}

/// Build the backend `kind` over `photons`. Quantized backends put their grid over
/// the photons alone, so no query changes another's answer; a query outside the
/// photon box is answered exactly by the host (see [`QuantizedMap::search_outside`]).
/// `sim` configures the `native` simulation (waveform dump); other backends refuse a
/// waveform request rather than ignore it.
pub fn make_backend(
    kind: BackendKind,
    photons: &[Point],
    params: &GatherParams,
    sim: &SimOptions,
) -> Result<Box<dyn GatherBackend>> {
    if !kind.simulates() && sim.vcd.is_some() {
        return Err(Error::new("--vcd needs --backend native or verilator"));
    }
    Ok(match kind {
        BackendKind::Float => Box::new(FloatBackend::new(photons, params)?),
        BackendKind::Sw => Box::new(SwBackend::new(photons, params)?),
        BackendKind::Native => Box::new(SimBackend::new(photons, params, sim.clone())?),
        BackendKind::Verilator => {
            let sim = SimOptions {
                engine: Engine::Verilator,
                ..sim.clone()
            };
            Box::new(SimBackend::new(photons, params, sim)?)
        }
    })
}

/// Sort neighbours nearest first, ties by photon index, so every backend that finds
/// the same set reports it identically.
pub fn canonical_order(n: &mut [Neighbour]) {
    n.sort_by(|a, b| {
        a.distance
            .total_cmp(&b.distance)
            .then(a.photon.cmp(&b.photon))
    });
}

/// kd-tree search on the unquantized positions.
pub struct FloatBackend {
    tree: KdTree<f64>,
    params: GatherParams,
}

impl FloatBackend {
    pub fn new(photons: &[Point], params: &GatherParams) -> Result<Self> {
        params.validate(photons.len())?;
        Ok(FloatBackend {
            tree: KdTree::build(photons),
            params: params.clone(),
        })
    }
}

impl GatherBackend for FloatBackend {
    fn name(&self) -> &'static str {
        "float"
    }
    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        let metric = self.params.metric;
        let r0 = match self.params.radius {
            None => f64::MAX_DIST,
            Some(r) => FloatDist::new(match metric {
                Metric::L2 => r * r,
                Metric::L1 => r,
            }),
        };
        Ok(queries
            .par_iter()
            .map(|&q| {
                let f = knn::search_with(
                    &self.tree,
                    q,
                    self.params.k,
                    r0,
                    metric,
                    self.params.traversal,
                );
                let mut neighbours: Vec<Neighbour> = f
                    .slots
                    .iter()
                    .map(|&(addr, d)| Neighbour {
                        photon: self.tree.perm[addr as usize],
                        distance: match metric {
                            Metric::L2 => d.get().sqrt(),
                            Metric::L1 => d.get(),
                        },
                    })
                    .collect();
                canonical_order(&mut neighbours);
                Gathered {
                    neighbours,
                    visited: f.visited,
                }
            })
            .collect())
    }
}

/// The quantized photon map as the hardware sees it: grid, packed tree, and the
/// integer form of the search radius.
pub struct QuantizedMap {
    pub quant: Quantizer,
    pub tree: PackedTree,
    /// Initial radius as an inclusive integer bound in the metric (saturated at the
    /// largest distance inside the photon box, what the core holds).
    pub radius_bound: u64,
    /// The same bound unsaturated, for queries outside the photon box.
    pub radius_wide: u128,
    pub params: GatherParams,
}

impl QuantizedMap {
    /// Quantize over the photons' bounding box. Queries are not part of it: a far
    /// query must not coarsen every other query's grid.
    pub fn new(photons: &[Point], params: &GatherParams) -> Result<Self> {
        params.validate(photons.len())?;
        let quant = match &params.fixed {
            Some(f) => Quantizer::for_layout(photons, f.config.layout)?,
            None => Quantizer::from_points(photons, params.bits)?,
        };
        let tree = PackedTree::build(photons, &quant);
        let max = params.metric.max_dist(quant.axis_bits());
        let (radius_bound, radius_wide) = match params.radius {
            None => (max, u128::MAX),
            Some(r) => (
                params.metric.radius_bound(r, quant.step, max),
                params.metric.radius_bound_wide(r, quant.step),
            ),
        };
        Ok(QuantizedMap {
            quant,
            tree,
            radius_bound,
            radius_wide,
            params: params.clone(),
        })
    }

    /// The distance bits of a core built for this gather: `given`, else the fewest
    /// that answer its radius exactly when it has one ("model only what the scene
    /// needs": the found lists and bounds of a core shrink with the radius), else
    /// the grid's diagonal (`None`).
    pub fn core_radius_bits(&self, given: Option<u32>) -> Option<u32> {
        let full = self.params.metric.dist_bits(self.quant.axis_bits());
        given.or_else(|| {
            self.params.radius?;
            Some(CoreConfig::radius_bits_for(self.radius_bound)).filter(|&b| b < full)
        })
    }

    /// Refuse a gather whose radius the core's distance bits cannot answer exactly
    /// (a radius at or above the saturated distance, or none).
    pub fn check_radius(&self, core: &CoreConfig, fixed: Option<&FixedCore>) -> Result<()> {
        if self.radius_bound <= core.max_radius() {
            return Ok(());
        }
        let whose = fixed.map_or(String::new(), |f| format!(" of {}", f.file.display()));
        let asked = match self.params.radius {
            Some(r) => format!("--radius {r} is {} on this map's grid", self.radius_bound),
            None => "an unbounded gather (no --radius)".to_string(),
        };
        Err(Error::new(format!(
            "{asked}, beyond the core{whose}: {} (a larger --radius-bits, or a smaller \
             --radius)",
            core.radius_limit()
        )))
    }

    /// Where `q` falls on the grid, or why no backend of this map can answer it.
    pub fn locate(&self, q: Point) -> std::result::Result<GridPoint, String> {
        self.quant.grid(q).map_err(|steps| {
            format!(
                "the query at ({:e}, {:e}, {:e}) lies {steps:.3e} grid steps from the photon box \
                 (at most 2^62 ≈ 4.6e18)",
                q[0], q[1], q[2]
            )
        })
    }

    /// The host's exact path for a query outside the photon box: the same search
    /// (`knn::search_with`, same traversal) on the packed tree widened to `i64`
    /// coordinates with `u128` distances. The core's query coordinates are as wide
    /// as the photons' and cannot hold such a query.
    pub fn search_outside(&self, g: [i64; 3]) -> Gathered {
        let f = knn::search_with(
            &knn::WideNodes(&self.tree),
            g,
            self.params.k,
            self.radius_wide,
            self.params.metric,
            self.params.traversal,
        );
        let step = self.quant.step;
        let mut n: Vec<Neighbour> = f
            .slots
            .iter()
            .map(|&(addr, d)| Neighbour {
                photon: self.tree.perm[addr as usize],
                distance: match self.params.metric {
                    Metric::L2 => (d as f64).sqrt() * step,
                    Metric::L1 => d as f64 * step,
                },
            })
            .collect();
        canonical_order(&mut n);
        Gathered {
            neighbours: n,
            visited: f.visited,
        }
    }

    /// Grid step, per-axis widths, word width and tree height.
    pub fn describe(&self) -> String {
        let l = self.quant.layout;
        format!(
            "grid step {:.6} world units; coordinate bits x/y/z {}/{}/{} ({}-bit photon words); \
             tree height {} ({} photons); {} distance bits",
            self.quant.step,
            l.bits[0],
            l.bits[1],
            l.bits[2],
            l.word_bits(),
            self.tree.address_bits(),
            self.tree.len(),
            self.params.metric.dist_bits(l.bits)
        )
    }

    /// Turn (heap address, integer distance) pairs into canonical neighbours.
    pub fn neighbours(&self, slots: &[(u32, u64)]) -> Vec<Neighbour> {
        let mut n: Vec<Neighbour> = slots
            .iter()
            .map(|&(addr, d)| Neighbour {
                photon: self.tree.perm[addr as usize],
                distance: self.params.metric.to_world(d, self.quant.step),
            })
            .collect();
        canonical_order(&mut n);
        n
    }
}

/// The paper's search on the packed tree, in software.
pub struct SwBackend {
    pub map: QuantizedMap,
}

impl SwBackend {
    pub fn new(photons: &[Point], params: &GatherParams) -> Result<Self> {
        Ok(SwBackend {
            map: QuantizedMap::new(photons, params)?,
        })
    }
}

impl GatherBackend for SwBackend {
    fn name(&self) -> &'static str {
        "sw"
    }
    fn describe(&self) -> Option<String> {
        Some(self.map.describe())
    }
    fn check_query(&self, q: Point) -> std::result::Result<(), String> {
        self.map.locate(q).map(|_| ())
    }
    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        let m = &self.map;
        queries
            .par_iter()
            .map(|&q| match m.locate(q).map_err(Error::new)? {
                GridPoint::Inside(c) => {
                    let f = knn::search_with(
                        &m.tree,
                        c,
                        m.params.k,
                        m.radius_bound,
                        m.params.metric,
                        m.params.traversal,
                    );
                    Ok(Gathered {
                        neighbours: m.neighbours(&f.slots),
                        visited: f.visited,
                    })
                }
                GridPoint::Outside(g) => Ok(m.search_outside(g)),
            })
            .collect()
    }
}
