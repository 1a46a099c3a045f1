//! FPGA devices and what they hold: `plan` derives a banked store's B, L and D
//! from a map's size and a device's BlockRAM and logic; `banked_core` makes that plan
//! a core configuration (`--device`).

pub mod banked_core;
pub mod plan;
