//! The one simulation driver: it plays the host's side of the core's load / query /
//! result streams cycle by cycle against any simulated core (a [`Dut`]: rust-hdl's
//! native simulation, or the exported Verilog under Verilator), checks the result protocol, and reports every cycle to
//! its [`Observer`]s (cycle and read statistics, a VCD trace, the cross-simulation's
//! recorder). The `rtl` and `verilator` gather backends, the lab's `bench-core`,
//! the testbenches and the cross-simulation all run through it.
//!
//! A run is a list of [`Job`]s, each an optional map load followed by queries. The
//! host presents the next job's load as soon as the previous job's queries are all
//! accepted, so the core must hold a load back until its searches are done. With a
//! stall seed every valid and every ready of the host is randomly withheld (35 % of
//! the cycles), so every handshake is exercised.

use crate::hw::config::core_config::{CoreConfig, MAX_RESULT_STREAMS};
use crate::hw::config::photon_word::TreeImage;
use crate::hw::error::HwError;
use crate::hw::primitives::stream::{QueryBeat, ResultBeat};
pub use crate::hw::sim::dut::{Cycle, Dut, Inputs, LoadBeat, Observer, Outputs};
use crate::hw::sim::entry_distances::HeldMap;
pub use crate::hw::sim::sim_stats::SimStats;
use crate::hw::sim::sim_stats::StatsObserver;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// One query for the core: grid coordinates, inclusive integer radius bound in the
/// metric, and k (1..=K).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HwQuery {
    pub id: u32,
    pub coords: [u32; 3],
    pub radius: u64,
    pub k: u32,
}

impl HwQuery {
    /// Each of `points` as a query for `cfg`'s K nearest photons with no radius
    /// bound (the largest distance of `cfg`'s grid), numbered in order.
    pub fn k_nearest(cfg: &CoreConfig, points: &[[u32; 3]]) -> Vec<HwQuery> {
        Self::within(cfg, points, cfg.max_dist())
    }

    /// The `cfg.k` nearest photons of each point within the inclusive bound
    /// `radius` on the grid, ids 0, 1, ...
    pub fn within(cfg: &CoreConfig, points: &[[u32; 3]], radius: u64) -> Vec<HwQuery> {
        points
            .iter()
            .enumerate()
            .map(|(i, &coords)| HwQuery {
                id: i as u32,
                coords,
                radius,
                k: cfg.k as u32,
            })
            .collect()
    }
}

/// One query's answer: (heap address, distance) in found-list slot order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HwResult {
    pub id: u32,
    pub found: Vec<(u32 /*heap addr*/, u64 /*distance*/)>,
    /// Photon reads this query issued.
    pub visited: u32,
}

/// One step of a run: load a map (if any), then run queries on the loaded map.
#[derive(Clone, Copy, Debug)]
pub struct Job<'a> {
    pub load: Option<TreeImage<'a>>,
    pub queries: &'a [HwQuery],
}

/// Synchronous reset cycles when the driver starts.
pub const RESET_CYCLES: u64 = 2;

/// How long a run may go on.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunLimits {
    /// Stop after this many cycles even if results are outstanding.
    pub max_cycles: Option<u64>,
    /// Idle cycles (result ready high) after the last result.
    pub tail_cycles: u64,
}

/// The host side of the streams, driving one [`Dut`].
pub struct Driver<D: Dut> {
    dut: D,
    stalls: Option<Pcg64>,
    inputs: Inputs,
    cycle: u64,
    stats: StatsObserver,
    observers: Vec<Box<dyn Observer>>,
    /// The map the core holds (the last one loaded), kept where result entries
    /// come without distances (`CoreConfig::sends_distances`): the driver computes
    /// them from it.
    map: HeldMap,
}

