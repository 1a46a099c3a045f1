//! A model of an external memory behind an AXI4 read port, for the simulations of
//! the external-memory blocks and core (issue: every simulation answers the AXI4
//! master with a model of a named memory). It holds the map's image and answers
//! INCR bursts in the order they were asked (one AXI ID), each beat after the
//! memory's latency and at most one beat a cycle (a beat of the port's width: the
//! bandwidth), with random pauses on both channels and random extra latency per
//! burst when asked for (the tests' stress: a master that only works with a
//! prompt memory fails). The figures of the memories modelled, and their sources,
//! are in docs/MEMORY.md.

use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::photon_word::TreeImage;
use crate::hw::error::HwError;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::VecDeque;

/// How the memory answers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxiTiming {
    /// Cycles from a burst's address accepted to its first beat.
    pub latency: u64,
    /// Extra cycles per burst, drawn uniformly from 0..=this.
    pub extra_latency: u64,
    /// Chance that `arready` is low in a cycle, and that a due beat waits a cycle.
    pub ar_pause: f64,
    pub r_pause: f64,
    /// Cycles from one beat to the next at least: 1 is a beat a cycle (the
    /// port's width a cycle), n a memory with 1/n of that bandwidth.
    pub beat_interval: u64,
    /// The DRAM's sustained bytes a cycle (0: no limit but the port's): a beat
    /// goes only with that many bytes of credit, which grows by this much a
    /// cycle up to one [`CREDIT_BYTES`] burst's worth, so an idle memory sends a
    /// line at the port's rate and a busy one averages this rate (refresh, row
    /// misses).
    pub sustained_bytes: f64,
    pub seed: u64,
}

/// The clock (MHz) of the ECP5-85k board's LiteDRAM controller, whose cycles
/// [`AxiTiming::ecp5_ddr3`]'s figures count (docs/MEMORY.md, "Memories modelled").
pub const ECP5_DDR3_MHZ: f64 = 75.0;

/// The most credit a memory saves up while idle: one 64-byte line.
pub const CREDIT_BYTES: f64 = 64.0;

impl AxiTiming {
    /// The memory every simulation of the external-memory core answers with
    /// unless told otherwise: the ECP5-85k board's 16-bit DDR3 behind LiteDRAM,
    /// its latency in controller cycles the PHY's and the controller's, and its
    /// sustained 6.4 bytes a cycle (80 % of the 8-byte peak), as docs/MEMORY.md
    /// ("Memories modelled") derives and sources them; a beat a cycle at most,
    /// no pauses.
    pub fn ecp5_ddr3() -> Self {
        AxiTiming::ecp5_ddr3_at(ECP5_DDR3_MHZ)
    }

    /// [`AxiTiming::ecp5_ddr3`] as a core clocked at `core_mhz` sees it: the
    /// controller's latency and sustained bytes are per cycle of its own clock,
    /// so a faster core waits more of its cycles for a burst (rounded up) and
    /// gets fewer bytes a cycle (the same bytes a second).
    pub fn ecp5_ddr3_at(core_mhz: f64) -> Self {
        let ratio = core_mhz / ECP5_DDR3_MHZ;
        AxiTiming {
            sustained_bytes: 6.4 / ratio,
            ..AxiTiming::fixed((22.0 * ratio).ceil() as u64)
        }
    }

    /// A prompt memory: the latency alone, no pauses.
    pub fn fixed(latency: u64) -> Self {
        AxiTiming {
            latency,
            extra_latency: 0,
            ar_pause: 0.0,
            r_pause: 0.0,
            beat_interval: 1,
            sustained_bytes: 0.0,
            seed: 1,
        }
    }

    /// This memory with `1/n` of its bandwidth (a beat every `n` cycles at most).
    pub fn with_beat_interval(self, n: u64) -> Self {
        AxiTiming {
            beat_interval: n.max(1),
            ..self
        }
    }
}

/// What the memory drives in a cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct AxiSlaveOut {
    pub arready: bool,
    pub rvalid: bool,
    pub rdata: u64,
    pub rlast: bool,
    pub rresp: u8,
}

/// A burst asked for: its byte address, beats − 1 and log2 of a beat's bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxiBurst {
    pub addr: u64,
    pub len: u8,
    pub size: u8,
    pub burst: u8,
}

struct InFlight {
    burst: AxiBurst,
    beat: u64,
    due: u64,
}

/// What a memory model has carried since its map was put in it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryTraffic {
    /// Bursts asked for (AR handshakes): the cache's line fills.
    pub bursts: u64,
    /// Read beats taken (R handshakes), and their bytes.
    pub beats: u64,
    pub bytes: u64,
}

