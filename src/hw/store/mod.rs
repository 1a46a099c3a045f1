//! Where the photons live. The paper's TreeModule (§4.1): the packed kd-tree in one
//! true dual-port BlockRAM, one read per port per cycle. Beyond the paper, the
//! banked store: one map spread over B BlockRAM banks below the replicated top
//! levels (`BankStore`, `BankMap`), reached through a crossbar with a round robin
//! per bank port (`BankCrossbar`); `ReadIssue`, a barrel datapath's reads to its
//! replica or a bank, each slot parked while its bank is busy; with the map in
//! external memory (`hw::memory`) the banks are a cache and `MissPark` parks a
//! slot whose read missed until its block has had time to arrive.

pub mod bank_crossbar;
pub mod bank_map;
pub mod bank_store;
pub mod miss_park;
pub mod read_issue;
pub mod read_place;
pub mod tree_module;
