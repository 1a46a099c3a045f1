//! `CoreConfig`: the elaboration-time parameters of the photon-search core (paper §4,
//! §5) and the fixed maximum widths of its datapath.
//!
//! rust-hdl's `Bits<N>` needs a constant width and stable Rust has no generic const
//! expressions, so the datapath types below have fixed *maximum* widths and the actual
//! widths (coordinate fields, split-axis offset, address bits, K, Q, metric) are
//! elaboration-time constants (`Constant<>` fields, `Vec` lengths, the TreeModule's
//! generated Verilog text). Every type is kept <= 32 bits because rust-hdl simulates
//! wider `Bits` much more slowly, except the slot masks and the photon word, which are
//! const generics that widen to 64 bits only for a configuration that needs it
//! ([`CoreConfig::slot_bits`], [`CoreConfig::word_width`], dispatched once by
//! [`dispatch_widths`]). The limits are checked by [`CoreConfig::validate`], which
//! returns an error instead of panicking.

use crate::hw::config::controller::Controller;
use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::{PhotonLayout, TreeImage};
use crate::hw::config::traversal::Traversal;
use crate::hw::error::HwError;
use rust_hdl::prelude::Bits;

/// Widest photon word the TreeModule port carries (paper: 30 coordinate bits + 2-bit
/// axis in 32; three 15-bit coordinates + axis = 47 bits in the wide word).
pub const MAX_WORD_BITS: u32 = 64;
/// Widest coordinate per axis: 15 bits keeps the squared-L2 distance of the widest
/// axis within the 32-bit distance path (the multiplier is rust-hdl's 16x16->32).
pub const MAX_HW_COORD_BITS: u32 = 15;
/// Widest distance (in the configured metric).
pub const MAX_DIST_BITS: u32 = 32;
/// Tree height H limit: 2^20 photon words, so a core holds at most 2^20 - 1 photons
/// (the photon limit of the hardware backends).
pub const MAX_ADDRESS_BITS: u32 = 20;
/// Found-list depth limit of the core (the barrel controller's: its found lists are
/// heaps in BlockRAM, [`FoundHeap`](crate::hw::barrel::found_heap::FoundHeap), 512 entries
/// being the paper's high-quality regime, §3: at least 500 search photons).
pub const MAX_K: usize = 512;
/// Found-list depth limit of the QueryModule controller: one bit per entry in a
/// MaxFinder row (§4.4), 64 bits wide at most, and Q rows per port; a row of hundreds
/// of bits per QueryModule would cost more logic than the whole core.
pub const MAX_K_MODULES: usize = 64;
/// Above this K a barrel port keeps its found lists as heaps in BlockRAM
/// ([`FoundHeap`](crate::hw::barrel::found_heap::FoundHeap)); up to it, as LUT-RAMs under a
/// comparator tree ([`FoundMax`](crate::hw::barrel::found_max::FoundMax)). At 64 entries the
/// two cost about the same logic (yosys xc6v), and the tree grows linearly with K
/// while the heap grows with log2 K; below it the tree is smaller.
pub const FOUND_TREE_MAX_K: usize = 64;
/// Bits of a found heap's key (see [`CoreConfig::heap_key_bits`]).
pub const HEAP_KEY_BITS: u32 = 32;

impl Controller {
    /// The deepest found list (K) the controller is built for.
    pub fn max_k(self) -> usize {
        match self {
            Controller::Modules => MAX_K_MODULES,
            Controller::Barrel => MAX_K,
        }
    }
}
/// Slot-mask widths the core is built with: 32 bits up to K = 32 (rust-hdl keeps
/// `Bits<=32>` in a machine word), 64 bits beyond (a bit vector, about 1.5x slower to
/// simulate). The choice is made once, by [`CoreConfig::slot_bits`].
pub const NARROW_SLOTS: usize = 32;
pub const WIDE_SLOTS: usize = 64;
/// Photon-word port widths, chosen the same way by [`CoreConfig::word_width`]: 32 bits
/// while the packed word fits (the paper's 3 x 10 + 2), 64 beyond (e.g. 12-bit
/// coordinates, a 38-bit word). The BlockRAM itself is always exactly as wide as the
/// layout's word (see `TreeModule`).
pub const NARROW_WORD: usize = 32;
pub const WIDE_WORD: usize = 64;
/// Q limit, QueryModules or query slots per port (one bit per module or slot in the
/// 32-bit arbiter and slot masks).
pub const MAX_QUERIES_PER_PORT: usize = 32;
/// TreeModule ports = SearchModules (paper §4.5: both BlockRAM ports are used).
pub const PORTS: usize = 2;
/// Query slots of a [`Controller::Barrel`] port: a slot reads every 11 cycles (seven
/// pipeline stages and the SearchModule's four), so 11 keep the port busy; 16 cost
/// the same LUT-RAM (an ECP5 DPR16X4 holds 16 entries, a Virtex-6 RAM32M 32).
pub const BARREL_SLOTS: usize = 16;
/// Replicated trees limit (`PhotonSearchArray`): four already exceed the largest
/// ECP5, and one bit per tree fits the arbiter masks.
pub const MAX_TREES: usize = 8;
/// Replicas of the top levels in a banked core: two datapaths each, and one bit per
/// datapath in the crossbar's 32-bit request and grant masks.
pub const MAX_BANKED_TREES: usize = 16;
/// Most result streams of one core (at most one per datapath).
pub const MAX_RESULT_STREAMS: usize = 16;

