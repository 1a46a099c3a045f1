//! [`CoreSpec`]: the one description of a core as a user writes it. The same struct
//! is the core file (TOML, `core_file`), the command line's core options (clap
//! derives behind the `cli` feature, so the hardware layer builds without clap) and
//! the core of every `synth/results.json` record; the validating
//! [`CoreBuilder`](crate::hw::config::config_builder::CoreBuilder) takes it
//! (`CoreBuilder::from_spec`) and [`CoreConfig`]'s `Display` describes the result.
//!
//! Every field is optional: one left out is the default core's (the best core
//! measured, synth/REPORT.md: the barrel controller, K = 32, L2; the traversal and
//! Q its controller's defaults), or with [`CoreSpec::paper`] under it the paper's
//! Table-2 core (§5). A new core option is one field here and one setter in the
//! builder: the file, the command line and the results records follow.
//!
//! The spec has two parts. [`CoreChoice`] picks which core answers (controller,
//! traversal, Q, trees): render and gather take it, since their grid, K and metric
//! follow the photon map and the gather. [`CoreBuild`] fixes how it is built (grid,
//! H, K, metric, pipelining, banks, result streams): export-verilog, the lab and a
//! core file give it.

use crate::hw::config::bank_config::{BankMapping, BankPorts};
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::memory_config::CacheTags;
use crate::hw::config::metric::Metric;
use crate::hw::config::traversal::Traversal;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Which core answers: the options a user of render and gather picks.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct CoreChoice {
    /// Who runs a port's queries [default: barrel, the best core measured
    /// (synth/REPORT.md); modules, the paper's, with export-verilog --paper].
    #[cfg_attr(feature = "cli", arg(long, value_enum))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<Controller>,
    /// How the search climbs back up the tree (changes read counts, never
    /// neighbours) [default: cell with the barrel controller, else remember].
    #[cfg_attr(feature = "cli", arg(long, value_enum))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub traversal: Option<Traversal>,
    /// Q, the queries a TreeModule port holds at once: QueryModules with
    /// --controller modules [default: the issue interval, so a busy port reads every
    /// cycle; render and gather fit it to their queries], query slots with
    /// --controller barrel [default: 16].
    #[cfg_attr(feature = "cli", arg(long, value_name = "Q"))]
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        alias = "modules_per_port",
        alias = "slots_per_port"
    )]
    pub queries_per_port: Option<usize>,
    /// Trees T (the paper's future work): an array of T whole cores, each with its
    /// own copy of the map, behind one set of streams [default: 1].
    #[cfg_attr(feature = "cli", arg(long, value_name = "T"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trees: Option<usize>,
}

