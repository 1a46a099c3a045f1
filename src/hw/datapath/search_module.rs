//! SearchModule (paper §4.3): everything a QueryModule needs to know about one photon
//! read, pipelined so that it accepts a read every cycle. The read's context
//! ([`ReadRequest`]: the QueryModule's index, query, radius, full flag and traversal
//! state) travels with the data (§4.5: the
//! SearchModule carries the id so several QueryModules can share it).
//!
//! The queries' coordinates live here, one LUT-RAM entry per QueryModule
//! of the port, written when the module is loaded and read with the id the request
//! carries: a QueryModule holds no coordinates and the port's request selection no
//! longer ORs Q copies of them. The lookup is in stage 0, from registers, so it
//! costs the distance stage nothing.
//!
//! Timing, with the read granted in cycle t:
//! * t:   request latched (stage 0) while the TreeModule reads the word;
//! * t+1: (pipelined core) word and request registered (stage W);
//! * t+1 (t+2 pipelined): word unpacked; DistModule's distance and split-axis
//!   distance (the paper's AxisDistModule) -> stage 1;
//! * t+2 (t+3): NextIndexModule and the in-range test of the registered distance
//!   -> result registers, seen by the QueryModules at t+3 (t+4).

use crate::hw::config::core_config::{
    low_mask, Addr, Coord, CoreConfig, Dist, ModuleIndex, ModuleMask, Word,
};
use crate::hw::config::metric::Metric;
use crate::hw::datapath::dist_module::DistModule;
use crate::hw::datapath::next_index::NextIndexModule;
use crate::hw::primitives::lut_ram::LutRam;
use crate::hw::primitives::stream::{QueryBeat, ReadRequest, ReadResult};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct SearchModule<const W: usize> {
    pub clock: Signal<In, Clock>,
    /// Drops the reads in flight (their QueryModules are being reset too).
    pub reset: Signal<In, bool>,
    /// The read granted this cycle (same cycle as the TreeModule address).
    pub request_valid: Signal<In, bool>,
    pub request: Signal<In, ReadRequest>,
    /// The TreeModule's word, one cycle after the request.
    pub word: Signal<In, Word<W>>,
    pub photon_count: Signal<In, Addr>,
    /// A query loaded into QueryModule `query_module` this cycle: its coordinates.
    pub query_write: Signal<In, bool>,
    pub query_module: Signal<In, ModuleIndex>,
    pub query: Signal<In, QueryBeat>,
    /// The result, broadcast to the port's QueryModules.
    pub result_valid: Signal<Out, bool>,
    /// Which QueryModule the result is for, one-hot (zero when none): decoded a
    /// stage early so that a module's "mine" is one flip-flop, not a comparison
    /// behind the broadcast's fan-out.
    pub result_for: Signal<Out, ModuleMask>,
    pub result: Signal<Out, ReadResult>,
    /// The coordinates of each QueryModule's query (Q entries per axis).
    query_x: LutRam,
    query_y: LutRam,
    query_z: LutRam,
    /// Stage 0's request with its query's coordinates.
    looked_up: Signal<Local, ReadRequest>,
    dist_module: DistModule,
    next_index: NextIndexModule,
    // Word layout (PhotonLayout) as elaboration-time constants.
    offset_x: Constant<Bits<8>>,
    offset_y: Constant<Bits<8>>,
    offset_z: Constant<Bits<8>>,
    offset_axis: Constant<Bits<8>>,
    mask_x: Constant<Word<W>>,
    mask_y: Constant<Word<W>>,
    mask_z: Constant<Word<W>>,
    photon_x: Signal<Local, Coord>,
    photon_y: Signal<Local, Coord>,
    photon_z: Signal<Local, Coord>,
    /// The photon as the BlockRAM's word arrives (stage W's input): a pipelined
    /// core's DistModule takes its differences from it and registers them in
    /// place of the word.
    raw_x: Signal<Local, Coord>,
    raw_y: Signal<Local, Coord>,
    raw_z: Signal<Local, Coord>,
    raw_axis: Signal<Local, Bits<2>>,
    /// The split axis as stage 1 sees it.
    in_axis: Signal<Local, Bits<2>>,
    // Stage 0: the request, aligned with the word.
    s0_valid: DFF<bool>,
    s0: DFF<ReadRequest>,
    /// `CoreConfig::pipelined`: register the BlockRAM's read data (stage W) before
    /// the distances, so the RAM's clock-to-out and the distance arithmetic are not
    /// one path (the critical path of the unpipelined core on ECP5).
    word_stage: Constant<bool>,
    /// A pipelined squared-L2 core registers the axis differences in place of the
    /// word (the squares and their sum fill stage 1); an L1 core's differences and
    /// sum are one short carry chain each and stay in stage 1, after stage W's
    /// registered word (else the subtraction would follow the BlockRAM's
    /// clock-to-out in stage W).
    diff_stage: Constant<bool>,
    // Stage W: the word and its request, one cycle after stage 0 (pipelined only).
    w_word: DFF<Word<W>>,
    w_valid: DFF<bool>,
    w: DFF<ReadRequest>,
    // Stage 1's inputs: stage W, or stage 0 and the BlockRAM output directly.
    in_word: Signal<Local, Word<W>>,
    in_valid: Signal<Local, bool>,
    in_request: Signal<Local, ReadRequest>,
    // Stage 1: distances.
    s1_valid: DFF<bool>,
    s1: DFF<ReadRequest>,
    s1_axis_dist: DFF<Dist>,
    s1_near_right: DFF<bool>,
    s1_axis: DFF<Bits<2>>,
    s1_dist: DFF<Dist>,
    /// Stage 2: the registered distance within R.
    s1_within: Signal<Local, bool>,
    // Stage 2: the result.
    s2_valid: DFF<bool>,
    s2: DFF<ReadResult>,
    s2_for: DFF<ModuleMask>,
    one: Constant<ModuleMask>,
    /// One bit per QueryModule of the port.
    module_mask: Constant<ModuleMask>,
}

