//! `GatherBackend`: every photon gather of the renderer and of `photon-fpga gather`
//! goes through one of these, so the simulated hardware can replace the software
//! search without the caller changing.

use crate::host::banking::device_core;
use crate::host::banking::plan::Device;
use crate::host::error::{Error, Result};
use crate::host::map::kdtree::{KdTree, PackedTree};
use crate::host::map::knn::{self, FloatDist, Scalar};
use crate::host::map::quantize::{GridPoint, Point, Quantizer};
use crate::hw::config::{CoreConfig, ReadProfile, MAX_ADDRESS_BITS};
use crate::hw::config_builder::CoreBuilder;
use crate::hw::metric::Metric;
use crate::hw::rtl::driver::{HwQuery, HwResult, SimStats};
use crate::hw::rtl::native::{run_gather, Engine, SimOptions};
use crate::hw::traversal::Traversal;
use rayon::prelude::*;
use std::fmt;
use std::sync::Mutex;

mod fixed_core;
pub use fixed_core::FixedCore;

/// Which implementation answers the gathers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum BackendKind {
    /// kd-tree search on the unquantized f64 positions (the accuracy baseline).
    Float,
    /// The paper's search on the packed, quantized tree (the hardware's reference).
    #[default]
    Sw,
    /// The photon-search core in rust-hdl's own simulation.
    Rtl,
    /// The core's exported Verilog under Verilator (the same results and cycles as
    /// rtl, much faster).
    Verilator,
}

impl fmt::Display for BackendKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BackendKind::Float => "float",
            BackendKind::Sw => "sw",
            BackendKind::Rtl => "rtl",
            BackendKind::Verilator => "verilator",
        })
    }
}

impl BackendKind {
    /// Whether this backend simulates the hardware (and so can dump a waveform).
    pub fn simulates(self) -> bool {
        matches!(self, BackendKind::Rtl | BackendKind::Verilator)
    }
}