/// How the core is built: its grid, H, K and metric, and the options that fix its
/// structure rather than which core it is.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct CoreBuild {
    /// Found-list depth K (the largest k a query may ask for) [default: 32, the
    /// render's k; 10 with --paper].
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<usize>,
    /// Coordinate bits: one width for every axis (as render's and gather's --bits
    /// on the longest axis), or x,y,z [default: 10, the paper's].
    #[cfg_attr(feature = "cli", arg(long = "bits", value_name = "BITS"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate_bits: Option<Widths>,
    /// Tree height H: the TreeModule holds 2^H photon words [default: 10].
    #[cfg_attr(feature = "cli", arg(long, value_name = "H"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub address_bits: Option<u32>,
    /// Distance metric [default: l2; l1, the paper's 12-bit distance, with --paper].
    #[cfg_attr(feature = "cli", arg(long, value_enum))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub metric: Option<Metric>,
    /// Distance bits for the largest initial radius the core is to answer (radii
    /// below 2^b − 1 in the metric on the grid; larger distances saturate):
    /// narrower found lists and bounds for a scene that gathers within a radius
    /// [default: the grid's diagonal, every radius].
    #[cfg_attr(feature = "cli", arg(long, value_name = "B"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_bits: Option<u32>,
    /// Leave out the pipeline registers (BlockRAM read data, result streams): two
    /// cycles less latency, longer critical paths. For before/after timing.
    #[cfg_attr(
        feature = "cli",
        arg(long = "unpipelined", num_args = 0, default_missing_value = "false")
    )]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pipelined: Option<bool>,
    /// One map banked over B BlockRAM banks (a power of two; --controller barrel)
    /// that every datapath reads through a crossbar: --replicas copies of the top
    /// levels, two datapaths each (docs/BANKING.md) [default: no banks, each tree
    /// holds the whole map].
    #[cfg_attr(feature = "cli", arg(long, value_name = "B", conflicts_with = "trees"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub banks: Option<u64>,
    /// Replicas R of the top levels inside one banked core, two datapaths each,
    /// with --banks [default: 1].
    #[cfg_attr(feature = "cli", arg(long, value_name = "R"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replicas: Option<usize>,
    /// Levels of the tree replicated beside each pair of datapaths, with --banks
    /// [default: 10, at least log2 B, below H].
    #[cfg_attr(feature = "cli", arg(long, value_name = "L"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replicated_levels: Option<u32>,
    /// How each bank's BlockRAM read ports are shared among the datapaths, with
    /// --banks or --device (docs/HARDWARE.md, "The crossbar's area") [default:
    /// shared].
    #[cfg_attr(feature = "cli", arg(long, value_enum))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bank_ports: Option<BankPorts>,
    /// How a node below the replicated levels picks its bank, with --banks
    /// [default: xor].
    #[cfg_attr(feature = "cli", arg(long, value_enum))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bank_map: Option<BankMapping>,
    /// With --banks: the map's levels below the replicas live in external memory
    /// (an AXI4 master port, blocks of 4 levels, docs/MEMORY.md) and the banks are
    /// their cache of this many lines, a power of two (1 to 256 a bank); H up to
    /// 24 [default: the map on chip].
    #[cfg_attr(feature = "cli", arg(long, value_name = "LINES"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cache_lines: Option<u32>,
    /// With cache_lines: the memory's AXI4 data width, one or two photon words a
    /// beat (32 or 64 for 10-bit grids, 64 for wider ones) [default: 64]. A core
    /// file's key only: the command lines keep to a user's few options.
    #[cfg_attr(feature = "cli", arg(skip))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory_data_bits: Option<u32>,
    /// With cache_lines: where each cache bank keeps its lines' tags, "block-ram"
    /// (LUT-RAM up to 32 lines a bank) or "lut-ram" (at any depth, only as wide as
    /// the map's tags: the BlockRAM left to the words, the tags in logic)
    /// [default: "block-ram"]. A core file's key only.
    #[cfg_attr(feature = "cli", arg(skip))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cache_tags: Option<CacheTags>,
    /// Result streams R: the datapaths' result packets leave on R streams, D / R
    /// datapaths each (a divisor of D = 2 x --replicas with --banks, else of 2); one
    /// stream carries a beat a cycle, which about 8 busy datapaths fill at k = 32
    /// [default: 1; with --device one per 4 datapaths].
    #[cfg_attr(feature = "cli", arg(long, value_name = "R"))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result_streams: Option<usize>,
}

/// One core: which core and how it is built. Fields left out are the default
/// core's (module docs).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct CoreSpec {
    #[serde(flatten)]
    #[cfg_attr(feature = "cli", command(flatten))]
    pub choice: CoreChoice,
    #[serde(flatten)]
    #[cfg_attr(feature = "cli", command(flatten))]
    pub build: CoreBuild,
}

/// The default core's K: the render's k (§3: the paper's renders gather tens of
/// photons per point; the found list's cost grows with K).
pub const DEFAULT_K: usize = 32;

