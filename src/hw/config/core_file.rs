//! The core description file: a [`CoreSpec`] as TOML, so that one fixed core (one
//! FPGA image, one Verilator model) serves every photon map that fits it.
//! `export-verilog` writes it beside the Verilog with every key given; `render`,
//! `gather`, `export-verilog` and the lab take it with `--core FILE` and check
//! each map against it instead of deriving a core from the map.
//!
//! The keys are the spec's fields, under the names the command line uses
//! (`--controller`, `--queries-per-port`, …; `coordinate_bits` is `--bits`). A key
//! left out is the default core's, as on the command line; an unknown key is
//! refused, and every error names the file, the line and the key. The values are
//! checked by the one validated constructor, [`CoreBuilder`].

use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::core_spec::CoreSpec;
use crate::hw::error::HwError;
use serde::Deserialize;
use std::path::Path;

/// The file name `export-verilog` gives the description beside `photon_search_core.v`.
pub const CORE_FILE_NAME: &str = "photon_search_core.toml";

/// `cfg` as the file's text: a comment saying what it is, then one key per line.
pub fn to_toml(cfg: &CoreConfig) -> String {
    let body = toml::to_string(&CoreSpec::from(cfg)).expect("a CoreSpec serialises to TOML");
    format!(
        "# photon-fpga core description: the core exported beside this file.\n\
         # render, gather and bench-core take it with --core FILE and run every photon\n\
         # map of at most 2^address_bits - 1 photons, and every k up to k, on this core.\n\
         {body}"
    )
}

/// The core described by `text`; `origin` (the file's name) starts every error,
/// which names the line and column of the key at fault.
pub fn from_toml(text: &str, origin: &str) -> Result<CoreConfig, HwError> {
    let spec = spec_from_toml(text, origin)?;
    let at = |e: HwError| HwError::Config(format!("{origin}: {}", strip(&e)));
    let cfg = CoreBuilder::from_spec(&spec)
        .and_then(|b| b.build())
        .map_err(at)?;
    if let (Some(p), None) = (spec.build.bank_ports, cfg.banking) {
        return Err(at(HwError::Config(format!(
            "bank_ports = {} without banks: only a banked store has bank ports",
            p.name()
        ))));
    }
    Ok(cfg)
}

/// The spec `text` holds, each key read on its own so that an unknown key or a
/// bad value is named with its line.
pub fn spec_from_toml(text: &str, origin: &str) -> Result<CoreSpec, HwError> {
    let fail = |m: String| HwError::Config(format!("{origin}: {m}"));
    // The whole text first: toml's own errors name the line, column and value.
    let keys: toml::Table = toml::from_str(text).map_err(|e| fail(e.to_string()))?;
    let lines = Lines(text);
    for (key, value) in &keys {
        let alone = toml::Table::from_iter([(key.clone(), value.clone())]);
        let spec: CoreSpec = alone
            .try_into()
            .map_err(|e: toml::de::Error| fail(format!("{}: {}", lines.of(key), e.message())))?;
        // Unknown keys are ignored by the flattened parts; a key alone that leaves
        // the spec empty is one no field reads.
        if spec == CoreSpec::default() {
            return Err(fail(format!("{}: unknown key `{key}`", lines.of(key))));
        }
    }
    CoreSpec::deserialize(keys).map_err(|e| fail(e.message().to_string()))
}

/// Where a top-level key is written in a file's text.
struct Lines<'a>(&'a str);

impl Lines<'_> {
    /// "line N" of the first line that assigns `key`.
    fn of(&self, key: &str) -> String {
        self.0
            .lines()
            .position(|l| {
                l.trim_start()
                    .strip_prefix(key)
                    .is_some_and(|rest| rest.trim_start().starts_with('='))
            })
            .map_or(format!("key `{key}`"), |n| format!("line {}", n + 1))
    }
}

/// The core described by the file at `path`.
pub fn read(path: &Path) -> Result<CoreConfig, HwError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| HwError::Config(format!("{}: cannot read: {e}", path.display())))?;
    from_toml(&text, &path.display().to_string())
}

/// An error's message without the "hardware core: " prefix of its kind.
fn strip(e: &HwError) -> String {
    match e {
        HwError::Config(m) | HwError::Simulation(m) | HwError::CrossSim(m) | HwError::Export(m) => {
            m.clone()
        }
    }
}
