//! B, L and D from the map and the device: how many banks one copy of the map
//! spreads over, how many top levels each datapath keeps its own copy of, and how
//! many datapaths the rest of the BlockRAM holds.
//!
//! * A bank is one column of BlockRAMs in the device's widest port shape (a photon
//!   word fits one BlockRAM's width on both devices), as deep as its share of the
//!   map needs: `B = 2^b` banks of `rows = (N >> b) + 1` words (the row of heap
//!   address `a` is `a >> b`, see `mapping`).
//! * `L`: the top levels fill one BlockRAM beside each datapath (`2^L − 1` nodes
//!   no deeper than one BlockRAM's words); a map that small needs no banks.
//! * `D`: each datapath costs its replica plus its own memories (the barrel port's
//!   offsets and found lists); D is what the BlockRAM left after the banks holds,
//!   capped by `B / banks_per_datapath` (the bank model's measured curve: fewer
//!   banks per datapath than that and the conflicts cost more than a datapath
//!   gains) and by the logic budget, which the datapaths share with the crossbar.
//! * The crossbar grows as D × B (each bank port picks a row among its
//!   requesters, each requester a word among the bank ports, both multiplexer
//!   trees), at the device's measured cost per requester and bank for shared
//!   and for split ports (`BankPorts`): split ports halve the trees for a few
//!   per cent more conflicts, so the plan takes shared ports where they fit the
//!   budget and split ports where only those do.
//! * `B` is a power of two, at most `2^L` (so the mappings are bijections,
//!   `mapping`) and at most `max_banks`: of those, the one giving the most
//!   datapaths, then the fewest BlockRAMs (rounding each bank up to whole
//!   BlockRAMs wastes some), then the most banks (fewer conflicts), then shared
//!   ports.

pub use crate::host::device::devices::{datapath_brams, Device, DeviceCosts, ECP5_85K, XC6VSX475T};
use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::core_config::{MAX_BANKED_TREES, MAX_TREES};
use crate::hw::config::memory_config::{
    CacheTags, DEFAULT_MEMORY_DATA_BITS, MAX_BANK_LINES, MAX_CACHE_BANK_BITS, MAX_CACHE_LINES,
    MAX_MEMORY_ADDRESS_BITS, MEMORY_BLOCK_LEVELS,
};
use crate::hw::memory::cache_port::TAG_BITS;
use std::fmt;

/// What the plan is asked to respect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Fewest datapaths worth building (four: what the ECP5-85k's logic holds at
    /// K = 32 beside the crossbar).
    pub min_datapaths: u32,
    /// Banks per datapath below which conflicts cost more than a datapath adds.
    pub banks_per_datapath: u32,
    /// Largest bank count and datapath count the interconnect is built for.
    pub max_banks: u32,
    pub max_datapaths: u32,
    /// Share of the device's logic the datapaths and the crossbar may take (the
    /// rest: the result path, the load path and the I/O).
    pub logic_share: f64,
    /// Share of the device's logic an external-memory core may take in all, its
    /// cache included: below the share at which nextpnr's router1 stopped routing
    /// such a core on the ECP5-85k (docs/MEMORY_CORE.md, "What fits").
    pub device_share: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            min_datapaths: 4,
            banks_per_datapath: 4,
            max_banks: 1024,
            max_datapaths: 2 * MAX_BANKED_TREES as u32,
            logic_share: 0.6,
            device_share: 0.8,
        }
    }
}

/// The banked store and the datapaths for one map on one device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BankPlan {
    pub photons: usize,
    /// `L`.
    pub replicated_levels: u32,
    /// `b` (`B = 2^b`).
    pub bank_bits: u32,
    /// Words per bank and BlockRAMs per bank (one column: wide enough for a word).
    pub bank_rows: u32,
    pub brams_per_bank: u32,
    /// `D`.
    pub datapaths: u32,
    /// How the banks' ports are shared (with banks).
    pub ports: BankPorts,
    /// BlockRAMs of the banks, of the datapaths (replicas and own memories).
    pub bank_brams: u32,
    pub datapath_brams: u32,
    /// Logic of the datapaths and of the crossbar (the device's estimates).
    pub datapath_luts: u64,
    pub crossbar_luts: u64,
}

