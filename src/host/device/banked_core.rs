//! The banked barrel core a device holds for a map (`--device`): [`plan`]'s B, L
//! and D made into core options. D datapaths are D / 2 replicas of the top levels
//! (two datapaths share one dual-port BlockRAM replica), so an odd D loses one.

use crate::host::device::plan::{
    datapath_brams, plan, plan_memory, Device, Limits, PlanError, ECP5_85K,
};
use crate::host::error::{Error, Result};
use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::{bits_for, MAX_ADDRESS_BITS, PORTS};
use crate::hw::config::memory_config::{
    CacheTags, DEFAULT_MEMORY_DATA_BITS, MAX_MEMORY_ADDRESS_BITS,
};

/// `b` with the banked barrel core that `dev` holds for `photons` photons of
/// `word_bits`-bit words: a clear error (naming the largest map that fits) if
/// none, or if `b` asks for the QueryModule controller.
pub fn for_device(
    b: CoreBuilder,
    photons: usize,
    word_bits: u32,
    dev: &Device,
) -> Result<CoreBuilder> {
    if b.chosen_controller() != Controller::Barrel {
        return Err(Error::new(format!(
            "--device {} builds the banked barrel core: --controller {} cannot wait for a bank",
            dev.name,
            b.chosen_controller()
        )));
    }
    let lim = Limits::default();
    let own = own_brams(&b, photons, dev)?;
    let p = match plan(photons, word_bits, own, dev, &lim) {
        Ok(p) => p,
        // Beyond the BlockRAM: the map in the board's memory behind a cache.
        Err(PlanError::MapTooLarge { .. }) => return memory_core(b, photons, word_bits, dev),
        Err(e) => return Err(Error::new(e.to_string())),
    };
    let trees = (p.datapaths as usize / PORTS).max(1);
    let address_bits = bits_for(photons as u64);
    Ok(
        if photons < 1 << p.replicated_levels || p.replicated_levels >= address_bits {
            // The whole map fits every replica: whole trees, no banks.
            b.trees(trees).banking(None)
        } else {
            // (One bank is no bank: the crossbar needs two.) The plan's port
            // mode unless one was given.
            let ports = b.given_bank_ports().unwrap_or(p.ports);
            b.trees(trees)
                .banks(p.bank_bits.max(1), Some(p.replicated_levels))
                .bank_ports(ports)
                .result_streams(result_streams(PORTS * trees))
        },
    )
}

/// `b` as the external-memory core `dev` holds for `photons` photons (whatever
/// their number: a map the BlockRAM would hold too gets it when asked, as the
/// lab's sweeps over map size do).
pub fn memory_core(
    b: CoreBuilder,
    photons: usize,
    word_bits: u32,
    dev: &Device,
) -> Result<CoreBuilder> {
    let own = own_brams(&b, photons, dev)?;
    let m = plan_memory(photons, word_bits, own, dev, &Limits::default())
        .map_err(|e| Error::new(e.to_string()))?;
    let trees = (m.datapaths as usize / PORTS).max(1);
    let b = b
        .trees(trees)
        .banks(m.bank_bits, Some(m.replicated_levels))
        .bank_ports(BankPorts::Split)
        .cache_lines(Some(m.cache_lines))
        .result_streams(result_streams(PORTS * trees));
    // (The default width and tags stay unnamed: the core file and description as
    // before.)
    let b = if m.cache_tags == CacheTags::default() {
        b
    } else {
        b.cache_tags(Some(m.cache_tags))
    };
    Ok(if m.memory_data_bits == DEFAULT_MEMORY_DATA_BITS {
        b
    } else {
        b.memory_data_bits(Some(m.memory_data_bits))
    })
}

/// One datapath's own BlockRAMs of the core `b` describes, for a map of `photons`
/// photons (its found lists hold their addresses): K, the query slots and the
/// distance width set them; the store's options do not.
fn own_brams(b: &CoreBuilder, photons: usize, dev: &Device) -> Result<u32> {
    // (A map beyond the external memory's addresses is refused by the plan.)
    let h = bits_for(photons as u64).min(MAX_MEMORY_ADDRESS_BITS);
    let mut core = b
        .address_bits(h.min(MAX_ADDRESS_BITS))
        .banking(None)
        .cache_lines(None)
        .build()
        .map_err(|e| Error::new(e.to_string()))?;
    core.address_bits = h;
    Ok(datapath_brams(dev, &core))
}

/// Datapaths one result stream serves in a planned core: a stream carries a beat
/// a cycle, and a busy barrel datapath at k = 32 sends about 0.12 (a 17-beat
/// packet per ~140 reads), so four keep a stream half full with room for smaller
/// maps (fewer reads per packet).
pub const DATAPATHS_PER_STREAM: usize = 4;

/// The fewest result streams that split `d` datapaths evenly with at most
/// [`DATAPATHS_PER_STREAM`] on each.
pub fn result_streams(d: usize) -> usize {
    (1..=d)
        .find(|&r| d.is_multiple_of(r) && d / r <= DATAPATHS_PER_STREAM)
        .unwrap_or(1)
}

/// [`for_device`] if a device is given; else `b` as it is for a map the core's
/// BlockRAM tree holds or when it names its cache, and beyond that (H >
/// `MAX_ADDRESS_BITS`) the external-memory core the smallest modelled board (the
/// ECP5-85k's) holds.
pub fn for_device_opt(
    b: CoreBuilder,
    photons: usize,
    word_bits: u32,
    dev: Option<&Device>,
) -> Result<CoreBuilder> {
    match dev {
        Some(d) => for_device(b, photons, word_bits, d),
        // An external-memory core given whole (its cache lines chosen) is built
        // as given.
        None if b.given_cache_lines().is_some() => Ok(b),
        None if bits_for(photons as u64) > MAX_ADDRESS_BITS => {
            if b.chosen_controller() != Controller::Barrel {
                return Err(Error::new(format!(
                    "a map of {photons} photons needs the external-memory core (more than \
                     {MAX_ADDRESS_BITS} address bits), a banked barrel core: --controller {} \
                     cannot wait for a bank",
                    b.chosen_controller()
                )));
            }
            for_device(b, photons, word_bits, &ECP5_85K)
        }
        None => Ok(b),
    }
}