/// Where the host is within a run.
struct Host {
    job: usize,
    loading: bool,
    load_next: usize,
    load_presenting: bool,
    query_next: usize,
    /// The tag of the query being presented, while it is.
    query_tag: Option<usize>,
    /// Tag -> (job, query index) while the query is in flight (accepted, its last
    /// result beat not yet received). The core keeps `CoreConfig::id_bits` of the
    /// id, so tags come from a pool of that size, reused in FIFO order.
    tags: Vec<Option<(usize, usize)>>,
    free_tags: std::collections::VecDeque<usize>,
    /// Per result stream, the result in progress: (tag, count).
    current: Vec<Option<(usize, usize)>>,
    received: usize,
    /// With external memory: the memory holds the job's map (reset and written
    /// once the previous jobs' results are all in).
    memory_ready: bool,
}

fn protocol(msg: impl Into<String>) -> HwError {
    HwError::Simulation(msg.into())
}

impl<D: Dut> Driver<D> {
    /// Start driving `dut`: [`RESET_CYCLES`] reset cycles, seen by `observers`.
    pub fn new(
        dut: D,
        stall_seed: Option<u64>,
        observers: Vec<Box<dyn Observer>>,
    ) -> Result<Self, HwError> {
        let mut d = Driver {
            dut,
            stalls: stall_seed.map(Pcg64::seed_from_u64),
            inputs: Inputs::default(),
            cycle: 0,
            stats: StatsObserver::default(),
            observers,
            map: HeldMap::default(),
        };
        d.reset()?;
        Ok(d)
    }

    pub fn config(&self) -> &CoreConfig {
        self.dut.config()
    }

    /// The simulated core.
    pub fn dut(&self) -> &D {
        &self.dut
    }

    /// Counters since the core was built.
    pub fn stats(&self) -> &SimStats {
        &self.stats.stats
    }

    /// The observers, e.g. to take a recording out.
    pub fn into_observers(self) -> Vec<Box<dyn Observer>> {
        self.observers
    }

    /// Synchronous reset for [`RESET_CYCLES`] cycles.
    pub fn reset(&mut self) -> Result<(), HwError> {
        let before = self.inputs;
        self.inputs = Inputs {
            reset: true,
            ..Inputs::default()
        };
        for _ in 0..RESET_CYCLES {
            self.step()?;
        }
        self.inputs = Inputs {
            reset: false,
            ..before
        };
        self.inputs.load_valid = false;
        self.inputs.query_valid = false;
        self.inputs.result_ready = [false; MAX_RESULT_STREAMS];
        Ok(())
    }

    /// One cycle with the current inputs; returns the outputs it sampled.
    fn step(&mut self) -> Result<Outputs, HwError> {
        self.dut.drive(&self.inputs)?;
        let outputs = self.dut.outputs();
        let cycle = Cycle {
            index: self.cycle,
            dut: &self.dut,
            inputs: &self.inputs,
            outputs: &outputs,
        };
        self.stats.sampled(&cycle)?;
        for o in &mut self.observers {
            o.sampled(&cycle)?;
        }
        self.dut.rising_edge()?;
        let cycle = Cycle {
            index: self.cycle,
            dut: &self.dut,
            inputs: &self.inputs,
            outputs: &outputs,
        };
        for o in &mut self.observers {
            o.edge(&cycle)?;
        }
        self.cycle += 1;
        Ok(outputs)
    }

    /// A random stall decision (never stalls without a seed).
    fn stall(&mut self) -> bool {
        match &mut self.stalls {
            Some(rng) => rng.gen_bool(0.35),
            None => false,
        }
    }

