//! Verilog export of the configured core (rust-hdl's `generate_verilog`, after
//! `check_all`, which `generate_verilog` would otherwise turn into a panic).

use crate::host::error::Error;
use crate::hw::config::{dispatch_widths, CoreConfig};
use crate::hw::core::PhotonSearchCore;
use rust_hdl::prelude::*;

/// The Verilog of the whole core for `cfg`; the top module is named `top`.
pub fn export_verilog(cfg: &CoreConfig) -> Result<String, Error> {
    cfg.validate()?;
    dispatch_widths!(cfg, export(cfg))
}

fn export<const S: usize, const W: usize>(cfg: &CoreConfig) -> Result<String, Error> {
    let mut uut = PhotonSearchCore::<S, W>::new(cfg);
    uut.connect_all();
    check_all(&uut).map_err(|e| Error::new(format!("hardware core check failed: {e:?}")))?;
    Ok(generate_verilog(&uut))
}