/// The memory: a byte image (little-endian words), its timing and the bursts in
/// flight. Beats of up to 64 bits.
pub struct AxiMemory {
    bytes: Vec<u8>,
    timing: AxiTiming,
    rng: Pcg64,
    cycle: u64,
    /// The first cycle the next beat may come (`beat_interval`), and the bytes
    /// the DRAM may send now (`sustained_bytes`).
    next_beat: u64,
    credit: f64,
    queue: VecDeque<InFlight>,
    out: AxiSlaveOut,
    /// Byte addresses whose bursts answer SLVERR (an injected fault).
    faulty: Vec<u64>,
    /// Every burst asked for, in order (for the tests' checks of the master).
    pub bursts: Vec<AxiBurst>,
    /// Read beats taken (`rvalid` and `rready`): the data channel's busy
    /// cycles; and their bytes.
    pub beats: u64,
    pub bytes_read: u64,
}

impl AxiMemory {
    /// A memory holding `words`, each `word_bytes` bytes (little-endian), at byte 0.
    pub fn from_words(words: &[u64], word_bytes: usize, timing: AxiTiming) -> Self {
        let bytes = words
            .iter()
            .flat_map(|w| w.to_le_bytes().into_iter().take(word_bytes))
            .collect();
        AxiMemory {
            bytes,
            timing,
            rng: Pcg64::seed_from_u64(timing.seed),
            cycle: 0,
            next_beat: 0,
            credit: CREDIT_BYTES,
            queue: VecDeque::new(),
            out: AxiSlaveOut::default(),
            faulty: vec![],
            bursts: vec![],
            beats: 0,
            bytes_read: 0,
        }
    }

    /// The memory of `cfg`'s external-memory core holding `tree`'s image
    /// (`MemoryLayout::image`, one photon word per `word_width() / 8` bytes, at
    /// byte 0).
    pub fn for_map(
        cfg: &CoreConfig,
        tree: TreeImage<'_>,
        timing: AxiTiming,
    ) -> Result<Self, HwError> {
        let layout = cfg
            .memory_layout()
            .ok_or_else(|| HwError::Simulation("this core's map is on chip".into()))?;
        Ok(AxiMemory::from_words(
            &layout.image(tree),
            cfg.word_width() / 8,
            timing,
        ))
    }

    /// Bursts at byte address `addr` answer SLVERR from now on.
    pub fn fail_at(&mut self, addr: u64) {
        self.faulty.push(addr);
    }

    /// What the memory drives this cycle, before the edge: `arready` (unless
    /// paused) and the head burst's next beat once it is due (unless paused).
    pub fn drive(&mut self) -> AxiSlaveOut {
        let arready = !self.rng.gen_bool(self.timing.ar_pause);
        let pause = self.rng.gen_bool(self.timing.r_pause);
        let mut out = AxiSlaveOut {
            arready,
            ..AxiSlaveOut::default()
        };
        if let Some(f) = self.queue.front() {
            let b = f.burst;
            let beat_bytes = 1u64 << b.size;
            let paid = self.timing.sustained_bytes <= 0.0 || self.credit >= beat_bytes as f64;
            if f.due <= self.cycle && self.next_beat <= self.cycle && paid && !pause {
                let at = b.addr + f.beat * beat_bytes;
                let mut data = [0u8; 8];
                for (i, d) in data.iter_mut().enumerate().take(beat_bytes as usize) {
                    *d = self
                        .bytes
                        .get((at + i as u64) as usize)
                        .copied()
                        .unwrap_or(0);
                }
                out.rvalid = true;
                out.rdata = u64::from_le_bytes(data);
                out.rlast = f.beat == u64::from(b.len);
                out.rresp = if self.faulty.contains(&b.addr) { 2 } else { 0 };
            }
        }
        self.out = out;
        out
    }

    /// The edge: a burst accepted (`arvalid` was high with this cycle's
    /// `arready`) joins the queue; a beat taken (`rready`) moves its burst on.
    pub fn edge(&mut self, ar: Option<AxiBurst>, rready: bool) {
        if let (Some(b), true) = (ar, self.out.arready) {
            assert!(b.size <= 3, "beats of at most 64 bits in this model");
            let extra = self.rng.gen_range(0..=self.timing.extra_latency);
            // In order: a burst starts no earlier than the one before it.
            let after = self.queue.back().map_or(0, |f| f.due);
            self.queue.push_back(InFlight {
                burst: b,
                beat: 0,
                due: (self.cycle + self.timing.latency + extra).max(after),
            });
            self.bursts.push(b);
        }
        if self.timing.sustained_bytes > 0.0 {
            self.credit = (self.credit + self.timing.sustained_bytes).min(CREDIT_BYTES);
        }
        if self.out.rvalid && rready {
            self.beats += 1;
            self.next_beat = self.cycle + self.timing.beat_interval.max(1);
            let f = self.queue.front_mut().expect("a beat came from a burst");
            let beat_bytes = 1u64 << f.burst.size;
            self.bytes_read += beat_bytes;
            if self.timing.sustained_bytes > 0.0 {
                self.credit -= beat_bytes as f64;
            }
            f.beat += 1;
            if f.beat > u64::from(f.burst.len) {
                self.queue.pop_front();
            }
        }
        self.cycle += 1;
    }