/// Photon word as carried on a TreeModule port; `W` is [`NARROW_WORD`] or [`WIDE_WORD`].
pub type Word<const W: usize> = Bits<W>;
/// One coordinate (16 bits so that the L2 square uses the 16x16->32 multiplier).
pub type Coord = Bits<16>;
/// A distance in the configured metric.
pub type Dist = Bits<32>;
/// A heap address; 24 bits hold the child address 2i+1 of any i < 2^20.
pub type Addr = Bits<24>;
/// One bit per found-list slot (MaxFinder rows, filter, one-hot slot pointers);
/// `S` is [`NARROW_SLOTS`] or [`WIDE_SLOTS`].
pub type SlotMask<const S: usize> = Bits<S>;
/// One bit per QueryModule of a port (arbiter masks).
pub type ModuleMask = Bits<32>;
/// The host's query id, returned with the result.
pub type QueryId = Bits<32>;
/// Found-list counts and k (0..=K, K <= [`MAX_K`]).
pub type Count = Bits<16>;
/// A found-list entry index (0..K).
pub type Entry = Bits<16>;
/// Index of a QueryModule within its port (carried through the SearchModule).
pub type ModuleIndex = Bits<8>;
/// Photons read by one query.
pub type ReadCount = Bits<32>;
/// One bit per tree level (the root is bit 0; H <= 20 levels): a QueryModule's
/// one-hot current level and its pending far children (`Traversal::Remember`).
pub type LevelMask = Bits<32>;

/// What a query stream costs the QueryModules, summed over a sample of queries as
/// the software search counts it (`knn::Found`): photon reads, MaxFinder runs,
/// levels climbed without a read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadProfile {
    pub reads: u64,
    pub max_finds: u64,
    pub climbs: u64,
}

impl std::iter::Sum for ReadProfile {
    fn sum<I: Iterator<Item = ReadProfile>>(iter: I) -> Self {
        iter.fold(ReadProfile::default(), |a, b| ReadProfile {
            reads: a.reads + b.reads,
            max_finds: a.max_finds + b.max_finds,
            climbs: a.climbs + b.climbs,
        })
    }
}

