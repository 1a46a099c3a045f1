//! FoundMax: a [`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort)'s found
//! distances, K per query slot, and the maximum of one slot's list with the lowest
//! entry holding it — what the paper's MaxFinder (§4.4) gives a QueryModule, for
//! the one slot per cycle the port's datapath handles.
//!
//! The MaxFinder needs one cycle per distance bit and one instance per
//! QueryModule; here the K entries of a slot are K LUT-RAMs read at once (one
//! entry per slot in each) into a tree of comparators pipelined over three
//! stages: the read and the first level (B), two levels (C), the rest (M). One
//! tree per port, a new slot every cycle, the maximum two cycles after the read.
//! On a tie the lower entry wins, which is knn.rs's rule ("the lowest list slot
//! among ties"); entries at and past the slot's k hold nothing and read as zero,
//! so a real entry (below them) wins every tie with them.
//!
//! The write port is registered: the entry is written at the end of the next cycle,
//! and a read in that cycle sees it by forwarding. In a BarrelPort the entry comes
//! from the slot state's asynchronous read in stage A; unregistered, that read,
//! the list rule and the K entries' write-enable decode were one path, ending at
//! the LUT-RAMs' write enables. The forwarded entry does not replace its leaf (a
//! multiplexer on every bit of every leaf): its leaf reads as zero, like an entry
//! past k, and the entry itself travels beside the tree as one more candidate.
//! In stage M it is compared with each of M's leaves, beside the tree's two levels
//! rather than after them (a third comparison in series): it is the maximum if it
//! beats all of them, on a tie the lower entry winning, as in the tree.
//!
//! The tree is flat: leaves 0..P (P a power of two, at least 8), node `P + i`
//! over nodes `2i` and `2i + 1`; each stage's winners are the next stage's leaves.

use crate::hw::config::core_config::{CoreConfig, Count, Dist, Entry, ModuleIndex};
use crate::hw::many;
use crate::hw::primitives::lut_ram::LutRam;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct FoundMax {
    pub clock: Signal<In, Clock>,
    /// Write `write_dist` into entry `write_pos` of slot `write_slot` (registered:
    /// a read in the next cycle sees it).
    pub write_enable: Signal<In, bool>,
    pub write_slot: Signal<In, ModuleIndex>,
    pub write_pos: Signal<In, Entry>,
    pub write_dist: Signal<In, Dist>,
    /// Read the first `read_k` entries of slot `read_slot` (stage B; a write of
    /// the cycle before shows).
    pub read_slot: Signal<In, ModuleIndex>,
    pub read_k: Signal<In, Count>,
    /// Two cycles after the read (stage M): the maximum and its lowest entry.
    pub max: Signal<Out, Dist>,
    pub max_pos: Signal<Out, Entry>,
    dist_mask: Constant<Dist>,
    /// The distances fit 16 bits: each comparison is made on the low 16. The
    /// datapath's values are 32 bits with the bits above masked off, and yosys
    /// (0.23) keeps a comparison as wide as its operands: a 32-bit carry chain
    /// where 16 bits would do. (A 24-bit class measured larger than the masked
    /// 32-bit comparison once mapped, so wider distances keep that.)
    cmp16: Constant<bool>,
    entry_index: Vec<Constant<Entry>>,
    /// One LUT-RAM per entry (padded to P with never-written ones).
    found_dist: Vec<LutRam>,
    /// The write, registered; `w_here`: it is to the slot being read.
    w_enable: DFF<bool>,
    w_slot: DFF<ModuleIndex>,
    w_pos: DFF<Entry>,
    w_dist: DFF<Dist>,
    w_here: Signal<Local, bool>,
    /// The forwarded entry beside the tree (valid, distance, entry) in C and M.
    c_fwd: DFF<bool>,
    c_fwd_dist: DFF<Dist>,
    c_fwd_pos: DFF<Entry>,
    m_fwd: DFF<bool>,
    m_fwd_dist: DFF<Dist>,
    m_fwd_pos: DFF<Entry>,
    /// The forwarded entry beats every leaf of M so far (so, at the end, the root).
    m_fwd_wins: Signal<Local, bool>,
    /// Each comparison's result: the right node is larger (per tree node), the
    /// forwarded entry is larger than or equal to M's leaf.
    b_gt: Vec<Signal<Local, bool>>,
    c_gt: Vec<Signal<Local, bool>>,
    m_gt: Vec<Signal<Local, bool>>,
    m_fwd_gt: Vec<Signal<Local, bool>>,
    m_fwd_eq: Vec<Signal<Local, bool>>,
    b_node: Vec<Signal<Local, Dist>>,
    b_node_ix: Vec<Signal<Local, Entry>>,
    _b_leaves: usize,
    _b_inner: usize,
    _b_out: usize,
    c_leaf: Vec<DFF<Dist>>,
    c_leaf_ix: Vec<DFF<Entry>>,
    c_node: Vec<Signal<Local, Dist>>,
    c_node_ix: Vec<Signal<Local, Entry>>,
    _c_leaves: usize,
    _c_inner: usize,
    _c_out: usize,
    m_leaf: Vec<DFF<Dist>>,
    m_leaf_ix: Vec<DFF<Entry>>,
    m_node: Vec<Signal<Local, Dist>>,
    m_node_ix: Vec<Signal<Local, Entry>>,
    _m_leaves: usize,
    _m_inner: usize,
    _m_root: usize,
}