/// Photons a simulated core holds at most: 2^H − 1 for the largest tree height H.
pub const HW_CAPACITY: usize = (1 << MAX_ADDRESS_BITS) - 1;
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
    /// The simulated core's options (rtl, verilator): controller, Q, trees,
    /// pipelining. Its grid and H follow the map; K, metric and traversal are the
    /// fields above.
    pub core: CoreBuilder,
    /// A core given whole (`--core FILE`): then `core` is unused, every map is
    /// quantized onto this core's layout (by the sw backend too, so that it answers
    /// as the core does) and must fit it, and the metric and traversal are its own.
    pub fixed: Option<FixedCore>,
    /// Plan `core` as the banked barrel core this device holds for each map
    /// (`banking::device_core`).
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
            if r.is_nan() || r < 0.0 || r.is_infinite() {
                return Err(Error::new(format!(
                    "--radius must be a finite number >= 0, got {r}"
                )));
            }
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
/// `sim` configures the `rtl` simulation (waveform dump); other backends refuse a
/// waveform request rather than ignore it.
pub fn make_backend(
    kind: BackendKind,
    photons: &[Point],
    params: &GatherParams,
    sim: &SimOptions,
) -> Result<Box<dyn GatherBackend>> {
    if !kind.simulates() && sim.vcd.is_some() {
        return Err(Error::new("--vcd needs --backend rtl or verilator"));
    }
    Ok(match kind {
        BackendKind::Float => Box::new(FloatBackend::new(photons, params)?),
        BackendKind::Sw => Box::new(SwBackend::new(photons, params)?),
        BackendKind::Rtl => Box::new(RtlBackend::new(photons, params, sim.clone())?),
        BackendKind::Verilator => {
            let sim = SimOptions {
                engine: Engine::Verilator,
                ..sim.clone()
            };
            Box::new(RtlBackend::new(photons, params, sim)?)
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

/// The gathers run through a simulation of the photon-search core (rust-hdl's
/// native one for `rtl`, the exported Verilog under Verilator for `verilator`),
/// with the options of `GatherParams::core` built for this map ("model only what
/// the scene needs": `CoreBuilder::build_for`).
pub struct RtlBackend {
    pub map: QuantizedMap,
    pub config: CoreConfig,
    /// Q was not given: it is sized from each batch of queries
    /// (`CoreConfig::fit_queries_per_port`).
    pub fit_q: bool,
    pub options: SimOptions,
    /// Cycle and read counts of the gathers so far, summed over simulations.
    pub stats: Mutex<Vec<SimStats>>,
}

impl RtlBackend {
    pub fn new(photons: &[Point], params: &GatherParams, options: SimOptions) -> Result<Self> {
        let map = QuantizedMap::new(photons, params)?;
        let config = match &params.fixed {
            // One core for every map: the map is checked against it, never the
            // core fitted to the map (so one exported Verilog, one model).
            Some(f) => f.check_map(map.tree.image())?,
            None => device_core::for_device_opt(
                params.core,
                map.tree.image().len(),
                map.tree.layout.word_bits(),
                params.device,
            )?
            .k(params.k)
            .metric(params.metric)
            .traversal(params.traversal)
            .build_for(map.tree.image())?,
        };
        Ok(RtlBackend {
            map,
            config,
            fit_q: params.fixed.is_none() && params.core.given_queries_per_port().is_none(),
            options,
            stats: Mutex::new(Vec::new()),
        })
    }
}

impl GatherBackend for RtlBackend {
    fn name(&self) -> &'static str {
        match self.options.engine {
            Engine::Native => "rtl",
            Engine::Verilator => "verilator",
        }
    }

    fn describe(&self) -> Option<String> {
        let c = &self.config;
        let q = match c.controller {
            crate::hw::controller::Controller::Modules => "QueryModules",
            crate::hw::controller::Controller::Barrel => "query slots",
        };
        let fitted = if self.fit_q {
            format!("Q fitted to the queries, at most {}", c.queries_per_port)
        } else {
            format!("Q = {}", c.queries_per_port)
        };
        Some(format!(
            "{}\ncore: {} controller, T = {} tree(s), H = {}, K = {}, {} x Q {q} ({fitted}), {} metric, {}-bit distances, {} traversal",
            self.map.describe(),
            c.controller,
            c.trees,
            c.address_bits,
            c.k,
            crate::hw::config::PORTS,
            c.metric,
            c.dist_bits(),
            c.traversal
        ))
    }

    fn check_query(&self, q: Point) -> std::result::Result<(), String> {
        self.map.locate(q).map(|_| ())
    }

    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        let m = &self.map;
        // Queries inside the photon box go to the core; the others take the host's
        // exact path (the core's query coordinates are as wide as the photons').
        let mut hw: Vec<HwQuery> = Vec::with_capacity(queries.len());
        let mut outside: Vec<(usize, [i64; 3])> = Vec::new();
        for (i, &q) in queries.iter().enumerate() {
            match m.locate(q).map_err(Error::new)? {
                GridPoint::Inside(c) => hw.push(HwQuery {
                    id: i as u32,
                    coords: c,
                    radius: m.radius_bound,
                    k: m.params.k as u32,
                }),
                GridPoint::Outside(g) => outside.push((i, g)),
            }
        }
        let mut out: Vec<Gathered> = vec![Gathered::default(); queries.len()];
        for r in run_core(m, self.config, self.fit_q, &self.options, &hw, &self.stats)? {
            out[r.id as usize] = Gathered {
                neighbours: m.neighbours(&r.found),
                visited: r.visited,
            };
        }
        let far: Vec<(usize, Gathered)> = outside
            .par_iter()
            .map(|&(i, g)| (i, m.search_outside(g)))
            .collect();
        for (i, g) in far {
            out[i] = g;
        }
        Ok(out)
    }
}

/// Run `hw` through simulations of the core `config` on `map`'s tree (Q sized from
/// the queries first if `fit_q`), their cycle counts appended to `stats`; the
/// results in no particular order (each names its query by `id`).
pub fn run_core(
    map: &QuantizedMap,
    mut config: CoreConfig,
    fit_q: bool,
    options: &SimOptions,
    hw: &[HwQuery],
    stats: &Mutex<Vec<SimStats>>,
) -> Result<Vec<HwResult>> {
    // Right-sized Q, unless one was given: from what the software search costs on an even
    // sample of these queries, instead of the worst-case issue interval.
    if fit_q {
        let profile: ReadProfile = hw
            .iter()
            .step_by(hw.len().div_ceil(512).max(1))
            .map(|q| {
                let c = &config;
                knn::search_with(
                    &map.tree,
                    q.coords,
                    q.k as usize,
                    q.radius,
                    c.metric,
                    c.traversal,
                )
                .read_profile()
            })
            .sum();
        config.fit_queries_per_port(&profile);
    }
    // Each query's answer depends only on the map and the query, not on which
    // QueryModule or simulation serves it, so independent simulations of the
    // core on chunks of the stream give the same results for any thread count.
    // A waveform dump wants one simulation.
    let chunks =
        if options.vcd.is_some() || std::env::var_os(crate::hw::rtl::native::VCD_ENV).is_some() {
            1
        } else {
            rayon::current_num_threads().max(1)
        };
    let size = hw.len().div_ceil(chunks).max(1);
    let runs: Vec<_> = hw
        .par_chunks(size)
        .map(|chunk| Ok(run_gather(&config, map.tree.image(), chunk, options)?))
        .collect::<Result<_>>()?;
    let mut stats = stats.lock().expect("stats lock");
    let mut out = Vec::with_capacity(hw.len());
    for (results, s) in runs {
        stats.push(s);
        out.extend(results);
    }
    Ok(out)
}