/// Elaboration-time parameters of one core. Made and checked by
/// [`CoreBuilder`](crate::hw::config::config_builder::CoreBuilder) (`CoreConfig::builder()`,
/// `CoreConfig::paper()`, `CoreConfig::for_map`): a combination the datapath cannot
/// build is refused there, naming the option and its value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoreConfig {
    /// Per-axis coordinate widths and the packed word layout.
    pub layout: PhotonLayout,
    /// Address bits H: the TreeModule holds 2^H words, addresses 1..2^H-1 usable.
    pub address_bits: u32,
    /// Found-list depth K: the largest k a query may ask for.
    pub k: usize,
    /// Q, the queries one TreeModule port runs at once. With [`Controller::Modules`]
    /// it is the number of QueryModules per port (each its own controller,
    /// MaxFinder and found list, paper §4.2); with [`Controller::Barrel`] the number
    /// of query slots per port (entries of the slot memories behind the port's one
    /// datapath). One name for both: `CoreBuilder::queries_per_port`.
    pub queries_per_port: usize,
    /// Distance metric of DistModule (the full and the split-axis distance).
    pub metric: Metric,
    /// Pipeline registers that shorten the critical paths, each one cycle of latency:
    /// the BlockRAM's read data (SearchModule stage W) and each SearchPort's result
    /// stream (a ResultRegister skid buffer). `false` builds the unpipelined core, for
    /// before/after timing.
    pub pipelined: bool,
    /// Replicated trees T (the paper's future work): 1 builds the core itself, T > 1 a
    /// `PhotonSearchArray` of T cores, each with its own copy of the map.
    pub trees: usize,
    /// How a QueryModule climbs back up the tree: remembering each level's axis
    /// distance (no reads), the paper's re-read of every parent, or remembering the
    /// distance to each level's far cell (`Traversal::Cell`).
    pub traversal: Traversal,
    /// Who runs a port's queries: Q QueryModules (the paper's) or Q slots of one
    /// shared datapath ([`Controller::Barrel`]).
    pub controller: Controller,
    /// `None`: each tree is a TreeModule holding the whole map. Some: one map in
    /// a banked store shared by every datapath ([`Banking`]).
    pub banking: Option<Banking>,
    /// Result streams R: the datapaths' result packets leave on R streams, each
    /// the merge of D / R consecutive datapaths (a replica's two together). One
    /// stream carries one beat a cycle; a packet is 1 + k/2 beats, so D barrel
    /// datapaths at k = 32 and nearly a read a cycle each fill one stream from D = 8
    /// on (docs/HARDWARE.md).
    pub result_streams: usize,
    /// `None`: distances are as wide as the grid's diagonal in the metric. `Some(b)`:
    /// the core is built for initial radii below `2^b − 1` (a scene's largest gather
    /// radius, "model only what the scene needs"): found lists, bounds and stored
    /// distances are `b` bits wide, and a bound that does not fit saturates at
    /// `2^b − 1`. Every comparison the search makes is against R, which never
    /// exceeds the initial radius, so a saturated bound prunes exactly as the true
    /// one would, and the in-range test sees the whole distance (docs/HARDWARE.md,
    /// "Distance width").
    pub radius_bits: Option<u32>,
    /// `None`: the map is on chip. `Some`: with banks, the levels below the
    /// replicas live in external memory and the banks are their cache
    /// ([`ExternalMemory`]), read through the core's AXI4 master.
    pub memory: Option<ExternalMemory>,
}

pub use crate::hw::config::bank_config::{BankMapping, Banking, MAX_BANK_BITS};
pub use crate::hw::config::memory_config::ExternalMemory;

impl CoreConfig {
    /// Largest distance two photons of this layout can have.
    pub fn max_dist(&self) -> u64 {
        self.metric.max_dist(self.layout.bits)
    }

    /// Cycles between two reads of one QueryModule in the worst case (an insertion
    /// that runs the MaxFinder): (pipelined: the registered grant,) grant, BlockRAM
    /// read, (pipelined: the read-data register,) two SearchModule stages, the
    /// insertion cycle, the MaxFinder's priming cycle and one cycle per distance
    /// bit, the update of R.
    pub fn issue_interval(&self) -> usize {
        6 + 2 * self.pipelined as usize + self.dist_bits() as usize
    }

    /// A QueryModule's mean cycles per photon read on a query stream whose software
    /// search made `profile`'s reads, MaxFinder runs and climbs: the read's round
    /// trip (grant, BlockRAM, read-data register, two SearchModule stages, the
    /// insertion cycle: the issue interval without the MaxFinder), plus one cycle
    /// per distance bit and one for R per MaxFinder run, plus one per level climbed.
    pub fn mean_read_interval(&self, profile: &ReadProfile) -> f64 {
        let round_trip = (self.issue_interval() - self.dist_bits() as usize - 1) as f64;
        let reads = profile.reads.max(1) as f64;
        round_trip
            + (profile.max_finds as f64 * (self.dist_bits() + 2) as f64 + profile.climbs as f64)
                / reads
    }

    /// Right-sized Q ("model only what the scene needs"): enough QueryModules that a port still reads a
    /// photon nearly every cycle on this stream — the mean read interval with 25 %
    /// slack for the queueing at the arbiter (the lab's throughput tests hold a port
    /// to nearly a read per cycle with it), never more than the worst-case issue
    /// interval.
    pub fn fit_queries_per_port(&mut self, profile: &ReadProfile) {
        if self.controller == Controller::Barrel {
            self.queries_per_port = BARREL_SLOTS;
            return;
        }
        let q = (1.25 * self.mean_read_interval(profile)).ceil() as usize;
        self.queries_per_port = q.clamp(2, self.issue_interval().min(MAX_QUERIES_PER_PORT));
    }

