//! The photon-search core (paper §4) as rust-hdl blocks.

pub mod metric;
pub mod photon_word;