impl BankPlan {
    pub fn banks(&self) -> u32 {
        1 << self.bank_bits
    }
    pub fn total_brams(&self) -> u32 {
        self.bank_brams + self.datapath_brams
    }
}

/// Why no plan exists.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlanError {
    /// The photon word is wider than one BlockRAM port.
    WordTooWide { bits: u32, device: &'static str },
    /// The map does not fit; the largest that does (0: none).
    MapTooLarge {
        photons: usize,
        device: &'static str,
        largest: usize,
    },
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::WordTooWide { bits, device } => {
                write!(
                    f,
                    "a {bits}-bit photon word is wider than a {device} BlockRAM"
                )
            }
            PlanError::MapTooLarge {
                photons,
                device,
                largest,
            } => write!(
                f,
                "a map of {photons} photons does not fit the {device} with the banks and \
                 datapaths it needs; the largest that fits is {largest} photons"
            ),
        }
    }
}

/// The plan for `photons` photons of `word_bits` bits on `dev`, each datapath
/// with `own_brams` BlockRAMs of its own ([`datapath_brams`]).
pub fn plan(
    photons: usize,
    word_bits: u32,
    own_brams: u32,
    dev: &Device,
    lim: &Limits,
) -> Result<BankPlan, PlanError> {
    if word_bits > dev.shape.1 {
        return Err(PlanError::WordTooWide {
            bits: word_bits,
            device: dev.name,
        });
    }
    plan_fit(photons, own_brams, dev, lim).ok_or_else(|| PlanError::MapTooLarge {
        photons,
        device: dev.name,
        largest: largest_map(own_brams, dev, lim),
    })
}

/// The best plan for `photons` (see the module docs), if any: the most
/// datapaths, then the fewest BlockRAMs, then the most banks.
fn plan_fit(photons: usize, own_brams: u32, dev: &Device, lim: &Limits) -> Option<BankPlan> {
    let depth = dev.shape.0;
    // 2^L − 1 <= depth.
    let l = 31 - (depth + 1).leading_zeros();
    let per_dp = 1 + own_brams;
    let budget = dev.luts as f64 * lim.logic_share;
    let dp_luts = |d: u32| u64::from(d) * u64::from(dev.costs().datapath_luts);
    if photons < (1usize << l) {
        // Every node is in every datapath's replica: no banks, no crossbar (an
        // array of whole cores, at most MAX_TREES).
        let by_logic = (budget / f64::from(dev.costs().datapath_luts)) as u32;
        let d = (dev.brams / per_dp)
            .min(by_logic)
            .min(lim.max_datapaths)
            .min(2 * MAX_TREES as u32);
        return (d >= lim.min_datapaths.max(1)).then_some(BankPlan {
            photons,
            replicated_levels: l,
            bank_bits: 0,
            bank_rows: 0,
            brams_per_bank: 0,
            datapaths: d,
            ports: BankPorts::default(),
            bank_brams: 0,
            datapath_brams: d * per_dp,
            datapath_luts: dp_luts(d),
            crossbar_luts: 0,
        });
    }
    let max_b = (1u32 << l).min(lim.max_banks);
    let mut best: Option<BankPlan> = None;
    for b in 0..=(31 - max_b.leading_zeros()) {
        let banks = 1u32 << b;
        let rows = (photons as u64 >> b) + 1;
        let per_bank = rows.div_ceil(depth as u64);
        let bank_brams = per_bank * banks as u64;
        if bank_brams + u64::from(lim.min_datapaths * per_dp) > u64::from(dev.brams) {
            continue;
        }
        let by_bram = (dev.brams - bank_brams as u32) / per_dp;
        let by_banks = banks / lim.banks_per_datapath.max(1);
        for ports in [BankPorts::Shared, BankPorts::Split] {
            // The most datapaths (an even number: two a replica) whose logic and
            // crossbar fit the budget.
            let mut d = by_bram.min(by_banks).min(lim.max_datapaths) & !1;
            let logic = |d: u32| dp_luts(d) + dev.crossbar_luts(d, banks, ports);
            while d > 0 && logic(d) as f64 > budget {
                d -= 2;
            }
            if d < lim.min_datapaths.max(1) {
                continue;
            }
            let p = BankPlan {
                photons,
                replicated_levels: l,
                bank_bits: b,
                bank_rows: rows as u32,
                brams_per_bank: per_bank as u32,
                datapaths: d,
                ports,
                bank_brams: bank_brams as u32,
                datapath_brams: d * per_dp,
                datapath_luts: dp_luts(d),
                crossbar_luts: dev.crossbar_luts(d, banks, ports),
            };
            let key = |p: &BankPlan| {
                (
                    p.datapaths,
                    std::cmp::Reverse(p.bank_brams),
                    p.bank_bits,
                    p.ports == BankPorts::Shared,
                )
            };
            if best.as_ref().is_none_or(|q| key(&p) > key(q)) {
                best = Some(p);
            }
        }
    }
    best
}