impl CoreSpec {
    /// The paper's Table-2 core (§5): K = 10, the 12-bit L1 distance, the
    /// QueryModules controller (its Q, the issue interval, and its traversal are
    /// the controller's defaults; the grid and H the builder's, the paper's).
    pub fn paper() -> Self {
        CoreSpec {
            choice: CoreChoice {
                controller: Some(Controller::Modules),
                ..CoreChoice::default()
            },
            build: CoreBuild {
                k: Some(10),
                metric: Some(Metric::L1),
                ..CoreBuild::default()
            },
        }
    }

    /// The default core's own fields: the barrel controller, K = 32, L2 (the rest
    /// follow from them in the builder).
    pub fn default_core() -> Self {
        CoreSpec {
            choice: CoreChoice {
                controller: Some(Controller::Barrel),
                ..CoreChoice::default()
            },
            build: CoreBuild {
                k: Some(DEFAULT_K),
                metric: Some(Metric::L2),
                ..CoreBuild::default()
            },
        }
    }

    /// `self`, with every field it leaves out taken from `base`.
    pub fn or(&self, base: &CoreSpec) -> CoreSpec {
        let mut table = table_of(base);
        table.extend(table_of(self));
        table
            .try_into()
            .expect("a merge of two specs' own fields is a spec")
    }

    /// The fields given, as `key = value` pairs in the file's names.
    pub fn given(&self) -> Vec<(String, toml::Value)> {
        table_of(self).into_iter().collect()
    }
}

/// The fields of `spec` as a TOML table (absent fields left out).
fn table_of(spec: &CoreSpec) -> toml::Table {
    toml::Table::try_from(spec).expect("a spec serialises to a TOML table")
}

impl From<&CoreConfig> for CoreSpec {
    /// Every option of `c`, given.
    fn from(c: &CoreConfig) -> Self {
        let banked = c.banking.is_some();
        CoreSpec {
            choice: CoreChoice {
                controller: Some(c.controller),
                traversal: Some(c.traversal),
                queries_per_port: Some(c.queries_per_port),
                trees: Some(if banked { 1 } else { c.trees }),
            },
            build: CoreBuild {
                k: Some(c.k),
                coordinate_bits: Some(Widths(c.layout.bits)),
                address_bits: Some(c.address_bits),
                metric: Some(c.metric),
                radius_bits: c.radius_bits,
                pipelined: Some(c.pipelined),
                banks: c.banking.map(|b| 1u64 << b.bank_bits),
                replicas: c.banking.map(|_| c.trees),
                replicated_levels: c.banking.map(|b| b.replicated_levels),
                bank_ports: c.banking.map(|b| b.ports),
                bank_map: c.banking.map(|b| b.mapping),
                cache_lines: c.memory.map(|m| m.cache_lines),
                memory_data_bits: c.memory.map(|m| m.data_bits),
                cache_tags: c.memory.map(|m| m.tags),
                result_streams: Some(c.result_streams),
            },
        }
    }
}

/// Coordinate bits of x, y and z: the photon word's layout. On the command line
/// one width for every axis or three (`10`, `12,9,5`); in the file three
/// (`[12, 9, 5]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct Widths(pub [u32; 3]);

impl<'de> Deserialize<'de> for Widths {
    /// Exactly three widths: toml would drop a fourth into a three-element array.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<u32>::deserialize(d)?;
        <[u32; 3]>::try_from(v.as_slice()).map(Widths).map_err(|_| {
            serde::de::Error::custom(format!(
                "coordinate_bits = {v:?}: expected three widths (x, y, z), got {}",
                v.len()
            ))
        })
    }
}

impl FromStr for Widths {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let v: Vec<u32> = s
            .split(',')
            .map(|w| w.trim().parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{s:?}: {e}"))?;
        match v.as_slice() {
            [w] => Ok(Widths([*w; 3])),
            [x, y, z] => Ok(Widths([*x, *y, *z])),
            _ => Err(format!(
                "{s:?}: one width for every axis or three (x,y,z), got {}",
                v.len()
            )),
        }
    }
}

impl fmt::Display for Widths {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.0;
        if x == y && y == z {
            write!(f, "{x}")
        } else {
            write!(f, "{x},{y},{z}")
        }
    }
}
