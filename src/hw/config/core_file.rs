//! The core description file: every elaboration-time parameter of one core
//! ([`CoreConfig`]) as TOML, so that one fixed core (one FPGA image, one Verilator
//! model) serves every photon map that fits it. `export-verilog` writes it beside
//! the Verilog; `render`, `gather` and `bench-core` take it with `--core FILE` and
//! check each map against it instead of deriving a core from the map.
//!
//! The file holds exactly what changes the exported Verilog, under the names the
//! command line uses (`--controller`, `--queries-per-port`, …); every key is
//! required except those of an absent feature (banks, extra result streams, radius
//! bits), and unknown keys are refused, so a file means one core and nothing is
//! filled in silently. The values are checked by
//! the one validated constructor, [`CoreBuilder::build`].

use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::{Banking, CoreConfig, MAX_HW_COORD_BITS};
use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::PhotonLayout;
use crate::hw::config::traversal::Traversal;
use crate::hw::error::HwError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The file name `export-verilog` gives the description beside `photon_search_core.v`.
pub const CORE_FILE_NAME: &str = "photon_search_core.toml";

/// One core, as the file holds it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoreFile {
    /// `modules` (the paper's QueryModules) or `barrel` (query slots).
    pub controller: Controller,
    /// `remember`, `reread` or `cell`.
    pub traversal: Traversal,
    /// Found-list depth K: the largest k a query may ask for.
    pub k: usize,
    /// Coordinate bits of x, y and z: the photon word's layout. A map is quantized
    /// onto exactly this grid.
    #[serde(deserialize_with = "three_widths")]
    pub coordinate_bits: [u32; 3],
    /// Tree height H: the core holds at most 2^H − 1 photons.
    pub address_bits: u32,
    /// `l2` or `l1`.
    pub metric: Metric,
    /// Q, the queries a TreeModule port holds at once: QueryModules with the
    /// modules controller, query slots with the barrel controller (earlier files
    /// spell it `modules_per_port` or `slots_per_port`, read the same).
    #[serde(alias = "modules_per_port", alias = "slots_per_port")]
    pub queries_per_port: usize,
    /// Trees T: an array of T whole cores, each its own copy of the map (1 with
    /// banks).
    pub trees: usize,
    /// With banks: the replicas of the top levels, two datapaths each (an earlier
    /// export, without this key, wrote them as `trees`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replicas: Option<usize>,
    /// The pipeline registers (BlockRAM read data, result streams).
    pub pipelined: bool,
    /// A banked store: the banks (a power of two) and the levels replicated beside
    /// the datapaths. Absent: each tree holds the whole map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub banks: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replicated_levels: Option<u32>,
    /// With banks: `one`, `shared` or `split` read ports per bank (absent: the
    /// default, `BankPorts::default`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bank_ports: Option<BankPorts>,
    /// Result streams R (absent: one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result_streams: Option<usize>,
    /// Distance bits for the largest initial radius the core answers (radii below
    /// 2^b − 1; larger distances saturate). Absent: the grid's diagonal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_bits: Option<u32>,
}

impl From<&CoreConfig> for CoreFile {
    fn from(c: &CoreConfig) -> Self {
        CoreFile {
            controller: c.controller,
            traversal: c.traversal,
            k: c.k,
            coordinate_bits: c.layout.bits,
            address_bits: c.address_bits,
            metric: c.metric,
            queries_per_port: c.queries_per_port,
            trees: if c.banking.is_some() { 1 } else { c.trees },
            replicas: c.banking.map(|_| c.trees),
            pipelined: c.pipelined,
            banks: c.banking.map(|b| 1u64 << b.bank_bits),
            replicated_levels: c.banking.map(|b| b.replicated_levels),
            bank_ports: c.banking.map(|b| b.ports),
            result_streams: (c.result_streams != 1).then_some(c.result_streams),
            radius_bits: c.radius_bits,
        }
    }
}

