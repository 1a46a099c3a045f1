//! Running the core: the one simulation driver (`driver`: load a map, stream
//! queries, collect results, the same for every target) and its two targets,
//! rust-hdl's native simulation (`native`) and the exported Verilog under Verilator
//! (`verilator`, its models in a safe cache, `model_cache`); `top` is what both
//! tops offer the driver; `axi_memory`, the external memory the AXI4 master
//! reads. Builds on the blocks and the export.

pub mod axi_memory;
pub mod driver;
pub mod dut;
pub mod entry_distances;
pub mod model_cache;
pub mod native;
pub mod sim_stats;
pub mod top;
pub mod verilator;
pub mod verilator_harness;
