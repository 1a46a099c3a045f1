//! The banked photon store's configuration ([`Banking`], `CoreConfig::banking`)
//! and its checks (`CoreConfig::validate` calls them).

use crate::hw::config::controller::Controller;
use crate::hw::error::HwError;
use serde::{Deserialize, Serialize};

/// A banked photon store: the map spread over `2^bank_bits` BlockRAM banks, its
/// top `replicated_levels` levels (read by every query) copied beside each pair
/// of barrel datapaths (`trees` copies, two datapaths each: the BlockRAM's two
/// ports), the nodes below in bank and row by [`BankMap`](crate::hw::store::bank_map::BankMap),
/// reached through a [`BankCrossbar`](crate::hw::store::bank_crossbar::BankCrossbar)
/// whose bank read ports are shared as `ports` says; `mapping` is how a node's
/// address picks its bank. Why and how measured:
/// `host::banking`, docs/BANKING.md and docs/HARDWARE.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Banking {
    pub bank_bits: u32,
    pub replicated_levels: u32,
    pub ports: BankPorts,
    pub mapping: BankMapping,
}

impl Banking {
    /// The bank bits of `banks` banks: a power of two from 2 to 2^[`MAX_BANK_BITS`].
    pub fn bank_bits_for(banks: u64) -> Result<u32, HwError> {
        if banks < 2 || !banks.is_power_of_two() || banks > 1 << MAX_BANK_BITS {
            return Err(HwError::Config(format!(
                "banks = {banks}: unsupported (a power of two, 2..={})",
                1u32 << MAX_BANK_BITS
            )));
        }
        Ok(banks.trailing_zeros())
    }

    /// The replicated levels when none are given: 10 (1,023 nodes, one RAMB36
    /// or two DP16KD of 32-bit words per replica: every query reads them, and
    /// they take the banks' busiest addresses off the crossbar), at least as
    /// many as the bank bits (`BankMap`) and below H.
    pub fn default_levels(bank_bits: u32, address_bits: u32) -> u32 {
        10.min(address_bits.saturating_sub(1)).max(bank_bits)
    }
}

/// Banks limit (the crossbar's 10-bit bank index).
pub const MAX_BANK_BITS: u32 = 10;

impl Banking {
    /// Check `b` for a core of `controller` and H = `address_bits`.
    /// `in_memory`: the banks are the external memory's cache (any H; the rows
    /// are the cache's).
    pub fn check(
        self,
        controller: Controller,
        address_bits: u32,
        in_memory: bool,
    ) -> Result<(), HwError> {
        let b = self;
        let fail = |m: String| Err(HwError::Config(m));
        if controller != Controller::Barrel {
            return fail(format!(
                "banks with controller {}: a read that waits for its bank needs the barrel \
                 controller (a QueryModule expects its word the next cycle)",
                controller
            ));
        }
        if b.bank_bits == 0 || b.bank_bits > MAX_BANK_BITS {
            return fail(format!(
                "banks = {}: unsupported (2..={} banks, a power of two)",
                1u64 << b.bank_bits.min(40),
                1u32 << MAX_BANK_BITS
            ));
        }
        if b.replicated_levels < b.bank_bits || b.replicated_levels >= address_bits {
            return fail(format!(
                "replicated levels = {} with {} banks and H = {}: the replica must cover at \
                 least as many nodes as there are banks (L >= {}) and leave levels to bank \
                 (L < H)",
                b.replicated_levels,
                1u64 << b.bank_bits,
                address_bits,
                b.bank_bits
            ));
        }
        if !in_memory && address_bits - b.bank_bits > 16 {
            return fail(format!(
                "{} banks for H = {}: a bank would hold 2^{} rows, more than the 2^16 a bank \
                 row index addresses (more banks)",
                1u64 << b.bank_bits,
                address_bits,
                address_bits - b.bank_bits
            ));
        }
        Ok(())
    }
}

/// How a bank's read ports are shared among the requesters (`--bank-ports`, the
/// core file's `bank_ports`); each variant's doc is its help text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum BankPorts {
    /// One read port per bank.
    One,
    /// Two ports, either one serving any datapath (the fewest bank conflicts): the
    /// second grants one of those the first left waiting.
    #[default]
    Shared,
    /// Two ports, the first serving the even datapaths and the second the odd ones
    /// (a replica's two datapaths, one on each): half the crossbar of shared.
    Split,
}

/// How a node below the replicated levels picks its bank (`--bank-map`, the core
/// file's `bank_map`); its row is the address's high bits either way. Each
/// variant's doc is its help text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum BankMapping {
    /// The address's low bits XOR every other group of as many bits: every branch
    /// decision mixed in, the banks' load the most even (docs/BANKING.md).
    #[default]
    Xor,
    /// The address's low bits alone (the last branch decisions): no XOR gates,
    /// for before/after measurement of the fold.
    Modulo,
}

impl std::fmt::Display for BankMapping {
    /// The mapping's one-word name, as `--bank-map` and the core file spell it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BankMapping::Xor => "xor",
            BankMapping::Modulo => "modulo",
        })
    }
}

impl BankPorts {
    /// Read ports per bank.
    pub fn ports(self) -> usize {
        if self == BankPorts::One {
            1
        } else {
            2
        }
    }
    /// The mode's one-word name, as `--bank-ports` and the core file spell it.
    pub fn name(self) -> &'static str {
        match self {
            BankPorts::One => "one",
            BankPorts::Shared => "shared",
            BankPorts::Split => "split",
        }
    }
}

impl std::fmt::Display for BankPorts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BankPorts::One => "one port per bank",
            BankPorts::Shared => "two shared ports per bank",
            BankPorts::Split => "two split ports per bank",
        })
    }
}
