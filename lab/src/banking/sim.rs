//! A cycle model of D barrel datapaths sharing B banks: which read each datapath
//! issues in each cycle, which bank it goes to, and who wins a bank.
//!
//! A datapath is the barrel port (`hw::barrel::barrel_port`): S slots, each with one read
//! in flight at most; a read granted in cycle t brings its slot back, ready to
//! issue its next read, in cycle t + `loop_cycles` (the barrel's eleven-cycle slot
//! loop plus the interconnect's registers); it issues at most one read per cycle.
//! A read of a replicated node goes to the datapath's own copy and always
//! succeeds; a read below goes to its bank, which serves one read per cycle per
//! port, round robin among the datapaths asking (per port, as the BankCrossbar's
//! arbiters: a second port serves the datapaths the first left waiting). The read a datapath offers is
//! its oldest ready slot's; refused, under [`Issue::InOrder`] it offers the same
//! read again next cycle (the datapath stalls), under [`Issue::Rotate`] that slot
//! goes to the back of the ready queue and the next slot offers its read (the slot
//! waits on its bank, the others go on, as the issue asks of the interconnect).
//! Queries enter in the given order, one per datapath per cycle into a free slot,
//! whichever datapath has one (the core's dispatcher); a query's first read is
//! offered in the cycle it enters.

use super::mapping::BankMap;
use std::collections::VecDeque;

/// What a datapath does with a refused read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Issue {
    /// Offer the same read again: the datapath stalls until its bank is free.
    InOrder,
    /// Put the slot at the back of the ready queue; the next ready slot offers.
    Rotate,
}

/// The datapaths and banks modelled.
#[derive(Clone, Copy, Debug)]
pub struct Machine {
    pub datapaths: usize,
    pub slots: usize,
    /// Cycles from a read's grant until its slot can issue again.
    pub loop_cycles: u64,
    /// Reads a bank serves per cycle (1; 2 for both ports of a dual-port bank).
    pub bank_ports: usize,
    pub map: BankMap,
    pub issue: Issue,
}

/// What a run measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measured {
    pub cycles: u64,
    /// Every read of every query (each exactly once).
    pub reads: u64,
    /// Of those, reads that went to a bank.
    pub bank_reads: u64,
    /// Bank requests offered (a refused read offered again counts again).
    pub offered: u64,
    pub refused: u64,
    /// Reads per bank.
    pub per_bank: Vec<u64>,
    /// Reads per datapath.
    pub per_datapath: Vec<u64>,
}

impl Measured {
    /// Reads per cycle per datapath over the whole run.
    pub fn reads_per_cycle_per_datapath(&self) -> f64 {
        self.reads as f64 / self.cycles.max(1) as f64 / self.per_datapath.len().max(1) as f64
    }
    /// Refused bank requests / offered bank requests.
    pub fn conflict_rate(&self) -> f64 {
        self.refused as f64 / self.offered.max(1) as f64
    }
    /// Busiest bank's reads / the mean bank's.
    pub fn bank_imbalance(&self) -> f64 {
        imbalance(&self.per_bank)
    }
}

/// max / mean of `v` (1 for an even spread; 0 for no data).
pub fn imbalance(v: &[u64]) -> f64 {
    let sum: u64 = v.iter().sum();
    if sum == 0 {
        return 0.0;
    }
    let max = *v.iter().max().unwrap() as f64;
    max / (sum as f64 / v.len() as f64)
}

struct Slot {
    query: usize,
    pos: usize,
}

struct Datapath {
    slots: Vec<Option<Slot>>,
    ready: VecDeque<usize>,
    inflight: VecDeque<(u64, usize)>,
}