    /// Entries of a QueryModule's path memory: one per level that can have children
    /// (H - 1 levels below the leaves) when the traversal remembers the path, none
    /// with `Traversal::Reread`.
    pub fn path_levels(&self) -> usize {
        if self.traversal.remembers() {
            self.address_bits as usize - 1
        } else {
            0
        }
    }

    /// Width of the slot masks this K needs: [`NARROW_SLOTS`] or [`WIDE_SLOTS`].
    pub fn slot_bits(&self) -> usize {
        if self.k <= NARROW_SLOTS {
            NARROW_SLOTS
        } else {
            WIDE_SLOTS
        }
    }

    /// Width of the photon-word ports this layout needs: [`NARROW_WORD`] or [`WIDE_WORD`].
    pub fn word_width(&self) -> usize {
        if self.layout.word_bits() as usize <= NARROW_WORD {
            NARROW_WORD
        } else {
            WIDE_WORD
        }
    }

    /// Total QueryModules (all trees).
    pub fn query_modules(&self) -> usize {
        self.trees * PORTS * self.queries_per_port
    }

    /// Query-id bits the core keeps (only what the scene needs): the
    /// host tags queries from a pool of `2^id_bits` tags, twice the queries that can
    /// be in flight (one per QueryModule, plus up to two result beats held in each
    /// port's ResultRegister after its QueryModule was freed). The core returns the
    /// low `id_bits` of the id it was given.
    pub fn id_bits(&self) -> u32 {
        let in_flight = self.query_modules() + 2 * PORTS * self.trees;
        bits_for(2 * in_flight as u64).min(32)
    }

    /// Bits of a found-list count or k (0..=K).
    pub fn count_bits(&self) -> u32 {
        bits_for(self.k as u64)
    }

    /// Bits of a query's photon-read count: at most 2N − 1 reads (every node read
    /// on the way down and, with re-reads, once more on the way up), N < 2^H.
    pub fn visited_bits(&self) -> u32 {
        self.address_bits + 1
    }

    /// Bits of a QueryModule's index within its port.
    pub fn module_bits(&self) -> u32 {
        bits_for(self.queries_per_port.saturating_sub(1) as u64).max(1)
    }

    /// Photon words the map may hold (the banked store holds as many).
    pub fn tree_words(&self) -> usize {
        1 << self.address_bits
    }

    /// Address bits of each TreeModule: the whole map's H, or with banks the
    /// replicated levels L.
    pub fn tree_address_bits(&self) -> u32 {
        self.banking
            .map_or(self.address_bits, |b| b.replicated_levels)
    }

    /// How a banked node picks its bank (the default without banks).
    pub fn bank_mapping(&self) -> crate::hw::config::bank_config::BankMapping {
        self.banking.map(|b| b.mapping).unwrap_or_default()
    }

    /// Where the map's nodes live when it is in external memory: the replicated
    /// levels on chip, blocks of the cache's levels below.
    pub fn memory_layout(&self) -> Option<crate::hw::config::memory_layout::MemoryLayout> {
        let (m, b) = self.memory.zip(self.banking)?;
        crate::hw::config::memory_layout::MemoryLayout::new(
            self.address_bits,
            b.replicated_levels,
            m.block_levels,
        )
        .ok()
    }

    /// TreeModule ports, one datapath each: two per tree.
    pub fn datapaths(&self) -> usize {
        PORTS
            * if self.banking.is_some() {
                self.trees
            } else {
                1
            }
    }

    /// T > 1 without banks: a `PhotonSearchArray` of whole cores (with banks the
    /// trees are replicas inside one core, sharing its banks).
    pub fn is_array(&self) -> bool {
        self.trees > 1 && self.banking.is_none()
    }

