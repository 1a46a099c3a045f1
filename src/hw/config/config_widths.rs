//! The widths a [`CoreConfig`] needs ("model only what the scene needs"): the
//! distance bits (the grid's diagonal, or a scene's largest radius with
//! [`CoreConfig::radius_bits`]) and the masks every register is loaded through.

use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::{bits_for, low_mask, CoreConfig, FOUND_TREE_MAX_K};

/// The width masks of the datapath's registers, one formula each, shared by both
/// controllers (QueryModule / SearchPort and BarrelPort / SlotStore / SlotReadout):
/// every register is loaded through the mask of the bits its configuration needs,
/// so synthesis drops the bits above (a flip-flop whose input is constant zero).
impl CoreConfig {
    /// Bits of a distance as the datapath keeps it: the grid's diagonal in the
    /// metric, or [`CoreConfig::radius_bits`].
    pub fn dist_bits(&self) -> u32 {
        self.radius_bits.unwrap_or_else(|| self.full_dist_bits())
    }

    /// Bits of the largest distance of this metric and layout (the grid's diagonal).
    pub fn full_dist_bits(&self) -> u32 {
        self.metric.dist_bits(self.layout.bits)
    }

    /// The largest initial radius (an inclusive bound in the metric) this core
    /// answers exactly: below the saturated distance with [`CoreConfig::radius_bits`],
    /// any radius without.
    pub fn max_radius(&self) -> u64 {
        match self.radius_bits {
            Some(b) => low_mask(b) - 1,
            None => u64::MAX,
        }
    }

    /// The limit [`CoreConfig::max_radius`] sets, in the words every refusal of a
    /// larger radius uses (host, bench and driver alike).
    pub fn radius_limit(&self) -> String {
        match self.radius_bits {
            Some(b) => format!(
                "radius_bits = {b} answers radii up to {} on the grid",
                self.max_radius()
            ),
            None => "every radius".to_string(),
        }
    }

    /// Distances are narrower than the grid's diagonal, so they saturate.
    pub fn saturates(&self) -> bool {
        self.dist_bits() < self.full_dist_bits()
    }

    /// The fewest distance bits that answer initial radii up to `bound` exactly
    /// (its saturated value `2^b − 1` above `bound`).
    pub fn radius_bits_for(bound: u64) -> u32 {
        bits_for(bound.saturating_add(1))
    }

    /// A distance in this metric ([`CoreConfig::dist_bits`]).
    pub fn dist_mask(&self) -> u64 {
        low_mask(self.dist_bits())
    }

    /// A heap address (H bits).
    pub fn addr_mask(&self) -> u64 {
        low_mask(self.address_bits)
    }

    /// A found-list count or k (0..=K).
    pub fn count_mask(&self) -> u64 {
        low_mask(self.count_bits())
    }

    /// A query's photon-read count ([`CoreConfig::visited_bits`]).
    pub fn visited_mask(&self) -> u64 {
        low_mask(self.visited_bits())
    }

    /// Bits of a found-list entry index (0..K).
    pub fn entry_bits(&self) -> u32 {
        bits_for(self.k.saturating_sub(1) as u64)
    }

    /// A found-list entry index (0..K).
    pub fn entry_mask(&self) -> u64 {
        low_mask(self.entry_bits())
    }

    /// Whether a barrel port keeps its found lists as heaps (K above
    /// [`FOUND_TREE_MAX_K`]).
    pub fn uses_found_heap(&self) -> bool {
        self.controller == Controller::Barrel && self.k > FOUND_TREE_MAX_K
    }

    /// Whether result entries carry their distances. A heap core's read-out keeps
    /// addresses only (its heaps hold the distances; `SlotReadout` says why) and
    /// sends zero; the driver fills each in from the map it loaded.
    pub fn sends_distances(&self) -> bool {
        !self.uses_found_heap()
    }

    /// Levels of a found heap: `2^levels − 1 >= K` nodes.
    pub fn heap_levels(&self) -> usize {
        bits_for(self.k as u64) as usize
    }

    /// Bits of a found heap's key: the distance over the entry index, so that keys
    /// are unique and the largest key is the farthest photon in the lowest entry
    /// among ties (the list rule of knn.rs and of `FoundMax`).
    pub fn heap_key_bits(&self) -> u32 {
        self.dist_bits() + self.entry_bits()
    }

    /// One bit per found-list slot (the K slots of a one-hot slot mask).
    pub fn slot_mask(&self) -> u64 {
        low_mask(self.k as u32)
    }

    /// One bit per query of a port: its QueryModules or its barrel slots.
    pub fn port_queries_mask(&self) -> u64 {
        low_mask(self.queries_per_port as u32)
    }

    /// Bits of a tree level's index (0..H): the root is level 0, a leaf at most H − 1.
    pub fn level_index_bits(&self) -> u32 {
        bits_for(self.address_bits.saturating_sub(1) as u64)
    }

    /// A tree level's index (0..H).
    pub fn level_index_mask(&self) -> u64 {
        low_mask(self.level_index_bits())
    }

    /// A one-hot tree level: one bit per level (H).
    pub fn level_onehot_mask(&self) -> u64 {
        low_mask(self.address_bits)
    }

    /// The levels that can have a pending far child ([`CoreConfig::path_levels`]).
    pub fn pending_mask(&self) -> u64 {
        low_mask(self.path_levels() as u32)
    }
}
