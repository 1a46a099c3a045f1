//! The core as Verilog for synthesis (§5: the paper's ISE flow; open tools here):
//! rust-hdl's export and the post-processing that makes it behave like the Rust
//! simulation (`export`), the top's port list (`ports`), the registered I/O shell for
//! place and route (`shell`) and the AXI4-Stream top (`axis_top`). Builds on the
//! blocks; nothing in them imports it.

pub mod axis_top;
pub mod ports;
pub mod shell;
pub mod verilog;