    fn check_jobs(&self, jobs: &[Job<'_>]) -> Result<(), HwError> {
        let cfg = self.config();
        for job in jobs {
            if let Some(tree) = job.load {
                cfg.check_map(tree)?;
            }
            for q in job.queries {
                if q.k == 0 || q.k as usize > cfg.k {
                    return Err(protocol(format!(
                        "query {}: k = {} outside 1..={} (the core's K)",
                        q.id, q.k, cfg.k
                    )));
                }
                if q.radius > cfg.max_radius() {
                    return Err(protocol(format!(
                        "query {}: radius {} is beyond the core: {}",
                        q.id,
                        q.radius,
                        cfg.radius_limit()
                    )));
                }
                for a in 0..3 {
                    if q.coords[a] > cfg.layout.coord_max(a) {
                        return Err(protocol(format!(
                            "query {}: coordinate {} = {} exceeds the {}-bit axis",
                            q.id, a, q.coords[a], cfg.layout.bits[a]
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Run `jobs`; per job, per query in input order, its result (`None` if
    /// `limits.max_cycles` ended the run first; the rest stay in flight).
    pub fn run(
        &mut self,
        jobs: &[Job<'_>],
        limits: RunLimits,
    ) -> Result<Vec<Vec<Option<HwResult>>>, HwError> {
        self.check_jobs(jobs)?;
        let cfg = *self.config();
        let mut host = Host {
            job: 0,
            loading: jobs.first().is_some_and(|j| j.load.is_some()),
            load_next: 1,
            load_presenting: false,
            query_next: 0,
            query_tag: None,
            tags: vec![None; 1 << cfg.id_bits()],
            free_tags: (0..1 << cfg.id_bits()).collect(),
            current: vec![None; cfg.result_streams],
            received: 0,
            memory_ready: false,
        };
        // With external memory only the replicated levels are streamed, then the
        // last word (whose address is the photon count).
        let on_chip = cfg
            .memory
            .and(cfg.banking)
            .map_or(usize::MAX, |b| 1usize << b.replicated_levels);
        let total: usize = jobs.iter().map(|j| j.queries.len()).sum();
        let mut results: Vec<Vec<Option<HwResult>>> =
            jobs.iter().map(|j| vec![None; j.queries.len()]).collect();
        let patience = 10_000 + 8 * (cfg.tree_words() as u64 + 2) * cfg.issue_interval() as u64;
        let start = self.cycle;
        let mut since_progress = 0u64;
        let mut tail = 0u64;
        loop {
            let all_sent = host.job + 1 >= jobs.len()
                && !host.loading
                && jobs
                    .get(host.job)
                    .is_none_or(|j| host.query_next == j.queries.len());
            let done = host.received == total && all_sent;
            if done {
                if tail == limits.tail_cycles {
                    break;
                }
                tail += 1;
            }
            if limits
                .max_cycles
                .is_some_and(|m| self.cycle - start >= m && !done)
            {
                break;
            }
            // This cycle's inputs.
            self.inputs.load_valid = false;
            self.inputs.query_valid = false;
            let streams = cfg.result_streams;
            if done {
                self.inputs.result_ready[..streams].fill(true);
            } else {
                let job = jobs[host.job];
                if host.loading && on_chip != usize::MAX && !host.memory_ready {
                    // A new map in memory: once every earlier result is in, reset
                    // the core (emptying its cache) and write the image.
                    let before: usize = jobs[..host.job].iter().map(|j| j.queries.len()).sum();
                    if host.received == before {
                        self.reset()?;
                        self.dut
                            .load_memory(job.load.expect("loading a job with a map"))?;
                        host.memory_ready = true;
                    }
                } else if host.loading {
                    let tree = job.load.expect("loading a job with a map");
                    if !host.load_presenting && !self.stall() {
                        host.load_presenting = true;
                    }
                    self.inputs.load_valid = host.load_presenting;
                    self.inputs.load = LoadBeat {
                        address: host.load_next as u64,
                        word: tree.words[host.load_next],
                        last: host.load_next == tree.len(),
                    };
                } else if host.query_next < job.queries.len() {
                    if host.query_tag.is_none() && !self.stall() {
                        // No free tag: every tag is in flight; wait for a result.
                        host.query_tag = host.free_tags.pop_front();
                    }
                    let q = &job.queries[host.query_next];
                    self.inputs.query_valid = host.query_tag.is_some();
                    self.inputs.query = QueryBeat {
                        id: (host.query_tag.unwrap_or(0) as u64).into(),
                        x: (q.coords[0] as u64).into(),
                        y: (q.coords[1] as u64).into(),
                        z: (q.coords[2] as u64).into(),
                        radius: q.radius.min(u32::MAX as u64).into(),
                        k: (q.k as u64).into(),
                    };
                }
                for s in 0..streams {
                    self.inputs.result_ready[s] = !self.stall();
                }
            }
            let out = self.step()?;
            let load_fire = self.inputs.load_valid && out.load_ready;
            let query_fire = self.inputs.query_valid && out.query_ready;
            let mut result_fire = false;
            for s in 0..streams {
                if self.inputs.result_ready[s] && out.result_valid[s] {
                    result_fire = true;
                    receive(&mut host, jobs, &mut results, s, &out.result[s])?;
                }
            }
            if load_fire {
                host.load_presenting = false;
                let tree = jobs[host.job].load.expect("loading");
                if host.load_next == tree.len() {
                    host.loading = false;
                    host.memory_ready = false;
                    host.query_next = 0;
                } else {
                    host.load_next += 1;
                    if host.load_next >= on_chip {
                        host.load_next = tree.len();
                    }
                }
            }
            if query_fire {
                let tag = host.query_tag.take().expect("presented with a tag");
                host.tags[tag] = Some((host.job, host.query_next));
                host.query_next += 1;
            }
            if !host.loading
                && host.query_next == jobs[host.job].queries.len()
                && host.job + 1 < jobs.len()
            {
                host.job += 1;
                host.query_next = 0;
                host.loading = jobs[host.job].load.is_some();
                host.load_next = 1;
            }
            if load_fire || query_fire || result_fire || done {
                since_progress = 0;
            } else {
                since_progress += 1;
                if since_progress > patience {
                    return Err(protocol(format!(
                        "no progress for {patience} cycles at cycle {} ({} of {total} results)",
                        self.cycle, host.received
                    )));
                }
            }
        }
        // A heap core's entries: distances from the map each job ran on.
        if !cfg.sends_distances() {
            for (job, res) in jobs.iter().zip(&mut results) {
                if let Some(t) = job.load {
                    self.map.load(t);
                }
                for (q, r) in job.queries.iter().zip(res.iter_mut()) {
                    if let Some(r) = r {
                        self.map.fill(cfg.metric, q.id, q.coords, &mut r.found)?;
                    }
                }
            }
        }
        Ok(results)
    }
}

/// Take one result beat from result stream `stream`, checking the packet protocol
/// (each stream's packets are whole; the streams are independent).
fn receive(
    host: &mut Host,
    jobs: &[Job<'_>],
    results: &mut [Vec<Option<HwResult>>],
    stream: usize,
    beat: &ResultBeat,
) -> Result<(), HwError> {
    let tag = beat.id.to_u64() as usize;
    let (ji, qi) = host
        .tags
        .get(tag)
        .copied()
        .flatten()
        .ok_or_else(|| protocol(format!("result for unknown query tag {tag}")))?;
    if beat.header {
        if host.current[stream].is_some() {
            return Err(protocol("result header inside a result"));
        }
        if results[ji][qi].is_some() {
            return Err(protocol(format!(
                "duplicate result for query {}",
                jobs[ji].queries[qi].id
            )));
        }
        let count = beat.count.to_u64() as usize;
        results[ji][qi] = Some(HwResult {
            id: jobs[ji].queries[qi].id,
            found: Vec::with_capacity(count),
            visited: beat.visited.to_u64() as u32,
        });
        if (count == 0) != beat.last {
            return Err(protocol("result header: last flag and count disagree"));
        }
        host.current[stream] = Some((tag, count));
    } else {
        let (ctag, count) =
            host.current[stream].ok_or_else(|| protocol("result entry without a header"))?;
        if ctag != tag {
            return Err(protocol("result entries of two queries interleaved"));
        }
        let r = results[ji][qi].as_mut().expect("header seen");
        r.found
            .push((beat.address.to_u64() as u32, beat.distance.to_u64()));
        if beat.pair {
            r.found
                .push((beat.address2.to_u64() as u32, beat.distance2.to_u64()));
        }
        if r.found.len() > count {
            return Err(protocol("result entries: more photons than the count"));
        }
        if (r.found.len() == count) != beat.last {
            return Err(protocol("result entries: last flag and count disagree"));
        }
    }
    if beat.last {
        host.current[stream] = None;
        host.received += 1;
        host.tags[tag] = None;
        host.free_tags.push_back(tag);
    }
    Ok(())
}
