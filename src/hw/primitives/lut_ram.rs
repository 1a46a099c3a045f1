//! LutRam: a small memory with one synchronous write port and one asynchronous
//! read port — distributed RAM (found lists where they are cheapest).
//! A QueryModule's found-index list (K entries of H bits) and its path memory
//! (H − 1 levels of distance bits) are written one entry per cycle and read one
//! entry at a time, so they need no flip-flop per bit and no read multiplexer: a
//! few LUT-RAM primitives hold them (Xilinx RAM32M/RAM64M, ECP5 DPR16X4), where
//! flip-flops and an AND-OR read-out cost a LUT per few bits. (The MaxFinder's
//! distance rows stay registers: they are read bit-transposed, a row across all
//! slots per cycle, which no RAM port gives.)
//!
//! The memory has a power-of-two number of entries, so a read needs no range check
//! (an index past `depth` reads an entry that is never written, zero): a range
//! check would put a comparator in front of every read, on the path from a
//! QueryModule's path memory to its next decision. Writes past `depth` are dropped.
//!
//! rust-hdl has no such primitive, so this is a custom block like the TreeModule:
//! `update()` is the simulation model, `hdl()` the template yosys maps to LUT-RAM.
//! The memory starts at zero in both.

use rust_hdl::prelude::*;

/// Index of an entry.
pub type RamIndex = Bits<8>;
/// An entry (the configured `width` low bits are stored).
pub type RamWord = Bits<32>;

#[derive(LogicBlock)]
pub struct LutRam {
    pub clock: Signal<In, Clock>,
    pub write_enable: Signal<In, bool>,
    pub write_index: Signal<In, RamIndex>,
    pub write_data: Signal<In, RamWord>,
    pub read_index: Signal<In, RamIndex>,
    /// The entry at `read_index`, combinationally (a write shows after its edge).
    pub read_data: Signal<Out, RamWord>,
    _mem: Vec<u32>,
    _depth: usize,
    _width: u32,
}

impl LutRam {
    /// `depth` entries (1..=64) of `width` bits (1..=32).
    pub fn new(depth: usize, width: u32) -> Self {
        assert!((1..=64).contains(&depth) && (1..=32).contains(&width));
        LutRam {
            clock: Default::default(),
            write_enable: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            read_index: Default::default(),
            read_data: Default::default(),
            _mem: vec![0; depth.next_power_of_two()],
            _depth: depth,
            _width: width,
        }
    }

    fn mask(&self) -> u32 {
        if self._width >= 32 {
            u32::MAX
        } else {
            (1u32 << self._width) - 1
        }
    }

    /// Address bits of the power-of-two memory (at least one).
    fn index_bits(&self) -> u32 {
        self._mem.len().trailing_zeros().max(1)
    }
}

impl Logic for LutRam {
    fn update(&mut self) {
        if self.clock.pos_edge() && self.write_enable.val() {
            let i = self.write_index.val().to_u64() as usize;
            if i < self._depth {
                self._mem[i] = self.write_data.val().to_u64() as u32 & self.mask();
            }
        }
        let r = self.read_index.val().to_u64() as usize & ((1 << self.index_bits()) - 1);
        let v = self._mem.get(r).copied().unwrap_or(0);
        self.read_data.next = (v as u64).into();
    }

    fn connect(&mut self) {
        self.read_data.connect();
    }

    fn hdl(&self) -> Verilog {
        let depth = self._depth;
        let entries = 1usize << self.index_bits();
        let w = self._width;
        let a = self.index_bits();
        Verilog::Custom(format!(
            "\
// {depth} entries of {w} bits in a memory of {entries}: distributed RAM, synchronous
// write, asynchronous read without a range check.
reg [{wm}:0] mem[0:{last}];
integer init_index;
initial for (init_index = 0; init_index < {entries}; init_index = init_index + 1) mem[init_index] = 0;

always @(posedge clock) begin
   if (write_enable && (write_index < {depth})) begin
      mem[write_index[{am}:0]] <= write_data[{wm}:0];
   end
end

always @(*) read_data = {{{pad}mem[read_index[{am}:0]]}};
",
            wm = w - 1,
            last = entries - 1,
            am = a - 1,
            pad = if w < 32 {
                format!("{}'d0, ", 32 - w)
            } else {
                String::new()
            },
        ))
    }
}