    /// Check every limit of the fixed-width datapath (`CoreBuilder::build` does; for
    /// a configuration changed field by field since).
    pub fn validate(&self) -> Result<(), HwError> {
        let b = self.layout.bits;
        if b.iter().any(|&w| w == 0 || w > MAX_HW_COORD_BITS) {
            return Err(HwError::Config(format!(
                "layout bits = {b:?}: coordinate widths unsupported (1..={MAX_HW_COORD_BITS} bits per axis)"
            )));
        }
        if self.layout.word_bits() > MAX_WORD_BITS {
            return Err(HwError::Config(format!(
                "layout bits = {b:?}: a photon word of {} bits exceeds the {MAX_WORD_BITS}-bit \
                 TreeModule word",
                self.layout.word_bits()
            )));
        }
        if let Some(r) = self.radius_bits {
            if r == 0 || r > self.full_dist_bits() {
                return Err(HwError::Config(format!(
                    "radius_bits = {r} unsupported: 1..={} ({} metric on coordinate widths \
                     {b:?})",
                    self.full_dist_bits(),
                    self.metric
                )));
            }
        }
        if self.full_dist_bits() > MAX_DIST_BITS {
            return Err(HwError::Config(format!(
                "metric = {} on coordinate widths {b:?}: distances need {} bits, the \
                 datapath has {MAX_DIST_BITS}",
                self.metric,
                self.full_dist_bits()
            )));
        }
        if let Some(m) = self.memory {
            let Some(b) = self.banking else {
                return Err(HwError::Config(format!(
                    "cache_lines = {} without banks: the cache is the banked store's banks",
                    m.cache_lines
                )));
            };
            m.check(b.bank_bits, self.address_bits, self.word_width())?;
            if self.layout.word_bits() >= MAX_WORD_BITS {
                return Err(HwError::Config(format!(
                    "coordinate widths {b:?} with external memory: a {}-bit photon word leaves no \
                     bit for the cache's miss flag (below {MAX_WORD_BITS})",
                    self.layout.word_bits(),
                    b = self.layout.bits
                )));
            }
        } else if self.address_bits == 0 || self.address_bits > MAX_ADDRESS_BITS {
            return Err(HwError::Config(format!(
                "address_bits (H) = {} unsupported (1..={MAX_ADDRESS_BITS}, at most {} photons)",
                self.address_bits,
                (1u64 << MAX_ADDRESS_BITS) - 1
            )));
        }
        let max_k = self.controller.max_k();
        if self.k == 0 || self.k > max_k {
            return Err(HwError::Config(format!(
                "K = {} unsupported by the {} controller (1..={max_k})",
                self.k, self.controller
            )));
        }
        if self.uses_found_heap() && self.heap_key_bits() > HEAP_KEY_BITS {
            return Err(HwError::Config(format!(
                "K = {} with {}-bit distances ({} metric on coordinate widths {b:?}): a found \
                 heap's key is the distance and a {}-bit entry index, {} bits, more than its \
                 {HEAP_KEY_BITS} (fewer coordinate bits, or K <= {FOUND_TREE_MAX_K})",
                self.k,
                self.dist_bits(),
                self.metric,
                self.entry_bits(),
                self.heap_key_bits()
            )));
        }
        let max_trees = if self.banking.is_some() {
            MAX_BANKED_TREES
        } else {
            MAX_TREES
        };
        if self.trees == 0 || self.trees > max_trees {
            let what = if self.banking.is_some() {
                "replicas of the top levels with banks"
            } else {
                "replicated trees"
            };
            return Err(HwError::Config(format!(
                "trees = {}: {what} unsupported (1..={max_trees})",
                self.trees
            )));
        }
        if self.queries_per_port == 0 || self.queries_per_port > MAX_QUERIES_PER_PORT {
            let what = match self.controller {
                Controller::Modules => "QueryModules",
                Controller::Barrel => "query slots",
            };
            return Err(HwError::Config(format!(
                "queries_per_port = {} unsupported (1..={MAX_QUERIES_PER_PORT} {what} per port)",
                self.queries_per_port
            )));
        }
        if self.controller == Controller::Barrel && !self.traversal.remembers() {
            return Err(HwError::Config(format!(
                "traversal = {} with controller barrel: the barrel controller needs a traversal \
                 that remembers the path (remember, cell)",
                self.traversal
            )));
        }
        if let Some(b) = self.banking {
            b.check(self.controller, self.address_bits, self.memory.is_some())?;
        }
        let (r, d) = (self.result_streams, self.datapaths());
        if self.is_array() && r != 1 {
            return Err(HwError::Config(format!(
                "result_streams = {r} with trees = {} and no banks: an array of whole cores \
                 has one result stream (banks give the trees' datapaths their own)",
                self.trees
            )));
        }
        if r == 0 || r > d || r > MAX_RESULT_STREAMS || !d.is_multiple_of(r) {
            return Err(HwError::Config(format!(
                "result_streams = {r} unsupported: the {d} datapaths split evenly over 1..={} \
                 streams (a divisor of {d})",
                d.min(MAX_RESULT_STREAMS)
            )));
        }
        Ok(())
    }

