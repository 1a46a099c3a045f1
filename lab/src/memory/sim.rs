//! The cycle model with a cache and a memory: `banking::sim`'s D barrel
//! datapaths of S slots (a read's slot comes back `loop_cycles` later, one read
//! issued per datapath per cycle), where a read below the on-chip levels goes to
//! its datapath's cache. A hit comes back like an on-chip read. A miss parks its
//! slot (as a slot refused by a busy bank waits, `hw::store::read_issue`) while the
//! datapath's other slots go on; its block is requested from the memory unless a
//! request for it is already in flight (a miss status holding register, Kroft,
//! ISCA 1981: the second miss waits for the same burst). The memory serves bursts
//! in order: each occupies the data bus `block_bytes / bytes_per_cycle` cycles and
//! is all in `latency` cycles after its transfer slot ends (the controller's and
//! the DRAM's read latency on top of the transfer); the burst fills the line when it arrives, and the parked reads come back a slot
//! loop later. This is Little's law made concrete: with L the loop, m the misses
//! per read and Lm the latency, a slot reads once per L + m × Lm cycles, so S
//! slots keep a datapath reading every cycle once S ≥ L + m × Lm, unless the
//! memory's bytes per cycle run out first (D × reads/cycle × m × block bytes ≤ W).

use super::cache::{Cache, CacheConfig};
use super::layout::{BlockLayout, Place};
use super::trace::Sharing;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, VecDeque};

/// The memory as the model sees it, in core cycles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryTiming {
    /// Cycles a burst's data arrives after its slot on the data bus (the
    /// controller's and the DRAM's read latency).
    pub latency: u64,
    /// Bytes the data bus delivers per core cycle (sustained).
    pub bytes_per_cycle: f64,
}

/// The modelled machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Machine {
    pub datapaths: usize,
    pub slots: usize,
    pub loop_cycles: u64,
    pub layout: BlockLayout,
    /// The core's whole cache (split among the caches as in `trace::Replay`).
    pub cache: CacheConfig,
    pub sharing: Sharing,
    pub memory: MemoryTiming,
}

/// What a run measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measured {
    pub cycles: u64,
    pub queries: u64,
    pub reads: u64,
    pub on_chip: u64,
    pub hits: u64,
    /// Misses that started a burst, and misses that waited on one in flight.
    pub misses: u64,
    pub merged: u64,
    /// Cycles the memory's data bus was busy.
    pub bus_cycles: f64,
    /// Most bursts in flight at once.
    pub max_in_flight: usize,
}

impl Measured {
    pub fn reads_per_cycle_per_datapath(&self, datapaths: usize) -> f64 {
        self.reads as f64 / self.cycles.max(1) as f64 / datapaths.max(1) as f64
    }
    pub fn bus_utilisation(&self) -> f64 {
        self.bus_cycles / self.cycles.max(1) as f64
    }
}

struct Datapath {
    /// Per slot: (query, next read).
    slots: Vec<Option<(usize, usize)>>,
    ready: VecDeque<usize>,
    /// (cycle the slot is ready again, slot).
    back: BinaryHeap<Reverse<(u64, usize)>>,
}

/// Run every query of `reads`, in `order`, through `m`; every read is issued
/// exactly once, and the run ends when the last read has come back.
pub fn run(m: &Machine, reads: &[Vec<u32>], order: &[usize]) -> Measured {
    assert!(m.datapaths >= 1 && m.slots >= 1 && m.loop_cycles >= 1);
    assert!(m.memory.bytes_per_cycle > 0.0);
    let replay = super::trace::Replay {
        datapaths: m.datapaths,
        slots: m.slots,
        layout: m.layout,
        cache: m.cache,
        sharing: m.sharing,
    };
    let blocks = m.layout.blocks() as usize;
    let mut caches: Vec<Cache> = (0..m.sharing.caches(m.datapaths))
        .map(|_| Cache::new(replay.cache_each(), blocks))
        .collect();
    // Per cache: the blocks whose bursts are in flight, and when each arrives.
    let mut pending: Vec<HashMap<u32, u64>> = vec![HashMap::new(); caches.len()];
    // Bursts in arrival order (the memory serves in order): (arrival, cache, block).
    let mut arrivals: VecDeque<(u64, usize, u32)> = VecDeque::new();
    let transfer = f64::from(m.layout.block_bytes()) / m.memory.bytes_per_cycle;
    let mut bus_free = 0.0f64;
    let mut dps: Vec<Datapath> = (0..m.datapaths)
        .map(|_| Datapath {
            slots: vec![None; m.slots],
            ready: VecDeque::new(),
            back: BinaryHeap::new(),
        })
        .collect();
    let mut out = Measured::default();
    let mut next = order.iter().copied().filter(|&q| !reads[q].is_empty());
    let mut pending_query = next.next();
    let mut live = 0usize;
    let mut t = 0u64;
    loop {
        // Bursts that arrived fill their lines.
        while arrivals.front().is_some_and(|&(at, _, _)| at <= t) {
            let (_, c, b) = arrivals.pop_front().unwrap();
            caches[c].fill(b);
            pending[c].remove(&b);
        }
        for dp in dps.iter_mut() {
            while dp.back.peek().is_some_and(|Reverse((at, _))| *at <= t) {
                let Reverse((_, s)) = dp.back.pop().unwrap();
                let (q, pos) = dp.slots[s].unwrap();
                if pos == reads[q].len() {
                    dp.slots[s] = None;
                    live -= 1;
                } else {
                    dp.ready.push_back(s);
                }
            }
            if let Some(q) = pending_query {
                if let Some(s) = dp.slots.iter().position(Option::is_none) {
                    dp.slots[s] = Some((q, 0));
                    dp.ready.push_back(s);
                    live += 1;
                    out.queries += 1;
                    pending_query = next.next();
                }
            }
        }
        if live == 0 && pending_query.is_none() {
            break;
        }
        for (d, dp) in dps.iter_mut().enumerate() {
            let Some(s) = dp.ready.pop_front() else {
                continue;
            };
            let (q, pos) = dp.slots[s].unwrap();
            dp.slots[s] = Some((q, pos + 1));
            out.reads += 1;
            let back = match m.layout.place(reads[q][pos]) {
                Place::OnChip => {
                    out.on_chip += 1;
                    t + m.loop_cycles
                }
                Place::External { block, .. } => {
                    let c = m.sharing.cache_of(d);
                    if caches[c].lookup(block) {
                        out.hits += 1;
                        t + m.loop_cycles
                    } else if let Some(&at) = pending[c].get(&block) {
                        out.merged += 1;
                        at + m.loop_cycles
                    } else {
                        out.misses += 1;
                        let start = bus_free.max(t as f64);
                        bus_free = start + transfer;
                        out.bus_cycles += transfer;
                        let at = (start + transfer).ceil() as u64 + m.memory.latency;
                        pending[c].insert(block, at);
                        arrivals.push_back((at, c, block));
                        out.max_in_flight = out.max_in_flight.max(arrivals.len());
                        at + m.loop_cycles
                    }
                }
            };
            dp.back.push(Reverse((back, s)));
        }
        t += 1;
    }
    out.cycles = t;
    out
}
