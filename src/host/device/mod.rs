//! FPGA devices and what they hold: `devices` says what each has and what the
//! core's parts cost on it; `plan` derives a banked store's B, L and D
//! from a map's size and a device's BlockRAM and logic; `banked_core` makes that plan
//! a core configuration (`--device`).

pub mod banked_core;
pub mod devices;
pub mod plan;
