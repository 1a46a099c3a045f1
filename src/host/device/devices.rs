//! The devices a plan is for: each one's BlockRAM (count and shapes) and logic;
//! what a barrel datapath, the crossbar and the external-memory cache cost on it
//! (synth/device_costs.toml, generated from the part syntheses of
//! synth/results.json); and a datapath's own BlockRAMs counted from the core
//! planned.

use crate::hw::barrel::barrel_port::datapath_block_rams;
use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::core_config::CoreConfig;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::sync::LazyLock;

/// A device's BlockRAM and logic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Device {
    pub name: &'static str,
    /// Its table in synth/device_costs.toml.
    pub key: &'static str,
    pub brams: u32,
    /// (words, bits) of one BlockRAM port in its widest true-dual-port shape.
    pub shape: (u32, u32),
    /// Logic cells (ECP5 LUT4s, Virtex-6 6-input LUTs).
    pub luts: u32,
    /// (words, bits) of each BlockRAM shape a memory may take, widest first (a
    /// memory takes the shape that needs the fewest: [`Device::brams_for`]).
    pub bram_shapes: &'static [(u32, u32)],
    /// One barrel datapath's own BlockRAMs (far-cell bounds, found lists) at the
    /// default K = 32, for the lab's studies (the product counts its core's:
    /// [`datapath_brams`]).
    pub datapath_brams: u32,
}

/// What each part of a banked or external-memory core costs in a device's logic
/// cells: the part synthesised as its own top for the device's family, divided by
/// what it grows with (synth/costs.py derives each from the rows of
/// synth/results.json that synth/device_costs.toml names; synth/REPORT.md lists
/// them).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceCosts {
    /// One barrel datapath at K = 32 (the direct render's k).
    pub datapath_luts: u32,
    /// The crossbar per requester and bank, with shared and with split bank ports.
    pub crossbar_luts_shared: f64,
    pub crossbar_luts_split: f64,
    /// One barrel datapath of an external-memory core at K = 32 (its read issue
    /// parks slots on misses, and its addresses are the memory's), and its
    /// crossbar over the cache banks (split ports) per requester and bank.
    pub memory_datapath_luts: u32,
    pub memory_crossbar_luts: f64,
    /// The external-memory cache per line (each line's valid, filling and used
    /// bits are flip-flops beside its bank, with the logic that reads and updates
    /// them) and per bank (its tags, miss and request registers, its read ports:
    /// `hw::memory::cache_bank`), so the cache costs logic as well as BlockRAM.
    pub cache_line_luts: f64,
    pub cache_bank_luts: f64,
    /// What a cache line's logic changes by with its tag in LUT-RAM
    /// (`CacheTags::LutRam`: both ports' copies and their read multiplexers, only
    /// as wide as the map's tags) instead of BlockRAM (24 bits, and as wide a
    /// compare): negative where the narrower compare saves more than the LUT-RAM
    /// costs.
    pub cache_lut_tag_luts: f64,
    /// The rest of an external-memory core: the line fill and its arbiter, the
    /// replicas of the top levels, the dispatcher and the result path.
    pub memory_rest_luts: u32,
}

/// Every device's costs, from the file synth/report.py generates.
static COSTS: LazyLock<BTreeMap<String, DeviceCosts>> = LazyLock::new(|| {
    toml::from_str(include_str!("../../../synth/device_costs.toml"))
        .expect("synth/device_costs.toml is what synth/report.py render writes")
});

impl Device {
    /// Its logic costs (synth/device_costs.toml).
    pub fn costs(&self) -> &'static DeviceCosts {
        COSTS
            .get(self.key)
            .unwrap_or_else(|| panic!("synth/device_costs.toml has no [{}]", self.key))
    }

    /// The BlockRAMs of a memory of `2^index_bits` words of `width` bits: the
    /// fewest any one shape takes (yosys picks one shape for a memory); memories
    /// of up to 32 words are LUT-RAM (yosys maps a cache bank's 32 tags so, and
    /// its 64 tags to a BlockRAM).
    pub fn brams_for(&self, index_bits: u32, width: u32) -> u32 {
        if index_bits <= 5 {
            return 0;
        }
        self.bram_shapes
            .iter()
            .map(|&(words, bits)| width.div_ceil(bits) * (1u32 << index_bits).div_ceil(words))
            .min()
            .unwrap_or(0)
    }

    /// The crossbar's logic for `d` requesters on `banks` banks with `ports`
    /// (one port a bank costs what split ports do: one port's arbiter and row
    /// tree over all D, one word input a bank for each requester).
    pub fn crossbar_luts(&self, d: u32, banks: u32, ports: BankPorts) -> u64 {
        let per = match ports {
            BankPorts::Shared => self.costs().crossbar_luts_shared,
            BankPorts::Split | BankPorts::One => self.costs().crossbar_luts_split,
        };
        (per * f64::from(d) * f64::from(banks)).ceil() as u64
    }
}

/// Lattice ECP5-85k: 208 DP16KD of 18 Kbit (widest true-dual-port shape 1K × 18;
/// the 512 × 36 shape is pseudo-dual-port, one read port, which is all a
/// single-ported bank needs; two read ports take two 1K × 18 halves of a word).
pub const ECP5_85K: Device = Device {
    name: "ECP5-85k",
    key: "ecp5_85k",
    brams: 208,
    shape: (512, 36),
    luts: 83_640,
    bram_shapes: &[
        (512, 36),
        (1024, 18),
        (2048, 9),
        (4096, 4),
        (8192, 2),
        (16384, 1),
    ],
    datapath_brams: 8,
};

/// Xilinx XC6VSX475T: 1,064 RAMB36 (1K × 36), 297,600 6-input LUTs.
pub const XC6VSX475T: Device = Device {
    name: "XC6VSX475T",
    key: "xc6vsx475t",
    brams: 1_064,
    shape: (1024, 36),
    luts: 297_600,
    bram_shapes: &[
        (512, 72),
        (1024, 36),
        (2048, 18),
        (4096, 9),
        (8192, 4),
        (16384, 2),
        (32768, 1),
    ],
    datapath_brams: 4,
};

/// One barrel datapath's own BlockRAMs on `dev` for `core` with its map's
/// address bits (the found lists hold photon addresses): its memories as its
/// blocks build them (`datapath_block_rams`: found lists, far-cell bounds, and
/// for K > 64 the heaps' levels), each in the device's fewest BlockRAMs.
pub fn datapath_brams(dev: &Device, core: &CoreConfig) -> u32 {
    datapath_block_rams(core)
        .into_iter()
        .map(|(index_bits, width)| dev.brams_for(index_bits, width))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generated costs file holds every device's every cost, each positive,
    /// and shared bank ports cost more than split ones (each port's row tree
    /// serves every datapath instead of half of them).
    #[test]
    fn every_device_has_its_costs() {
        for dev in [ECP5_85K, XC6VSX475T] {
            let c = dev.costs();
            assert!(c.datapath_luts > 0 && c.memory_datapath_luts > 0, "{c:?}");
            assert!(
                c.memory_rest_luts > 0 && c.memory_crossbar_luts > 0.0,
                "{c:?}"
            );
            assert!(c.cache_line_luts > 0.0 && c.cache_bank_luts > 0.0, "{c:?}");
            assert!(c.crossbar_luts_shared > c.crossbar_luts_split, "{c:?}");
            assert!(c.crossbar_luts_split > 0.0, "{c:?}");
        }
    }
}
