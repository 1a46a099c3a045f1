//! The `native` and `verilator` backends: every gather through a simulation of the
//! photon-search core built for the map (or planned for `--device`, or the fixed
//! core of `--core FILE`).

use super::*;
use crate::host::device::banked_core;

/// The gathers run through a simulation of the photon-search core (rust-hdl's
/// native one for `rtl`, the exported Verilog under Verilator for `verilator`),
/// with the options of `GatherParams::core` built for this map ("model only what
/// the scene needs": `CoreBuilder::build_for`).
pub struct SimBackend {
    pub map: QuantizedMap,
    pub config: CoreConfig,
    /// Q was not given: it is sized from each batch of queries
    /// (`CoreConfig::fit_queries_per_port`).
    pub fit_q: bool,
    pub options: SimOptions,
    /// Cycle and read counts of the gathers so far, summed over simulations.
    pub stats: Mutex<Vec<SimStats>>,
}

impl SimBackend {
    pub fn new(photons: &[Point], params: &GatherParams, options: SimOptions) -> Result<Self> {
        let map = QuantizedMap::new(photons, params)?;
        let config = match &params.fixed {
            // One core for every map: the map is checked against it, never the
            // core fitted to the map (so one exported Verilog, one model).
            Some(f) => f.check_map(map.tree.image())?,
            None => banked_core::for_device_opt(
                params.core,
                map.tree.image().len(),
                map.tree.layout.word_bits(),
                params.device,
            )?
            .k(params.k)
            .metric(params.metric)
            .traversal(params.traversal)
            .radius_bits(map.core_radius_bits(params.core.given_radius_bits()))
            .build_for(map.tree.image())?,
        };
        map.check_radius(&config, params.fixed.as_ref())?;
        Ok(SimBackend {
            map,
            config,
            fit_q: params.fixed.is_none() && params.core.given_queries_per_port().is_none(),
            options,
            stats: Mutex::new(Vec::new()),
        })
    }
}

impl GatherBackend for SimBackend {
    fn name(&self) -> &'static str {
        match self.options.engine {
            Engine::Native => "rtl",
            Engine::Verilator => "verilator",
        }
    }

    fn describe(&self) -> Option<String> {
        let fitted = if self.fit_q {
            format!(
                " (Q fitted to the queries, at most {})",
                self.config.queries_per_port
            )
        } else {
            String::new()
        };
        Some(format!(
            "{}\ncore: {}{fitted}",
            self.map.describe(),
            self.config
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
        if options.vcd.is_some() || std::env::var_os(crate::hw::sim::native::VCD_ENV).is_some() {
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