impl FoundMax {
    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        let db = cfg.dist_bits();
        // One level in B, two in C: at least 8 leaves.
        let p = cfg.k.next_power_of_two().max(8);
        FoundMax {
            clock: Default::default(),
            write_enable: Default::default(),
            write_slot: Default::default(),
            write_pos: Default::default(),
            write_dist: Default::default(),
            read_slot: Default::default(),
            read_k: Default::default(),
            max: Default::default(),
            max_pos: Default::default(),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            cmp16: Constant::new(db <= 16),
            entry_index: (0..p)
                .map(|i| Constant::new(Entry::from(i as u64)))
                .collect(),
            found_dist: (0..p)
                .map(|i| {
                    if i < cfg.k {
                        LutRam::new(q, db)
                    } else {
                        LutRam::new(1, 1)
                    }
                })
                .collect(),
            w_enable: Default::default(),
            w_slot: Default::default(),
            w_pos: Default::default(),
            w_dist: Default::default(),
            w_here: Default::default(),
            c_fwd: Default::default(),
            c_fwd_dist: Default::default(),
            c_fwd_pos: Default::default(),
            m_fwd: Default::default(),
            m_fwd_dist: Default::default(),
            m_fwd_pos: Default::default(),
            m_fwd_wins: Default::default(),
            b_gt: many(p / 2),
            c_gt: many(p / 4 + p / 8),
            m_gt: many(p / 8 - 1),
            m_fwd_gt: many(p / 8),
            m_fwd_eq: many(p / 8),
            b_node: many(p + p / 2),
            b_node_ix: many(p + p / 2),
            _b_leaves: p,
            _b_inner: p / 2,
            _b_out: p,
            c_leaf: many(p / 2),
            c_leaf_ix: many(p / 2),
            c_node: many(p / 2 + p / 4 + p / 8),
            c_node_ix: many(p / 2 + p / 4 + p / 8),
            _c_leaves: p / 2,
            _c_inner: p / 4 + p / 8,
            _c_out: p / 2 + p / 4,
            m_leaf: many(p / 8),
            m_leaf_ix: many(p / 8),
            m_node: many(p / 4 - 1),
            m_node_ix: many(p / 4 - 1),
            _m_leaves: p / 8,
            _m_inner: p / 8 - 1,
            _m_root: p / 4 - 2,
        }
    }
}