/// The largest photon count [`plan`] fits on `dev` with `own_brams` a datapath
/// (0 if none).
pub fn largest_map(own_brams: u32, dev: &Device, lim: &Limits) -> usize {
    if plan_fit(1, own_brams, dev, lim).is_none() {
        return 0;
    }
    let (mut lo, mut hi) = (1usize, 1usize << 28);
    // plan_fit holds for lo, fails for hi.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if plan_fit(mid, own_brams, dev, lim).is_some() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The external-memory core for a map the BlockRAM cannot hold (docs/MEMORY_CORE.md):
/// the top levels in every replica as above, the levels below in the board's DRAM
/// behind a cache in the BlockRAM the datapaths leave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryPlan {
    pub photons: usize,
    /// `T`: the levels every replica holds (one BlockRAM's words).
    pub replicated_levels: u32,
    /// Cache banks `2^bank_bits`, their lines in all, and the BlockRAMs they take.
    pub bank_bits: u32,
    pub cache_lines: u32,
    pub cache_brams: u32,
    /// `D`, their BlockRAMs (replicas and own memories) and logic, and the
    /// crossbar's logic (split ports).
    pub datapaths: u32,
    pub datapath_brams: u32,
    pub datapath_luts: u64,
    pub crossbar_luts: u64,
    /// The memory's data width: the default (two photon words a beat) unless
    /// only a narrower port's cache fits.
    pub memory_data_bits: u32,
    /// Where the banks keep their tags: BlockRAM, unless only LUT-RAM tags leave
    /// the words BlockRAM for these lines.
    pub cache_tags: CacheTags,
}

/// Largest map of an external-memory core: [`MAX_MEMORY_ADDRESS_BITS`] (every
/// modelled board's DRAM holds that many 32-bit words many times over).
pub const MEMORY_MAP_LIMIT: usize = (1 << MAX_MEMORY_ADDRESS_BITS) - 1;

/// BlockRAMs of a cache of `lines` lines of `2^s` words over `2^b` banks, its
/// RAM words a memory beat of `beat_words` photon words in `lane_bits`-bit lanes
/// (`CachePort`: a 64-bit beat of two words is one 64-bit RAM word, two DP16KD
/// wide however few the lines): with split ports each port has its own copy of
/// the words and of the tags (a bank's lines' tags, BlockRAM from 64 lines up).
fn cache_brams(
    dev: &Device,
    lines: u32,
    b: u32,
    beat_words: u32,
    lane_bits: u32,
    tags: CacheTags,
) -> u32 {
    let per_bank = lines >> b;
    let rows = (per_bank << MEMORY_BLOCK_LEVELS) / beat_words;
    let words = dev
        .brams_for(rows.trailing_zeros(), beat_words * lane_bits)
        .max(1);
    let tags = match tags {
        CacheTags::BlockRam => dev.brams_for(per_bank.trailing_zeros(), TAG_BITS),
        CacheTags::LutRam => 0,
    };
    (2 * (words + tags)) << b
}

