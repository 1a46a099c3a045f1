//! What a core is, before any block is built: the photon word (§4: x, y, z and the
//! split axis in one BlockRAM word), the metric (§4, Table 2: the paper's 12-bit
//! absolute distance, or squared L2), the traversal (§2.2: the ascent), the
//! controller, the banked store's shape, and [`config::CoreConfig`], the one
//! elaborated description every block reads its widths and counts from. A core is
//! made only by the validating [`config_builder::CoreBuilder`], from code or from a
//! [`core_spec::CoreSpec`], the one description a user writes: the command line's
//! core options, the TOML core file (`core_file`, `--core`) and the core of each
//! synth/results.json record.

pub mod bank_config;
pub mod config_builder;
pub mod config_widths;
pub mod controller;
pub mod core_config;
pub mod core_file;
pub mod core_spec;
pub mod memory_config;
pub mod memory_layout;
pub mod metric;
pub mod photon_word;
pub mod traversal;