impl Logic for FoundMax {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, w_enable, w_slot, w_pos, w_dist, c_fwd, c_fwd_dist, c_fwd_pos, m_fwd,
            m_fwd_dist, m_fwd_pos
        );
        self.w_enable.d.next = self.write_enable.val();
        self.w_slot.d.next = self.write_slot.val();
        self.w_pos.d.next = self.write_pos.val();
        self.w_dist.d.next = self.write_dist.val() & self.dist_mask.val();
        for i in 0..self.found_dist.len() {
            self.found_dist[i].clock.next = self.clock.val();
            self.found_dist[i].write_enable.next =
                self.w_enable.q.val() && (self.w_pos.q.val() == self.entry_index[i].val());
            self.found_dist[i].write_index.next = self.w_slot.q.val();
            self.found_dist[i].write_data.next = self.w_dist.q.val();
            self.found_dist[i].read_index.next = self.read_slot.val();
        }
        // Stage B: the read (with the registered write forwarded) and the first level.
        self.w_here.next = self.w_enable.q.val() && (self.w_slot.q.val() == self.read_slot.val());
        for i in 0..self.found_dist.len() {
            self.b_node[i].next = 0.into();
            if (self.entry_index[i].val() < self.read_k.val())
                && !(self.w_here.val() && (self.w_pos.q.val() == self.entry_index[i].val()))
            {
                self.b_node[i].next = self.found_dist[i].read_data.val() & self.dist_mask.val();
            }
            self.b_node_ix[i].next = self.entry_index[i].val();
        }
        self.c_fwd.d.next = self.w_here.val() && (self.w_pos.q.val() < self.read_k.val());
        self.c_fwd_dist.d.next = self.w_dist.q.val() & self.dist_mask.val();
        self.c_fwd_pos.d.next = self.w_pos.q.val();
        self.m_fwd.d.next = self.c_fwd.q.val();
        self.m_fwd_dist.d.next = self.c_fwd_dist.q.val() & self.dist_mask.val();
        self.m_fwd_pos.d.next = self.c_fwd_pos.q.val();
        for p in self._b_leaves..(self._b_leaves + 1) {
            for i in 0..self._b_inner {
                // The larger of two; on a tie the lower entry (knn.rs: "the lowest
                // list slot among ties").
                self.b_gt[i].next = self.b_node[2 * i + 1].val() > self.b_node[2 * i].val();
                if self.cmp16.val() {
                    self.b_gt[i].next = self.b_node[2 * i + 1].val().get_bits::<16>(0)
                        > self.b_node[2 * i].val().get_bits::<16>(0);
                }
                if self.b_gt[i].val() {
                    self.b_node[p + i].next = self.b_node[2 * i + 1].val() & self.dist_mask.val();
                    self.b_node_ix[p + i].next = self.b_node_ix[2 * i + 1].val();
                } else {
                    self.b_node[p + i].next = self.b_node[2 * i].val() & self.dist_mask.val();
                    self.b_node_ix[p + i].next = self.b_node_ix[2 * i].val();
                }
            }
        }
        for p in self._b_out..(self._b_out + 1) {
            for j in 0..self.c_leaf.len() {
                self.c_leaf[j].clock.next = self.clock.val();
                self.c_leaf_ix[j].clock.next = self.clock.val();
                self.c_leaf[j].d.next = self.b_node[p + j].val() & self.dist_mask.val();
                self.c_leaf_ix[j].d.next = self.b_node_ix[p + j].val();
            }
        }

        // Stage C: two more levels.
        for j in 0..self.c_leaf.len() {
            self.c_node[j].next = self.c_leaf[j].q.val() & self.dist_mask.val();
            self.c_node_ix[j].next = self.c_leaf_ix[j].q.val();
        }
        for n in self._c_leaves..(self._c_leaves + 1) {
            for i in 0..self._c_inner {
                self.c_gt[i].next = self.c_node[2 * i + 1].val() > self.c_node[2 * i].val();
                if self.cmp16.val() {
                    self.c_gt[i].next = self.c_node[2 * i + 1].val().get_bits::<16>(0)
                        > self.c_node[2 * i].val().get_bits::<16>(0);
                }
                if self.c_gt[i].val() {
                    self.c_node[n + i].next = self.c_node[2 * i + 1].val() & self.dist_mask.val();
                    self.c_node_ix[n + i].next = self.c_node_ix[2 * i + 1].val();
                } else {
                    self.c_node[n + i].next = self.c_node[2 * i].val() & self.dist_mask.val();
                    self.c_node_ix[n + i].next = self.c_node_ix[2 * i].val();
                }
            }
        }
        for p in self._c_out..(self._c_out + 1) {
            for j in 0..self.m_leaf.len() {
                self.m_leaf[j].clock.next = self.clock.val();
                self.m_leaf_ix[j].clock.next = self.clock.val();
                self.m_leaf[j].d.next = self.c_node[p + j].val() & self.dist_mask.val();
                self.m_leaf_ix[j].d.next = self.c_node_ix[p + j].val();
            }
        }

        // Stage M: the rest, and the root.
        self.m_fwd_wins.next = self.m_fwd.q.val();
        for j in 0..self.m_leaf.len() {
            self.m_node[j].next = self.m_leaf[j].q.val() & self.dist_mask.val();
            self.m_node_ix[j].next = self.m_leaf_ix[j].q.val();
            self.m_fwd_gt[j].next = self.m_fwd_dist.q.val() > self.m_leaf[j].q.val();
            self.m_fwd_eq[j].next = self.m_fwd_dist.q.val() == self.m_leaf[j].q.val();
            if self.cmp16.val() {
                self.m_fwd_gt[j].next = self.m_fwd_dist.q.val().get_bits::<16>(0)
                    > self.m_leaf[j].q.val().get_bits::<16>(0);
                self.m_fwd_eq[j].next = self.m_fwd_dist.q.val().get_bits::<16>(0)
                    == self.m_leaf[j].q.val().get_bits::<16>(0);
            }
            self.m_fwd_wins.next = self.m_fwd_wins.val()
                && (self.m_fwd_gt[j].val()
                    || (self.m_fwd_eq[j].val()
                        && (self.m_fwd_pos.q.val() < self.m_leaf_ix[j].q.val())));
        }
        for n in self._m_leaves..(self._m_leaves + 1) {
            for i in 0..self._m_inner {
                self.m_gt[i].next = self.m_node[2 * i + 1].val() > self.m_node[2 * i].val();
                if self.cmp16.val() {
                    self.m_gt[i].next = self.m_node[2 * i + 1].val().get_bits::<16>(0)
                        > self.m_node[2 * i].val().get_bits::<16>(0);
                }
                if self.m_gt[i].val() {
                    self.m_node[n + i].next = self.m_node[2 * i + 1].val() & self.dist_mask.val();
                    self.m_node_ix[n + i].next = self.m_node_ix[2 * i + 1].val();
                } else {
                    self.m_node[n + i].next = self.m_node[2 * i].val() & self.dist_mask.val();
                    self.m_node_ix[n + i].next = self.m_node_ix[2 * i].val();
                }
            }
        }
        for r in self._m_root..(self._m_root + 1) {
            self.max.next = self.m_node[r].val();
            self.max_pos.next = self.m_node_ix[r].val();
            // The forwarded entry, if it beats the root (its own leaf read as zero).
            if self.m_fwd_wins.val() {
                self.max.next = self.m_fwd_dist.q.val();
                self.max_pos.next = self.m_fwd_pos.q.val();
            }
        }
    }
}
