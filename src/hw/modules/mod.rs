//! The paper's controller (`--controller modules`): a port shared round robin by Q
//! QueryModules (§4.5, `SearchPort`), each holding one query's radius, traversal
//! state and found list (§4.2) with the bit-serial MaxFinder over bit-transposed
//! distances (§4.4); `ResultReadout` sequences the port's result packets.

pub mod max_finder;
pub mod query_module;
pub mod result_readout;
pub mod search_port;