    /// What the memory has carried: bursts asked for and beats taken.
    pub fn traffic(&self) -> MemoryTraffic {
        MemoryTraffic {
            bursts: self.bursts.len() as u64,
            beats: self.beats,
            bytes: self.bytes_read,
        }
    }

    /// Bursts asked for and not yet answered in full.
    pub fn in_flight(&self) -> usize {
        self.queue.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cycles at which a prompt master (always ready) takes each beat of one
    /// 16-beat burst of 4-byte beats.
    fn beat_cycles(timing: AxiTiming) -> Vec<u64> {
        let words: Vec<u64> = (0..16).collect();
        let mut m = AxiMemory::from_words(&words, 4, timing);
        let burst = AxiBurst {
            addr: 0,
            len: 15,
            size: 2,
            burst: 1,
        };
        let mut taken = vec![];
        let mut asked = false;
        for cycle in 0..200 {
            let out = m.drive();
            if out.rvalid {
                assert_eq!(out.rdata, taken.len() as u64, "beats in address order");
                assert_eq!(out.rlast, taken.len() == 15);
                taken.push(cycle);
            }
            let ar = (!asked).then_some(burst);
            asked |= out.arready;
            m.edge(ar, true);
        }
        taken
    }

    #[test]
    fn the_ddr3_seen_from_a_faster_core_keeps_its_nanoseconds_and_bytes_a_second() {
        // The ECPIX-5's DDR3: 22 controller cycles of 13.3 ns to the first beat
        // (293.3 ns), 480 MB/s sustained (docs/MEMORY.md).
        let at_75 = AxiTiming::ecp5_ddr3_at(75.0);
        assert_eq!((at_75.latency, at_75.sustained_bytes), (22, 6.4));
        for mhz in [50.0, 87.0, 150.0] {
            let t = AxiTiming::ecp5_ddr3_at(mhz);
            let ns = t.latency as f64 * 1e3 / mhz;
            assert!(
                (293.3..293.4 + 1e3 / mhz).contains(&ns),
                "{mhz} MHz: {ns} ns"
            );
            let mb_per_s = t.sustained_bytes * mhz;
            assert!(
                (mb_per_s - 480.0).abs() < 1e-9,
                "{mhz} MHz: {mb_per_s} MB/s"
            );
        }
    }

    #[test]
    fn a_beat_interval_spaces_the_beats_by_that_many_cycles() {
        for n in [1u64, 2, 3, 8] {
            let t = beat_cycles(AxiTiming::fixed(5).with_beat_interval(n));
            assert_eq!(t.len(), 16, "every beat of the burst");
            assert_eq!(t[0], 5, "the first beat after the latency");
            for w in t.windows(2) {
                assert_eq!(w[1] - w[0], n, "a beat every {n} cycles");
            }
        }
    }

    #[test]
    fn a_sustained_rate_lets_a_line_go_then_holds_the_average() {
        // Four 16-beat bursts of 4-byte beats (256 bytes) asked at once from a
        // memory sustaining 2 bytes a cycle: the 64 bytes of credit saved while
        // idle go at a beat a cycle, the other 192 bytes take 2 bytes a cycle.
        let words: Vec<u64> = (0..64).collect();
        let timing = AxiTiming {
            sustained_bytes: 2.0,
            ..AxiTiming::fixed(0)
        };
        let mut m = AxiMemory::from_words(&words, 4, timing);
        let mut taken = vec![];
        let mut asked = 0u64;
        for cycle in 0..400u64 {
            let out = m.drive();
            if out.rvalid {
                assert_eq!(out.rdata, taken.len() as u64, "beats in address order");
                taken.push(cycle);
            }
            let ar = (asked < 4).then_some(AxiBurst {
                addr: asked * 64,
                len: 15,
                size: 2,
                burst: 1,
            });
            if ar.is_some() && out.arready {
                asked += 1;
            }
            m.edge(ar, true);
        }
        assert_eq!(taken.len(), 64, "every beat");
        let first = taken[0];
        assert!(
            taken[..16].windows(2).all(|w| w[1] == w[0] + 1),
            "a saved-up line at full rate"
        );
        let span = taken[63] - first;
        // 64 bytes on credit, then 192 at 2 a cycle (the credit regrows while the
        // first line goes): about 96 cycles, not the 63 of a beat a cycle.
        assert!(
            (80..=100).contains(&span),
            "256 bytes at 2 bytes a cycle: {span} cycles"
        );
        assert_eq!(m.traffic().bytes, 256);
    }
}