/// Run every query of `reads` (per query, its addresses), in `order`, through
/// `m`. Every read is issued exactly once; the run ends when the last query's last
/// read has come back.
pub fn run(m: &Machine, reads: &[Vec<u32>], order: &[usize]) -> Measured {
    assert!(m.datapaths >= 1 && m.slots >= 1 && m.bank_ports >= 1 && m.loop_cycles >= 1);
    let banks = m.map.banks();
    let mut dps: Vec<Datapath> = (0..m.datapaths)
        .map(|_| Datapath {
            slots: (0..m.slots).map(|_| None).collect(),
            ready: VecDeque::new(),
            inflight: VecDeque::new(),
        })
        .collect();
    let mut out = Measured {
        per_bank: vec![0; banks],
        per_datapath: vec![0; m.datapaths],
        ..Measured::default()
    };
    // Per bank port, the round robin's next start (the last granted + 1).
    let mut rr = vec![0usize; banks * m.bank_ports];
    let mut next = order.iter().copied().filter(|&q| !reads[q].is_empty());
    let mut pending = next.next();
    let mut live = 0usize;
    // (bank, datapath) requests of this cycle, and each datapath's offered address.
    let mut requests: Vec<(u32, usize)> = Vec::with_capacity(m.datapaths);
    let mut granted = vec![false; m.datapaths];
    let mut t = 0u64;
    loop {
        for dp in dps.iter_mut() {
            while dp.inflight.front().is_some_and(|&(at, _)| at <= t) {
                let (_, s) = dp.inflight.pop_front().unwrap();
                let slot = dp.slots[s].as_ref().unwrap();
                if slot.pos == reads[slot.query].len() {
                    dp.slots[s] = None;
                    live -= 1;
                } else {
                    dp.ready.push_back(s);
                }
            }
            if let Some(q) = pending {
                if let Some(s) = dp.slots.iter().position(Option::is_none) {
                    dp.slots[s] = Some(Slot { query: q, pos: 0 });
                    dp.ready.push_back(s);
                    live += 1;
                    pending = next.next();
                }
            }
        }
        if live == 0 && pending.is_none() {
            break;
        }
        requests.clear();
        for (d, dp) in dps.iter().enumerate() {
            granted[d] = false;
            if let Some(&s) = dp.ready.front() {
                let slot = dp.slots[s].as_ref().unwrap();
                match m.map.bank(reads[slot.query][slot.pos]) {
                    None => granted[d] = true,
                    Some(b) => requests.push((b, d)),
                }
            }
        }
        out.offered += requests.len() as u64;
        requests.sort_unstable();
        let mut i = 0;
        while i < requests.len() {
            let b = requests[i].0;
            let mut j = i;
            while j < requests.len() && requests[j].0 == b {
                j += 1;
            }
            // Each port of the bank in turn (the BankCrossbar's arbiters): round
            // robin among the requesters no earlier port took, the first at or
            // after the port's pointer.
            let group = &requests[i..j];
            let mut took = 0;
            for p in 0..m.bank_ports {
                let ptr = &mut rr[b as usize * m.bank_ports + p];
                let free = |&&(_, d): &&(u32, usize)| !granted[d];
                let pick = group
                    .iter()
                    .filter(free)
                    .find(|&&(_, d)| d >= *ptr)
                    .or_else(|| group.iter().find(free));
                let Some(&(_, d)) = pick else { break };
                granted[d] = true;
                *ptr = d + 1;
                took += 1;
                out.per_bank[b as usize] += 1;
                out.bank_reads += 1;
            }
            out.refused += (group.len() - took) as u64;
            i = j;
        }
        for (d, dp) in dps.iter_mut().enumerate() {
            if granted[d] {
                let s = dp.ready.pop_front().unwrap();
                dp.slots[s].as_mut().unwrap().pos += 1;
                dp.inflight.push_back((t + m.loop_cycles, s));
                out.reads += 1;
                out.per_datapath[d] += 1;
            } else if m.issue == Issue::Rotate && dp.ready.len() > 1 {
                dp.ready.rotate_left(1);
            }
        }
        t += 1;
    }
    out.cycles = t;
    out
}
