//! Verilog export of the configured core (rust-hdl's `generate_verilog`, after
//! `check_all`, which `generate_verilog` would otherwise turn into a panic).

use crate::host::error::Error;
use crate::hw::config::{CoreConfig, NARROW_SLOTS, WIDE_SLOTS};
use crate::hw::core::PhotonSearchCore;
use rust_hdl::prelude::*;

/// The Verilog of the whole core for `cfg`; the top module is named `top`.
pub fn export_verilog(cfg: &CoreConfig) -> Result<String, Error> {
    cfg.validate()?;
    if cfg.slot_bits() == NARROW_SLOTS {
        export::<NARROW_SLOTS>(cfg)
    } else {
        export::<WIDE_SLOTS>(cfg)
    }
}

fn export<const S: usize>(cfg: &CoreConfig) -> Result<String, Error> {
    let mut uut = PhotonSearchCore::<S>::new(cfg);
    uut.connect_all();
    check_all(&uut).map_err(|e| Error::new(format!("hardware core check failed: {e:?}")))?;
    Ok(generate_verilog(&uut))
}