/// Logic of an external-memory core of `d` datapaths with `lines` cache lines
/// over `2^b` banks, their tags in `tags`: the datapaths, the split-port
/// crossbar, the cache and the rest of the core.
fn cache_logic(dev: &Device, d: u32, lines: u32, b: u32, tags: CacheTags) -> f64 {
    let c = dev.costs();
    let (datapaths, crossbar) = memory_datapath_logic(dev, d, 1 << b);
    let line = match tags {
        CacheTags::BlockRam => c.cache_line_luts,
        CacheTags::LutRam => c.cache_line_luts + c.cache_lut_tag_luts,
    };
    (datapaths + crossbar) as f64
        + c.cache_bank_luts * f64::from(1u32 << b)
        + line * f64::from(lines)
        + f64::from(c.memory_rest_luts)
}

/// The logic of an external-memory core's `d` datapaths and of their crossbar
/// over `banks` cache banks (split ports).
fn memory_datapath_logic(dev: &Device, d: u32, banks: u32) -> (u64, u64) {
    let c = dev.costs();
    let crossbar = c.memory_crossbar_luts * f64::from(d) * f64::from(banks);
    (
        u64::from(d * c.memory_datapath_luts),
        crossbar.ceil() as u64,
    )
}

/// The external-memory core for `photons` photons of `word_bits` bits on `dev`,
/// each datapath with `own_brams` BlockRAMs of its own: the most datapaths (two a replica, at most `2^b / banks_per_datapath` for `2^b`
/// cache banks, within the logic budget beside a split-port crossbar), then the
/// most cache lines the BlockRAM left and the logic budget hold (a line's state
/// bits cost [`DeviceCosts::cache_line_luts`]; a power of two, at most 256 a bank and
/// 4,096 in all: `ExternalMemory::check`); refused only for a map beyond
/// [`MEMORY_MAP_LIMIT`] or a word the cache cannot flag.
pub fn plan_memory(
    photons: usize,
    word_bits: u32,
    own_brams: u32,
    dev: &Device,
    lim: &Limits,
) -> Result<MemoryPlan, PlanError> {
    let too_large = PlanError::MapTooLarge {
        photons,
        device: dev.name,
        largest: MEMORY_MAP_LIMIT,
    };
    // The cache's words carry a miss flag above the photon word.
    if word_bits >= dev.shape.1 {
        return Err(PlanError::WordTooWide {
            bits: word_bits,
            device: dev.name,
        });
    }
    if photons > MEMORY_MAP_LIMIT {
        return Err(too_large);
    }
    // The default memory width unless a 32-bit port's cache (one word a RAM word,
    // half the BlockRAM width) holds more lines beside as many datapaths.
    let lane_bits = if word_bits <= 32 { 32 } else { 64 };
    [DEFAULT_MEMORY_DATA_BITS, 32]
        .into_iter()
        .filter(|&bits| bits >= lane_bits)
        .filter_map(|bits| {
            plan_memory_width(photons, own_brams, dev, lim, bits / lane_bits, lane_bits)
        })
        .max_by_key(|p| (p.datapaths, p.cache_lines, p.memory_data_bits))
        .ok_or(too_large)
}