/// `coordinate_bits`: exactly three widths, x, y and z (toml would drop a fourth).
fn three_widths<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[u32; 3], D::Error> {
    let v = Vec::<u32>::deserialize(d)?;
    <[u32; 3]>::try_from(v.as_slice()).map_err(|_| {
        serde::de::Error::custom(format!(
            "coordinate_bits = {v:?}: expected three widths (x, y, z), got {}",
            v.len()
        ))
    })
}

impl CoreFile {
    /// The core this file describes, checked by [`CoreBuilder::build`] (K, Q, T, H
    /// or the widths out of range are refused, named with their value).
    pub fn config(&self) -> Result<CoreConfig, HwError> {
        let widths = 1..=MAX_HW_COORD_BITS;
        if !self.coordinate_bits.iter().all(|b| widths.contains(b)) {
            return Err(HwError::Config(format!(
                "coordinate_bits = {:?}: each width must be 1..={MAX_HW_COORD_BITS}",
                self.coordinate_bits
            )));
        }
        let mut b = CoreBuilder::default()
            .layout(PhotonLayout::new(self.coordinate_bits))
            .address_bits(self.address_bits)
            .k(self.k)
            .metric(self.metric)
            .pipelined(self.pipelined)
            .trees(self.trees()?)
            .traversal(self.traversal)
            .controller(self.controller)
            .result_streams(self.result_streams.unwrap_or(1))
            .radius_bits(self.radius_bits)
            .queries_per_port(self.queries_per_port);
        match (self.banks, self.replicated_levels) {
            (Some(banks), levels) => b = b.banks(Banking::bank_bits_for(banks)?, levels),
            (None, Some(l)) => {
                return Err(HwError::Config(format!(
                    "replicated_levels = {l} without banks: only a banked store replicates levels"
                )))
            }
            (None, None) => {}
        }
        match (self.banks, self.bank_ports) {
            (Some(_), Some(p)) => b = b.bank_ports(p),
            (None, Some(p)) => {
                return Err(HwError::Config(format!(
                    "bank_ports = {:?} without banks: only a banked store has bank ports",
                    p
                )))
            }
            _ => {}
        }
        b.build()
    }
}

impl CoreFile {
    /// The core's copies: whole trees, or a banked core's replicas.
    fn trees(&self) -> Result<usize, HwError> {
        match (self.banks, self.replicas) {
            (Some(_), Some(_)) if self.trees != 1 => Err(HwError::Config(format!(
                "trees = {} with banks: a banked core is one tree, its copies of the top \
                 levels are replicas",
                self.trees
            ))),
            (Some(_), Some(r)) => Ok(r),
            (None, Some(r)) => Err(HwError::Config(format!(
                "replicas = {r} without banks: only a banked store replicates its top levels"
            ))),
            // Without banks, whole trees; an earlier export wrote replicas as trees.
            (_, None) => Ok(self.trees),
        }
    }
}

/// `cfg` as the file's text: a comment saying what it is, then one key per line.
pub fn to_toml(cfg: &CoreConfig) -> String {
    let body = toml::to_string(&CoreFile::from(cfg)).expect("a CoreFile serialises to TOML");
    format!(
        "# photon-fpga core description: the core exported beside this file.\n\
         # render, gather and bench-core take it with --core FILE and run every photon\n\
         # map of at most 2^address_bits - 1 photons, and every k up to k, on this core.\n\
         {body}"
    )
}

/// The core described by `text`; `origin` (the file's name) starts every error,
/// and a parse error names the line, the column and the value (toml's span).
pub fn from_toml(text: &str, origin: &str) -> Result<CoreConfig, HwError> {
    let file: CoreFile =
        toml::from_str(text).map_err(|e| HwError::Config(format!("{origin}: {e}")))?;
    file.config()
        .map_err(|e| HwError::Config(format!("{origin}: {}", strip(&e))))
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
