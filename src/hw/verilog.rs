//! Verilog export of the configured core (rust-hdl's `generate_verilog`, after
//! `check_all`, which `generate_verilog` would otherwise turn into a panic).

use crate::host::error::Error;
use crate::hw::array::PhotonSearchArray;
use crate::hw::config::{dispatch_widths, CoreConfig};
use crate::hw::core::PhotonSearchCore;
use rust_hdl::prelude::*;

/// The Verilog of the whole core for `cfg`; the top module is named `top`.
pub fn export_verilog(cfg: &CoreConfig) -> Result<String, Error> {
    cfg.validate()?;
    dispatch_widths!(cfg, export(cfg))
}

/// The core itself for T = 1, the array of T cores otherwise.
fn export<const S: usize, const W: usize>(cfg: &CoreConfig) -> Result<String, Error> {
    if cfg.trees == 1 {
        export_top(PhotonSearchCore::<S, W>::new(cfg))
    } else {
        export_top(PhotonSearchArray::<S, W>::new(cfg))
    }
}

fn export_top<U: Block>(mut uut: U) -> Result<String, Error> {
    uut.connect_all();
    check_all(&uut).map_err(|e| Error::new(format!("hardware core check failed: {e:?}")))?;
    Ok(generate_verilog(&uut))
}