/// [`plan_memory`] with `beat_words` photon words of `lane_bits` a memory beat.
fn plan_memory_width(
    photons: usize,
    own_brams: u32,
    dev: &Device,
    lim: &Limits,
    beat_words: u32,
    lane_bits: u32,
) -> Option<MemoryPlan> {
    let cache_brams =
        |lines: u32, b: u32, tags| cache_brams(dev, lines, b, beat_words, lane_bits, tags);
    let l = 31 - (dev.shape.0 + 1).leading_zeros();
    let per_dp = 1 + own_brams;
    let budget = dev.luts as f64 * lim.logic_share;
    let mut best: Option<MemoryPlan> = None;
    for b in 1..=MAX_CACHE_BANK_BITS {
        let banks = 1u32 << b;
        let logic = |d: u32| {
            let (datapaths, crossbar) = memory_datapath_logic(dev, d, banks);
            datapaths + crossbar
        };
        let mut d = (banks / lim.banks_per_datapath.max(1)).min(lim.max_datapaths) & !1;
        while d > 0 && logic(d) as f64 > budget {
            d -= 2;
        }
        // The largest cache beside the datapaths, from one line a bank up.
        // ... in the BlockRAM left, and with its logic in the device's: the tags
        // in BlockRAM, else (where the words alone would fit) in LUT-RAM.
        let fits = |lines: u32| {
            [CacheTags::BlockRam, CacheTags::LutRam]
                .into_iter()
                .find(|&t| {
                    cache_brams(lines, b, t) + d * per_dp <= dev.brams
                        && cache_logic(dev, d, lines, b, t) <= dev.luts as f64 * lim.device_share
                })
        };
        let mut lines = banks;
        let Some(mut tags) = fits(lines).filter(|_| d >= lim.min_datapaths.max(1)) else {
            continue;
        };
        while lines * 2 <= ((MAX_BANK_LINES as u32) << b).min(MAX_CACHE_LINES) {
            let Some(t) = fits(lines * 2) else { break };
            lines *= 2;
            tags = t;
        }
        let (datapath_luts, crossbar_luts) = memory_datapath_logic(dev, d, banks);
        let p = MemoryPlan {
            photons,
            replicated_levels: l,
            bank_bits: b,
            cache_lines: lines,
            cache_brams: cache_brams(lines, b, tags),
            datapaths: d,
            datapath_brams: d * per_dp,
            datapath_luts,
            crossbar_luts,
            memory_data_bits: beat_words * lane_bits,
            cache_tags: tags,
        };
        let key = |p: &MemoryPlan| (p.datapaths, p.cache_lines, std::cmp::Reverse(p.bank_bits));
        if best.as_ref().is_none_or(|q| key(&p) > key(q)) {
            best = Some(p);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::config::core_config::CoreConfig;
    use crate::hw::config::core_spec::CoreSpec;

    /// The default core (K = 32) with `k` photons a query, for a map of `h`
    /// address bits.
    fn core(k: usize, h: u32) -> CoreConfig {
        let mut c = CoreConfig::builder()
            .with_spec(&CoreSpec::default_core())
            .unwrap()
            .k(k)
            .address_bits(20)
            .build()
            .unwrap();
        c.address_bits = h;
        c
    }

    /// A datapath's BlockRAMs as the synthesised netlists have them (DP16KD cells
    /// counted by instance in the external-memory cores of synth/REPORT.md, H =
    /// 21): at K = 32 two each for the even and odd found lists and the two
    /// far-cell memories; at K = 500 six for each found list, 16 for the heap's
    /// levels and the same four. The device constants the lab uses agree.
    #[test]
    fn a_datapaths_blockrams_are_the_synthesised_ones() {
        assert_eq!(datapath_brams(&ECP5_85K, &core(32, 21)), 8);
        assert_eq!(datapath_brams(&ECP5_85K, &core(500, 21)), 6 + 6 + 16 + 4);
        assert_eq!(
            datapath_brams(&ECP5_85K, &core(32, 21)),
            ECP5_85K.datapath_brams
        );
        assert_eq!(
            datapath_brams(&XC6VSX475T, &core(32, 21)),
            XC6VSX475T.datapath_brams
        );
    }

    /// At K = 500 the paper's map on the ECP5-85k keeps K = 32's 1,024 lines only
    /// with the tags in LUT-RAM (the heaps take BlockRAM), and the plan fits the
    /// device's BlockRAM: four datapaths of 32 DP16KD and their replicas (132),
    /// and 16 banks' two copies of the words, a 64-bit RAM word two DP16KD wide at
    /// any depth up to 512 beats: 64. With the tags in BlockRAM (a DP16KD a copy
    /// from 64 lines a bank up) 1,024 lines take 96, 228 in all (the synthesised
    /// core that did not fit); at K = 32 the tags stay in BlockRAM.
    #[test]
    fn a_k500_memory_plan_leaves_the_heaps_their_blockram() {
        let lim = Limits::default();
        let own = datapath_brams(&ECP5_85K, &core(500, 21));
        let p = plan_memory(1_945_886, 32, own, &ECP5_85K, &lim).unwrap();
        assert!(
            p.cache_brams + p.datapaths * (1 + own) <= ECP5_85K.brams,
            "{p:?}"
        );
        assert_eq!(
            (
                p.datapaths,
                p.bank_bits,
                p.cache_lines,
                p.cache_brams,
                p.memory_data_bits,
                p.cache_tags
            ),
            (4, 4, 1024, 64, 64, CacheTags::LutRam)
        );
        assert_eq!(
            cache_brams(&ECP5_85K, 1024, 4, 2, 32, CacheTags::BlockRam),
            96
        );
        let at32 = plan_memory(1_945_886, 32, ECP5_85K.datapath_brams, &ECP5_85K, &lim).unwrap();
        assert_eq!(
            (at32.cache_lines, at32.cache_tags),
            (1024, CacheTags::BlockRam)
        );
    }

    /// The paper's 1 M-photon map on each device: a plan that fits the BlockRAM,
    /// a cache twice as large that would not, and a map one photon beyond the
    /// 24-bit addresses refused with the largest named.
    #[test]
    fn a_map_beyond_the_blockram_gets_the_largest_cache_that_fits() {
        let lim = Limits::default();
        for dev in [ECP5_85K, XC6VSX475T] {
            let p = plan_memory(1_945_886, 32, dev.datapath_brams, &dev, &lim).unwrap();
            assert!(
                plan(1_945_886, 32, dev.datapath_brams, &dev, &lim).is_err(),
                "{}",
                dev.name
            );
            assert!(p.datapaths >= lim.min_datapaths && p.datapaths.is_multiple_of(2));
            assert_eq!(1u32 << p.replicated_levels, dev.shape.0);
            // Words: two copies (split ports) of every line's 16 words, two a
            // 64-bit RAM word, in BlockRAMs of shape.0 words of shape.1 bits a
            // bank, plus a tag BlockRAM a copy where a bank has more than 32
            // lines (fewer are LUT-RAM).
            assert_eq!(p.memory_data_bits, 64);
            let banks = 1u32 << p.bank_bits;
            let words_per_bank = p.cache_lines / banks * 16;
            let brams = |words: u32| {
                let wide = 64u32.div_ceil(dev.shape.1);
                let tags = u32::from(words / 16 > 32 && p.cache_tags == CacheTags::BlockRam);
                2 * banks * (wide * (words / 2).div_ceil(dev.shape.0) + tags)
            };
            assert_eq!(p.cache_brams, brams(words_per_bank));
            assert!(p.cache_brams + p.datapath_brams <= dev.brams, "{p:?}");
            // Logic: the datapaths, the crossbar, each bank's and each line's
            // state, the rest of the core.
            let budget = dev.luts as f64 * lim.device_share;
            let c = dev.costs();
            let logic = |lines: u32| {
                (p.datapath_luts + p.crossbar_luts) as f64
                    + f64::from(banks) * c.cache_bank_luts
                    + f64::from(lines) * c.cache_line_luts
                    + f64::from(c.memory_rest_luts)
            };
            assert!(logic(p.cache_lines) <= budget, "{p:?}");
            assert!(
                (p.datapath_luts + p.crossbar_luts) as f64 <= dev.luts as f64 * lim.logic_share
            );
            let doubled = brams(2 * words_per_bank) + p.datapath_brams > dev.brams
                || logic(2 * p.cache_lines) > budget;
            assert!(doubled || p.cache_lines == 4096 || p.cache_lines / banks == 256);
        }
        // The ECP5-85k's: the core docs/MEMORY_CORE.md measures.
        let e = plan_memory(1_945_886, 32, ECP5_85K.datapath_brams, &ECP5_85K, &lim).unwrap();
        assert_eq!(
            (e.datapaths, e.bank_bits, e.cache_lines, e.replicated_levels),
            (4, 4, 1024, 9)
        );
        let err = plan_memory(1 << 23, 32, ECP5_85K.datapath_brams, &ECP5_85K, &lim).unwrap_err();
        assert!(
            err.to_string().contains("the largest that fits is 8388607"),
            "{err}"
        );
    }
}
