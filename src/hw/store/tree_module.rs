//! TreeModule (paper §4.2): the BlockRAM holding the kd-tree, photon words by heap
//! address. True dual-port: port A loads the tree (write) and reads for the first
//! SearchModule, port B reads for the second (§4.5: both BlockRAM ports are used).
//! A read returns the word in the next cycle (registered output, read-first).
//!
//! rust-hdl has no true dual-port RAM, so this is a custom block: `update()` is the
//! simulation model and `hdl()` emits the standard two-`always` template that yosys
//! and Vivado/ISE infer as RAMB36E1/RAMB18E1, with the exact word width and depth of
//! the configuration (the ports are `W` = 32 or 64 bits, the memory only as wide as
//! the layout's word).
//!
//! The memory carries yosys' `no_rw_check`: port B never reads while port A writes
//! (the core loads a map only while every QueryModule is free, `core.rs`), so what a
//! read returns when both ports hit one address in one cycle does not matter.
//! Without it yosys builds the Verilog's read-first collision rule out of an address
//! comparator and a bypass multiplexer on port B, which puts port B's read address
//! on the core's critical path.

use crate::hw::config::core_config::{Addr, Word};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct TreeModule<const W: usize> {
    pub clock: Signal<In, Clock>,
    /// Port A: address for the load write and for reads.
    pub a_address: Signal<In, Addr>,
    pub a_write_enable: Signal<In, bool>,
    pub a_write_data: Signal<In, Word<W>>,
    pub a_read_data: Signal<Out, Word<W>>,
    /// Port B: read only.
    pub b_address: Signal<In, Addr>,
    pub b_read_data: Signal<Out, Word<W>>,
    _mem: Vec<u64>,
    _address_bits: u32,
    _word_bits: u32,
}

impl<const W: usize> TreeModule<W> {
    /// A TreeModule of 2^`address_bits` words of `word_bits` bits.
    pub fn new(address_bits: u32, word_bits: u32) -> Self {
        assert!(
            (1..=W as u32).contains(&word_bits),
            "a {word_bits}-bit word does not fit the {W}-bit TreeModule ports"
        );
        TreeModule {
            clock: Default::default(),
            a_address: Default::default(),
            a_write_enable: Default::default(),
            a_write_data: Default::default(),
            a_read_data: Default::default(),
            b_address: Default::default(),
            b_read_data: Default::default(),
            _mem: vec![0; 1 << address_bits],
            _address_bits: address_bits,
            _word_bits: word_bits,
        }
    }

    fn index(&self, address: Addr) -> usize {
        (address.to_u64() as usize) & (self._mem.len() - 1)
    }

    fn word_mask(&self) -> u64 {
        if self._word_bits >= 64 {
            u64::MAX
        } else {
            (1u64 << self._word_bits) - 1
        }
    }
}

impl<const W: usize> Logic for TreeModule<W> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let a = self.index(self.a_address.val());
            let b = self.index(self.b_address.val());
            // Read-first on port A, as in the Verilog below.
            self.a_read_data.next = self._mem[a].into();
            self.b_read_data.next = self._mem[b].into();
            if self.a_write_enable.val() {
                self._mem[a] = self.a_write_data.val().to_u64() & self.word_mask();
            }
        }
    }

    fn connect(&mut self) {
        self.a_read_data.connect();
        self.b_read_data.connect();
    }

    fn hdl(&self) -> Verilog {
        let w = self._word_bits;
        let h = self._address_bits;
        Verilog::Custom(format!(
            "\
// {depth} photon words of {w} bits: BlockRAM, one always block per port. Port B
// never reads while port A writes (loads wait for an idle core): no collision logic.
(* no_rw_check *)
reg [{wm}:0] mem[0:{last}];

always @(posedge clock) begin
   if (a_write_enable) begin
      mem[a_address[{hm}:0]] <= a_write_data[{wm}:0];
   end
   a_read_data <= mem[a_address[{hm}:0]];
end

always @(posedge clock) begin
   b_read_data <= mem[b_address[{hm}:0]];
end
",
            depth = 1u64 << h,
            w = w,
            wm = w - 1,
            hm = h - 1,
            last = (1u64 << h) - 1,
        ))
    }
}
