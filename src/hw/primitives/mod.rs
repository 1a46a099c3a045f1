//! The small blocks every larger one is built from: BlockRAM and LUT-RAM with the
//! read timing the FPGA gives them (§4.1), the lowest-set-bit priority encoder
//! (§4.4's "lowest slot among ties"), the round-robin arbiter of a shared port
//! (§4.5), the registered free pick, multiplexer trees, the skid-buffer register
//! slice and the offer queue for a late `ready`; the AXI4 read channels of an
//! external memory.

pub mod axi4_read;
pub mod bank_bus;
pub mod block_ram;
pub mod free_pick;
pub mod lut_ram;
pub mod mux_trees;
pub mod offer_queue;
pub mod port_arbiter;
pub mod priority_encoder;
pub mod register_slice;
pub mod stream;