impl<const W: usize> SearchModule<W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let l = cfg.layout;
        let mask = |a: usize| Constant::new(Word::<W>::from(l.coord_max(a) as u64));
        let offset = |o: u32| Constant::new(Bits::<8>::from(o as u64));
        let diff_stage = cfg.pipelined && cfg.metric == Metric::L2;
        SearchModule {
            clock: Default::default(),
            reset: Default::default(),
            request_valid: Default::default(),
            request: Default::default(),
            word: Default::default(),
            photon_count: Default::default(),
            query_write: Default::default(),
            query_module: Default::default(),
            query: Default::default(),
            query_x: LutRam::new(cfg.queries_per_port, l.bits[0]),
            query_y: LutRam::new(cfg.queries_per_port, l.bits[1]),
            query_z: LutRam::new(cfg.queries_per_port, l.bits[2]),
            looked_up: Default::default(),
            result_valid: Default::default(),
            result_for: Default::default(),
            result: Default::default(),
            dist_module: DistModule::pipelined(cfg.metric, l.bits, cfg.dist_bits(), diff_stage),
            next_index: NextIndexModule::new(cfg.address_bits),
            offset_x: offset(l.offset(0)),
            offset_y: offset(l.offset(1)),
            offset_z: offset(l.offset(2)),
            offset_axis: offset(l.axis_offset()),
            mask_x: mask(0),
            mask_y: mask(1),
            mask_z: mask(2),
            photon_x: Default::default(),
            photon_y: Default::default(),
            photon_z: Default::default(),
            raw_x: Default::default(),
            raw_y: Default::default(),
            raw_z: Default::default(),
            raw_axis: Default::default(),
            in_axis: Default::default(),
            s0_valid: Default::default(),
            s0: Default::default(),
            word_stage: Constant::new(cfg.pipelined),
            diff_stage: Constant::new(diff_stage),
            w_word: Default::default(),
            w_valid: Default::default(),
            w: Default::default(),
            in_word: Default::default(),
            in_valid: Default::default(),
            in_request: Default::default(),
            s1_valid: Default::default(),
            s1: Default::default(),
            s1_axis_dist: Default::default(),
            s1_near_right: Default::default(),
            s1_axis: Default::default(),
            s1_dist: Default::default(),
            s1_within: Default::default(),
            s2_valid: Default::default(),
            s2: Default::default(),
            s2_for: Default::default(),
            one: Constant::new(ModuleMask::from(1u64)),
            module_mask: Constant::new(ModuleMask::from(low_mask(cfg.queries_per_port as u32))),
        }
    }
}

