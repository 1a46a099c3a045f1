//! The AXI4 (full) read channels, the port a memory controller (Xilinx MIG,
//! LiteDRAM's AXI frontend) offers: read address (`ar*`, with bursts: `arlen`
//! beats − 1, `arsize` = log2 of a beat's bytes, `arburst` INCR) and read data
//! (`r*`, `rlast` on a burst's last beat, `rresp` OKAY = 0). The core only reads
//! the map in memory (the host loads it), so the write channels are left out; one
//! ID, so the bursts return in the order they were asked (AMBA AXI4 spec, A5.3).
//! `D` is the data width in bits.

use rust_hdl::prelude::*;

/// A byte address in the memory.
pub type AxiAddr = Bits<32>;

/// `arburst` INCR: consecutive addresses.
pub const BURST_INCR: u64 = 1;

/// The master's side (`m_axi_*`).
#[derive(LogicInterface, Default)]
#[join = "AxiReadSlave"]
pub struct AxiReadMaster<const D: usize> {
    pub arvalid: Signal<Out, bool>,
    pub arready: Signal<In, bool>,
    pub araddr: Signal<Out, AxiAddr>,
    pub arlen: Signal<Out, Bits<8>>,
    pub arsize: Signal<Out, Bits<3>>,
    pub arburst: Signal<Out, Bits<2>>,
    pub rvalid: Signal<In, bool>,
    pub rready: Signal<Out, bool>,
    pub rdata: Signal<In, Bits<D>>,
    pub rlast: Signal<In, bool>,
    pub rresp: Signal<In, Bits<2>>,
}

/// The memory's side (`s_axi_*`).
#[derive(LogicInterface, Default)]
#[join = "AxiReadMaster"]
pub struct AxiReadSlave<const D: usize> {
    pub arvalid: Signal<In, bool>,
    pub arready: Signal<Out, bool>,
    pub araddr: Signal<In, AxiAddr>,
    pub arlen: Signal<In, Bits<8>>,
    pub arsize: Signal<In, Bits<3>>,
    pub arburst: Signal<In, Bits<2>>,
    pub rvalid: Signal<Out, bool>,
    pub rready: Signal<In, bool>,
    pub rdata: Signal<Out, Bits<D>>,
    pub rlast: Signal<Out, bool>,
    pub rresp: Signal<Out, Bits<2>>,
}
