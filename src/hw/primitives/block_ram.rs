//! BlockRam: a simple dual-port memory with one synchronous write port and one
//! synchronous read port (the read data is registered: it appears the cycle after
//! its index) — what yosys maps to an ECP5 DP16KD or a Virtex-6 RAMB18/36.
//!
//! The [`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort) keeps two kinds of
//! per-(query, entry) state in it, hundreds of entries that a LUT-RAM would need a
//! read multiplexer for, and that are read one entry at a time with a cycle to
//! spare: the found list for the read-out and each level's far-cell offsets
//! (`Traversal::Cell`) for the ascent. BlockRAMs are the device's least used
//! resource (the largest placed array used 4 of the ECP5-85k's 208).
//!
//! A write and a read of the same entry in the same cycle never happen in this
//! design (the entries of a query in flight are written, those of other queries
//! read), so the template has no collision logic; the model reads before it
//! writes, as a read-first BlockRAM. The memory starts at zero in both.

use rust_hdl::prelude::*;

/// Index of an entry.
pub type BramIndex = Bits<16>;
/// An entry (the configured `width` low bits are stored).
pub type BramWord = Bits<64>;

#[derive(LogicBlock)]
pub struct BlockRam {
    pub clock: Signal<In, Clock>,
    pub write_enable: Signal<In, bool>,
    pub write_index: Signal<In, BramIndex>,
    pub write_data: Signal<In, BramWord>,
    pub read_index: Signal<In, BramIndex>,
    /// The entry at the `read_index` of the previous cycle.
    pub read_data: Signal<Out, BramWord>,
    _mem: Vec<u64>,
    _width: u32,
    /// Asks synthesis for distributed (LUT) RAM: the same registered read.
    _distributed: bool,
}

impl BlockRam {
    /// `2^index_bits` entries (index_bits 1..=16) of `width` bits (1..=64).
    pub fn new(index_bits: u32, width: u32) -> Self {
        assert!((1..=16).contains(&index_bits) && (1..=64).contains(&width));
        BlockRam {
            clock: Default::default(),
            write_enable: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            read_index: Default::default(),
            read_data: Default::default(),
            _mem: vec![0; 1 << index_bits],
            _width: width,
            _distributed: false,
        }
    }

    /// [`BlockRam::new`] held in distributed RAM (LUT-RAM and the read register):
    /// for a memory that would fill a small part of the BlockRAMs its width takes
    /// (`FoundHeap`'s upper levels), where BlockRAMs are what the device runs out of.
    pub fn distributed(index_bits: u32, width: u32) -> Self {
        BlockRam {
            _distributed: true,
            ..Self::new(index_bits, width)
        }
    }

    /// (index bits, width) of a memory that synthesis places in BlockRAM (None
    /// for distributed RAM), for a device's BlockRAM count.
    pub fn block_ram_shape(&self) -> Option<(u32, u32)> {
        (!self._distributed).then(|| (self._mem.len().trailing_zeros(), self._width))
    }

    /// [`BlockRam::block_ram_shape`] of each of `rams` held in BlockRAM.
    pub fn shapes<'a>(rams: impl IntoIterator<Item = &'a BlockRam>) -> Vec<(u32, u32)> {
        rams.into_iter()
            .filter_map(BlockRam::block_ram_shape)
            .collect()
    }

    fn mask(&self) -> u64 {
        if self._width >= 64 {
            u64::MAX
        } else {
            (1u64 << self._width) - 1
        }
    }

    fn index_bits(&self) -> u32 {
        self._mem.len().trailing_zeros()
    }
}

impl Logic for BlockRam {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let last = self._mem.len() - 1;
            let r = self.read_index.val().to_u64() as usize & last;
            self.read_data.next = self._mem[r].into();
            if self.write_enable.val() {
                let w = self.write_index.val().to_u64() as usize & last;
                self._mem[w] = self.write_data.val().to_u64() & self.mask();
            }
        }
    }

    fn connect(&mut self) {
        self.read_data.connect();
    }

    fn hdl(&self) -> Verilog {
        let w = self._width;
        let a = self.index_bits();
        let (kind, style) = if self._distributed {
            ("Distributed RAM", " (* ram_style = \"distributed\" *)")
        } else {
            ("BlockRAM", "")
        };
        Verilog::Custom(format!(
            "\
// {entries} entries of {w} bits: {kind}, registered read. No entry is read and
// written in the same cycle: no collision logic.
(* no_rw_check *){style}
reg [{wm}:0] mem[0:{last}];
integer init_index;
initial for (init_index = 0; init_index < {entries}; init_index = init_index + 1) mem[init_index] = 0;
initial read_data = 0;

always @(posedge clock) begin
   if (write_enable) begin
      mem[write_index[{am}:0]] <= write_data[{wm}:0];
   end
   read_data <= {{{pad}mem[read_index[{am}:0]]}};
end
",
            entries = 1u64 << a,
            wm = w - 1,
            last = (1u64 << a) - 1,
            am = a - 1,
            pad = if w < 64 {
                format!("{}'d0, ", 64 - w)
            } else {
                String::new()
            },
        ))
    }
}