    /// Check that `tree` fits this core (layout and photon count).
    pub fn check_map(&self, tree: TreeImage<'_>) -> Result<(), HwError> {
        if tree.layout != self.layout {
            return Err(HwError::Config(format!(
                "map layout {:?} differs from the core's {:?}",
                tree.layout.bits, self.layout.bits
            )));
        }
        if tree.is_empty() {
            return Err(HwError::Config("empty photon map".into()));
        }
        if tree.len() >= self.tree_words() {
            return Err(HwError::Config(format!(
                "{} photons do not fit {} address bits (at most {})",
                tree.len(),
                self.address_bits,
                self.tree_words() - 1
            )));
        }
        Ok(())
    }
}

/// Bits needed to hold `x` (at least 1).
pub fn bits_for(x: u64) -> u32 {
    (u64::BITS - x.leading_zeros()).max(1)
}

/// The low `bits` bits set.
pub fn low_mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// Call the generic `$f::<S, W>($args)` with the slot-mask width `S` and photon-word
/// width `W` that `$cfg` needs ([`CoreConfig::slot_bits`], [`CoreConfig::word_width`]):
/// the one place where a configuration picks its monomorphised core.
#[macro_export]
macro_rules! dispatch_widths {
    ($cfg:expr, $f:ident ( $($arg:expr),* $(,)? )) => {{
        use $crate::hw::config::core_config::{NARROW_SLOTS, NARROW_WORD, WIDE_SLOTS, WIDE_WORD};
        match ($cfg.slot_bits() == NARROW_SLOTS, $cfg.word_width() == NARROW_WORD) {
            (true, true) => $f::<NARROW_SLOTS, NARROW_WORD>($($arg),*),
            (true, false) => $f::<NARROW_SLOTS, WIDE_WORD>($($arg),*),
            (false, true) => $f::<WIDE_SLOTS, NARROW_WORD>($($arg),*),
            (false, false) => $f::<WIDE_SLOTS, WIDE_WORD>($($arg),*),
        }
    }};
}
pub use dispatch_widths;

/// One line that names a core, the same wherever a core is described (export,
/// render and gather on a simulated core, the lab's bench-core): controller,
/// traversal, copies, H, K, Q per port under its name, the banked store, grid,
/// metric and distance width.
impl std::fmt::Display for CoreConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let q = match self.controller {
            Controller::Modules => "QueryModules",
            Controller::Barrel => "query slots",
        };
        write!(
            f,
            "{} controller, {} traversal, ",
            self.controller, self.traversal
        )?;
        match self.banking {
            // A banked core is one tree: its copies are replicas of the top levels.
            Some(b) => write!(
                f,
                "{} replica(s) of the top {} levels over {} banks ({}{})",
                self.trees,
                b.replicated_levels,
                1u64 << b.bank_bits,
                b.ports,
                match b.mapping {
                    BankMapping::Xor => "",
                    BankMapping::Modulo => ", bank = address mod B",
                }
            )?,
            None => write!(f, "T = {} tree(s)", self.trees)?,
        }
        // An array's trees are whole cores, each with its own two ports.
        let (ports, per_tree) = if self.is_array() {
            (PORTS, " per tree")
        } else {
            (self.datapaths(), "")
        };
        write!(
            f,
            ", H = {}, K = {}, {ports} x {} {q}{per_tree}",
            self.address_bits, self.k, self.queries_per_port
        )?;
        if let Some(m) = self.memory {
            let tags = m.tags.note();
            write!(
                f,
                ", the levels below in external memory ({}-bit beats) behind {} cache lines of \
                 {}-level blocks{}",
                m.data_bits, m.cache_lines, m.block_levels, tags
            )?;
        }
        if self.result_streams != 1 {
            write!(f, ", {} result streams", self.result_streams)?;
        }
        let [x, y, z] = self.layout.bits;
        if x == y && y == z {
            write!(f, ", {x}-bit coordinates")?;
        } else {
            write!(f, ", {x}/{y}/{z}-bit coordinates")?;
        }
        write!(
            f,
            ", {} metric, {}-bit distances",
            self.metric,
            self.dist_bits()
        )?;
        if !self.pipelined {
            write!(f, ", unpipelined")?;
        }
        Ok(())
    }
}