impl<const W: usize> Logic for SearchModule<W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            s0_valid,
            s0,
            w_word,
            w_valid,
            w,
            s1_valid,
            s1,
            s1_axis_dist,
            s1_near_right,
            s1_axis,
            s1_dist,
            s2_valid,
            s2,
            s2_for
        );
        // Stage 0: latch the request while the BlockRAM reads.
        self.s0_valid.d.next = self.request_valid.val();
        self.s0.d.next = self.request.val();

        // The query store: written at the load, read by stage 0's module index.
        clock!(self, clock, query_x, query_y, query_z);
        self.query_x.write_enable.next = self.query_write.val();
        self.query_y.write_enable.next = self.query_write.val();
        self.query_z.write_enable.next = self.query_write.val();
        self.query_x.write_index.next = self.query_module.val();
        self.query_y.write_index.next = self.query_module.val();
        self.query_z.write_index.next = self.query_module.val();
        self.query_x.write_data.next = bit_cast::<32, 16>(self.query.val().x);
        self.query_y.write_data.next = bit_cast::<32, 16>(self.query.val().y);
        self.query_z.write_data.next = bit_cast::<32, 16>(self.query.val().z);
        self.query_x.read_index.next = self.s0.q.val().query_module;
        self.query_y.read_index.next = self.s0.q.val().query_module;
        self.query_z.read_index.next = self.s0.q.val().query_module;
        self.looked_up.next = self.s0.q.val();
        self.looked_up.next.x = bit_cast::<16, 32>(self.query_x.read_data.val());
        self.looked_up.next.y = bit_cast::<16, 32>(self.query_y.read_data.val());
        self.looked_up.next.z = bit_cast::<16, 32>(self.query_z.read_data.val());

        // Stage W: register the word with its request (wires when not pipelined).
        self.w_word.d.next = self.word.val();
        self.w_valid.d.next = self.s0_valid.q.val();
        self.w.d.next = self.looked_up.val();
        if self.word_stage.val() {
            self.in_word.next = self.w_word.q.val();
            self.in_valid.next = self.w_valid.q.val();
            self.in_request.next = self.w.q.val();
        } else {
            self.in_word.next = self.word.val();
            self.in_valid.next = self.s0_valid.q.val();
            self.in_request.next = self.looked_up.val();
        }

        // Stage 1: unpack the photon word, distances in parallel.
        self.photon_x.next =
            bit_cast::<16, W>((self.in_word.val() >> self.offset_x.val()) & self.mask_x.val());
        self.photon_y.next =
            bit_cast::<16, W>((self.in_word.val() >> self.offset_y.val()) & self.mask_y.val());
        self.photon_z.next =
            bit_cast::<16, W>((self.in_word.val() >> self.offset_z.val()) & self.mask_z.val());
        self.in_axis.next = bit_cast::<2, W>((self.in_word.val() >> self.offset_axis.val()) & 3);
        // The full and split-axis distances: from stage W's inputs into its
        // registered differences (pipelined squared L2), else from stage 1's.
        self.dist_module.clock.next = self.clock.val();
        self.raw_x.next =
            bit_cast::<16, W>((self.word.val() >> self.offset_x.val()) & self.mask_x.val());
        self.raw_y.next =
            bit_cast::<16, W>((self.word.val() >> self.offset_y.val()) & self.mask_y.val());
        self.raw_z.next =
            bit_cast::<16, W>((self.word.val() >> self.offset_z.val()) & self.mask_z.val());
        self.raw_axis.next = bit_cast::<2, W>((self.word.val() >> self.offset_axis.val()) & 3);
        if self.diff_stage.val() {
            self.dist_module.query_x.next = self.looked_up.val().x;
            self.dist_module.query_y.next = self.looked_up.val().y;
            self.dist_module.query_z.next = self.looked_up.val().z;
            self.dist_module.photon_x.next = self.raw_x.val();
            self.dist_module.photon_y.next = self.raw_y.val();
            self.dist_module.photon_z.next = self.raw_z.val();
            self.dist_module.axis.next = self.raw_axis.val();
        } else {
            self.dist_module.query_x.next = self.in_request.val().x;
            self.dist_module.query_y.next = self.in_request.val().y;
            self.dist_module.query_z.next = self.in_request.val().z;
            self.dist_module.photon_x.next = self.photon_x.val();
            self.dist_module.photon_y.next = self.photon_y.val();
            self.dist_module.photon_z.next = self.photon_z.val();
            self.dist_module.axis.next = self.in_axis.val();
        }
        self.s1_valid.d.next = self.in_valid.val();
        // The query's coordinates are not needed past this stage; synthesis drops
        // their stage-1 bits.
        self.s1.d.next = self.in_request.val();
        self.s1_axis_dist.d.next = self.dist_module.axis_dist.val();
        self.s1_near_right.d.next = self.dist_module.near_right.val();
        self.s1_axis.d.next = self.in_axis.val();
        self.s1_dist.d.next = self.dist_module.distance.val();

        // Stage 2: the next traversal step.
        self.next_index.address.next = self.s1.q.val().address;
        self.next_index.up.next = self.s1.q.val().up;
        self.next_index.came_from_right.next = self.s1.q.val().came_from_right;
        self.next_index.near_right.next = self.s1_near_right.q.val();
        self.next_index.axis_dist.next = self.s1_axis_dist.q.val();
        self.next_index.radius.next = self.s1.q.val().radius;
        self.next_index.full.next = self.s1.q.val().full;
        self.next_index.photon_count.next = self.photon_count.val();
        self.s2_valid.d.next = self.s1_valid.q.val();
        self.s2_for.d.next = 0.into();
        if self.s1_valid.q.val() {
            self.s2_for.d.next =
                (self.one.val() << self.s1.q.val().query_module) & self.module_mask.val();
        }
        self.s2.d.next.query_module = self.s1.q.val().query_module;
        self.s2.d.next.address = self.s1.q.val().address;
        // The in-range test against the requesting QueryModule's R, on the
        // registered distance (the difference, the sum and this comparison in one
        // stage would be three carry chains in series). Before the list is full R is inclusive (`d <= R`), once
        // full only a strictly nearer photon enters (`d < R`): knn.rs's rules.
        // Only a first (downward) visit tests the photon against the found list.
        if self.s1.q.val().full {
            self.s1_within.next = self.s1_dist.q.val() < self.s1.q.val().radius;
        } else {
            self.s1_within.next = self.s1_dist.q.val() <= self.s1.q.val().radius;
        }
        self.s2.d.next.in_range = self.s1_within.val() && (!self.s1.q.val().up);
        self.s2.d.next.distance = self.s1_dist.q.val();
        self.s2.d.next.axis_dist = self.s1_axis_dist.q.val();
        self.s2.d.next.far_pending = self.next_index.far_pending.val();
        self.s2.d.next.axis = self.s1_axis.q.val();
        self.s2.d.next.next_address = self.next_index.next_address.val();
        self.s2.d.next.next_up = self.next_index.next_up.val();
        self.s2.d.next.next_came_from_right = self.next_index.next_came_from_right.val();
        self.s2.d.next.done = self.next_index.done.val();

        if self.reset.val() {
            self.s0_valid.d.next = false;
            self.w_valid.d.next = false;
            self.s1_valid.d.next = false;
            self.s2_valid.d.next = false;
            self.s2_for.d.next = 0.into();
        }

        self.result_valid.next = self.s2_valid.q.val();
        self.result_for.next = self.s2_for.q.val();
        self.result.next = self.s2.q.val();
    }
}
