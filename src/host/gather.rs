//! `GatherBackend`: every photon gather of the renderer and of `photon-fpga gather`
//! goes through one of these, so the simulated hardware can replace the software
//! search without the caller changing.

use super::error::{Error, Result};
use super::kdtree::{KdTree, PackedTree};
use super::knn::{self, Coord, FloatDist};
use super::quantize::{Point, Quantizer};
use crate::hw::config::CoreConfig;
use crate::hw::metric::Metric;
use crate::hw::sim::{run_gather, HwQuery, SimOptions, SimStats};
use crate::hw::traversal::Traversal;
use rayon::prelude::*;
use std::fmt;
use std::str::FromStr;
use std::sync::Mutex;

/// Which implementation answers the gathers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BackendKind {
    /// kd-tree search on the unquantized f64 positions (the accuracy baseline).
    Float,
    /// The paper's search on the packed, quantized tree (the hardware's reference).
    #[default]
    Sw,
    /// The rust-hdl simulation of the photon-search core.
    Rtl,
}

impl FromStr for BackendKind {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "float" => Ok(BackendKind::Float),
            "sw" => Ok(BackendKind::Sw),
            "rtl" => Ok(BackendKind::Rtl),
            _ => Err(format!("unknown backend '{s}' (expected float, sw or rtl)")),
        }
    }
}

impl fmt::Display for BackendKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BackendKind::Float => "float",
            BackendKind::Sw => "sw",
            BackendKind::Rtl => "rtl",
        })
    }
}

/// Default photon capacity: 2^20 − 1 photons, a 20-bit tree address.
pub const DEFAULT_CAPACITY: usize = (1 << 20) - 1;

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
                "{photons} photons exceed the configured capacity of {}",
                self.capacity
            )));
        }
        Ok(())
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
}

/// Build the backend `kind` over `photons`. Quantized backends put their grid over
/// the photons and `queries` (empty: the photons alone).
/// `sim` configures the `rtl` simulation (waveform dump); other backends refuse a
/// waveform request rather than ignore it.
pub fn make_backend(
    kind: BackendKind,
    photons: &[Point],
    queries: &[Point],
    params: &GatherParams,
    sim: &SimOptions,
) -> Result<Box<dyn GatherBackend>> {
    if kind != BackendKind::Rtl && sim.vcd.is_some() {
        return Err(Error::new("--vcd needs --backend rtl"));
    }
    Ok(match kind {
        BackendKind::Float => Box::new(FloatBackend::new(photons, params)?),
        BackendKind::Sw => Box::new(SwBackend::covering(photons, queries, params)?),
        BackendKind::Rtl => Box::new(RtlBackend::covering(photons, queries, params, sim.clone())?),
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
    /// Initial radius as an inclusive integer bound in the metric.
    pub radius_bound: u64,
    pub params: GatherParams,
}

impl QuantizedMap {
    /// Quantize over the photons' bounding box (queries outside it are clamped
    /// onto the grid).
    pub fn new(photons: &[Point], params: &GatherParams) -> Result<Self> {
        Self::covering(photons, &[], params)
    }

    /// Quantize over the bounding box of the photons and `extra` points (the
    /// queries, when they are known up front), so no query is clamped.
    pub fn covering(photons: &[Point], extra: &[Point], params: &GatherParams) -> Result<Self> {
        params.validate(photons.len())?;
        let quant = if extra.is_empty() {
            Quantizer::from_points(photons, params.bits)?
        } else {
            let all: Vec<Point> = photons.iter().chain(extra).copied().collect();
            Quantizer::from_points(&all, params.bits)?
        };
        let tree = PackedTree::build(photons, &quant);
        let max = params.metric.max_dist(quant.axis_bits());
        let radius_bound = match params.radius {
            None => max,
            Some(r) => params.metric.radius_bound(r, quant.step, max),
        };
        Ok(QuantizedMap {
            quant,
            tree,
            radius_bound,
            params: params.clone(),
        })
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

    /// A backend whose grid also covers `queries` (see [`QuantizedMap::covering`]).
    pub fn covering(photons: &[Point], queries: &[Point], params: &GatherParams) -> Result<Self> {
        Ok(SwBackend {
            map: QuantizedMap::covering(photons, queries, params)?,
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
    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        let m = &self.map;
        Ok(queries
            .par_iter()
            .map(|&q| {
                let f = knn::search_with(
                    &m.tree,
                    m.quant.quantize(q),
                    m.params.k,
                    m.radius_bound,
                    m.params.metric,
                    m.params.traversal,
                );
                Gathered {
                    neighbours: m.neighbours(&f.slots),
                    visited: f.visited,
                }
            })
            .collect())
    }
}

/// The gathers run through the rust-hdl simulation of the photon-search core,
/// configured for this map ("model only what the scene needs": `CoreConfig::for_map`).
pub struct RtlBackend {
    pub map: QuantizedMap,
    pub config: CoreConfig,
    pub options: SimOptions,
    /// Cycle and read counts of the gathers so far, summed over simulations.
    pub stats: Mutex<Vec<SimStats>>,
}

impl RtlBackend {
    pub fn covering(
        photons: &[Point],
        queries: &[Point],
        params: &GatherParams,
        options: SimOptions,
    ) -> Result<Self> {
        let map = QuantizedMap::covering(photons, queries, params)?;
        let mut config = CoreConfig::for_map(&map.tree, params.k, params.metric)?;
        config.traversal = params.traversal;
        Ok(RtlBackend {
            map,
            config,
            options,
            stats: Mutex::new(Vec::new()),
        })
    }
}

impl GatherBackend for RtlBackend {
    fn name(&self) -> &'static str {
        "rtl"
    }

    fn describe(&self) -> Option<String> {
        let c = &self.config;
        Some(format!(
            "{}\ncore: H = {}, K = {}, {} x {} QueryModules, {} metric, {}-bit distances, {} traversal",
            self.map.describe(),
            c.address_bits,
            c.k,
            crate::hw::config::PORTS,
            c.queries_per_port,
            c.metric,
            c.dist_bits(),
            c.traversal
        ))
    }

    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        let m = &self.map;
        let hw: Vec<HwQuery> = queries
            .iter()
            .enumerate()
            .map(|(i, &q)| HwQuery {
                id: i as u32,
                coords: m.quant.quantize(q),
                radius: m.radius_bound,
                k: m.params.k as u32,
            })
            .collect();
        // Each query's answer depends only on the map and the query, not on which
        // QueryModule or simulation serves it, so independent simulations of the
        // core on chunks of the stream give the same results for any thread count.
        // A waveform dump wants one simulation.
        let chunks =
            if self.options.vcd.is_some() || std::env::var_os(crate::hw::sim::VCD_ENV).is_some() {
                1
            } else {
                rayon::current_num_threads().max(1)
            };
        let size = hw.len().div_ceil(chunks).max(1);
        let runs: Vec<_> = hw
            .par_chunks(size)
            .map(|chunk| run_gather(&self.config, &m.tree, chunk, &self.options))
            .collect::<Result<_>>()?;
        let mut out = Vec::with_capacity(queries.len());
        let mut stats = self.stats.lock().expect("stats lock");
        for (results, s) in runs {
            stats.push(s);
            out.extend(results.into_iter().map(|r| Gathered {
                neighbours: m.neighbours(&r.found),
                visited: r.visited,
            }));
        }
        Ok(out)
    }
}
