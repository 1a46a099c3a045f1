//! SearchModule (paper §4.3): everything a QueryModule needs to know about one photon
//! read, pipelined so that it accepts a read every cycle. The QueryModule's index,
//! query, radius, full flag and traversal state travel with the data (§4.5: the
//! SearchModule carries the id so several QueryModules can share it).
//!
//! Timing, with the read granted in cycle t:
//! * t:   request latched (stage 0) while the TreeModule reads the word;
//! * t+1: (pipelined core) word and request registered (stage W);
//! * t+1 (t+2 pipelined): word unpacked; AxisDistModule and DistModule in parallel
//!   -> stage 1;
//! * t+2 (t+3): NextIndexModule -> result registers, seen by the QueryModules at
//!   t+3 (t+4).

use crate::hw::axis_dist::AxisDistModule;
use crate::hw::config::{Addr, Coord, CoreConfig, Dist, ModuleIndex, Word};
use crate::hw::dist_module::DistModule;
use crate::hw::next_index::NextIndexModule;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct SearchModule<const W: usize> {
    pub clock: Signal<In, Clock>,
    /// Drops the reads in flight (their QueryModules are being reset too).
    pub reset: Signal<In, bool>,
    /// The read granted this cycle (same cycle as the TreeModule address).
    pub request_valid: Signal<In, bool>,
    pub request_module: Signal<In, ModuleIndex>,
    pub request_address: Signal<In, Addr>,
    pub request_up: Signal<In, bool>,
    pub request_came_from_right: Signal<In, bool>,
    pub request_x: Signal<In, Coord>,
    pub request_y: Signal<In, Coord>,
    pub request_z: Signal<In, Coord>,
    pub request_radius: Signal<In, Dist>,
    pub request_full: Signal<In, bool>,
    /// The TreeModule's word, one cycle after the request.
    pub word: Signal<In, Word<W>>,
    pub photon_count: Signal<In, Addr>,
    /// The result, broadcast to the port's QueryModules.
    pub result_valid: Signal<Out, bool>,
    pub result_module: Signal<Out, ModuleIndex>,
    pub result_address: Signal<Out, Addr>,
    pub result_in_range: Signal<Out, bool>,
    pub result_dist: Signal<Out, Dist>,
    pub result_next_address: Signal<Out, Addr>,
    pub result_next_up: Signal<Out, bool>,
    pub result_next_came_from_right: Signal<Out, bool>,
    pub result_done: Signal<Out, bool>,
    /// For the QueryModule's path memory (`Traversal::Remember`): the photon's axis
    /// distance, and whether its far child is still to be visited.
    pub result_axis_dist: Signal<Out, Dist>,
    pub result_far_pending: Signal<Out, bool>,
    axis_dist: AxisDistModule,
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
    // Stage 0: the request, aligned with the word.
    s0_valid: DFF<bool>,
    s0_module: DFF<ModuleIndex>,
    s0_address: DFF<Addr>,
    s0_up: DFF<bool>,
    s0_came_from_right: DFF<bool>,
    s0_x: DFF<Coord>,
    s0_y: DFF<Coord>,
    s0_z: DFF<Coord>,
    s0_radius: DFF<Dist>,
    s0_full: DFF<bool>,
    /// `CoreConfig::pipelined`: register the BlockRAM's read data (stage W) before
    /// the distances, so the RAM's clock-to-out and the distance arithmetic are not
    /// one path (the critical path of the unpipelined core on ECP5).
    word_stage: Constant<bool>,
    // Stage W: the word and its request, one cycle after stage 0 (pipelined only).
    w_word: DFF<Word<W>>,
    w_valid: DFF<bool>,
    w_module: DFF<ModuleIndex>,
    w_address: DFF<Addr>,
    w_up: DFF<bool>,
    w_came_from_right: DFF<bool>,
    w_x: DFF<Coord>,
    w_y: DFF<Coord>,
    w_z: DFF<Coord>,
    w_radius: DFF<Dist>,
    w_full: DFF<bool>,
    // Stage 1's inputs: stage W, or stage 0 and the BlockRAM output directly.
    in_word: Signal<Local, Word<W>>,
    in_valid: Signal<Local, bool>,
    in_module: Signal<Local, ModuleIndex>,
    in_address: Signal<Local, Addr>,
    in_up: Signal<Local, bool>,
    in_came_from_right: Signal<Local, bool>,
    in_x: Signal<Local, Coord>,
    in_y: Signal<Local, Coord>,
    in_z: Signal<Local, Coord>,
    in_radius: Signal<Local, Dist>,
    in_full: Signal<Local, bool>,
    // Stage 1: distances.
    s1_valid: DFF<bool>,
    s1_module: DFF<ModuleIndex>,
    s1_address: DFF<Addr>,
    s1_up: DFF<bool>,
    s1_came_from_right: DFF<bool>,
    s1_radius: DFF<Dist>,
    s1_full: DFF<bool>,
    s1_axis_dist: DFF<Dist>,
    s1_near_right: DFF<bool>,
    s1_dist: DFF<Dist>,
    s1_in_range: DFF<bool>,
    // Stage 2: the result.
    s2_valid: DFF<bool>,
    s2_module: DFF<ModuleIndex>,
    s2_address: DFF<Addr>,
    s2_in_range: DFF<bool>,
    s2_dist: DFF<Dist>,
    s2_next_address: DFF<Addr>,
    s2_next_up: DFF<bool>,
    s2_next_came_from_right: DFF<bool>,
    s2_done: DFF<bool>,
    s2_axis_dist: DFF<Dist>,
    s2_far_pending: DFF<bool>,
}

impl<const W: usize> SearchModule<W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let l = cfg.layout;
        let mask = |a: usize| Constant::new(Word::<W>::from(l.coord_max(a) as u64));
        let offset = |o: u32| Constant::new(Bits::<8>::from(o as u64));
        SearchModule {
            clock: Default::default(),
            reset: Default::default(),
            request_valid: Default::default(),
            request_module: Default::default(),
            request_address: Default::default(),
            request_up: Default::default(),
            request_came_from_right: Default::default(),
            request_x: Default::default(),
            request_y: Default::default(),
            request_z: Default::default(),
            request_radius: Default::default(),
            request_full: Default::default(),
            word: Default::default(),
            photon_count: Default::default(),
            result_valid: Default::default(),
            result_module: Default::default(),
            result_address: Default::default(),
            result_in_range: Default::default(),
            result_dist: Default::default(),
            result_next_address: Default::default(),
            result_next_up: Default::default(),
            result_next_came_from_right: Default::default(),
            result_done: Default::default(),
            result_axis_dist: Default::default(),
            result_far_pending: Default::default(),
            axis_dist: AxisDistModule::new(cfg.metric),
            dist_module: DistModule::new(cfg.metric),
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
            s0_valid: Default::default(),
            s0_module: Default::default(),
            s0_address: Default::default(),
            s0_up: Default::default(),
            s0_came_from_right: Default::default(),
            s0_x: Default::default(),
            s0_y: Default::default(),
            s0_z: Default::default(),
            s0_radius: Default::default(),
            s0_full: Default::default(),
            word_stage: Constant::new(cfg.pipelined),
            w_word: Default::default(),
            w_valid: Default::default(),
            w_module: Default::default(),
            w_address: Default::default(),
            w_up: Default::default(),
            w_came_from_right: Default::default(),
            w_x: Default::default(),
            w_y: Default::default(),
            w_z: Default::default(),
            w_radius: Default::default(),
            w_full: Default::default(),
            in_word: Default::default(),
            in_valid: Default::default(),
            in_module: Default::default(),
            in_address: Default::default(),
            in_up: Default::default(),
            in_came_from_right: Default::default(),
            in_x: Default::default(),
            in_y: Default::default(),
            in_z: Default::default(),
            in_radius: Default::default(),
            in_full: Default::default(),
            s1_valid: Default::default(),
            s1_module: Default::default(),
            s1_address: Default::default(),
            s1_up: Default::default(),
            s1_came_from_right: Default::default(),
            s1_radius: Default::default(),
            s1_full: Default::default(),
            s1_axis_dist: Default::default(),
            s1_near_right: Default::default(),
            s1_dist: Default::default(),
            s1_in_range: Default::default(),
            s2_valid: Default::default(),
            s2_module: Default::default(),
            s2_address: Default::default(),
            s2_in_range: Default::default(),
            s2_dist: Default::default(),
            s2_next_address: Default::default(),
            s2_next_up: Default::default(),
            s2_next_came_from_right: Default::default(),
            s2_done: Default::default(),
            s2_axis_dist: Default::default(),
            s2_far_pending: Default::default(),
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
            s0_module,
            s0_address,
            s0_up,
            s0_came_from_right,
            s0_x,
            s0_y,
            s0_z,
            s0_radius,
            s0_full,
            w_word,
            w_valid,
            w_module,
            w_address,
            w_up,
            w_came_from_right,
            w_x,
            w_y,
            w_z,
            w_radius,
            w_full,
            s1_valid,
            s1_module,
            s1_address,
            s1_up,
            s1_came_from_right,
            s1_radius,
            s1_full,
            s1_axis_dist,
            s1_near_right,
            s1_dist,
            s1_in_range,
            s2_valid,
            s2_module,
            s2_address,
            s2_in_range,
            s2_dist,
            s2_next_address,
            s2_next_up,
            s2_next_came_from_right,
            s2_done,
            s2_axis_dist,
            s2_far_pending
        );
        // Stage 0: latch the request while the BlockRAM reads.
        self.s0_valid.d.next = self.request_valid.val();
        self.s0_module.d.next = self.request_module.val();
        self.s0_address.d.next = self.request_address.val();
        self.s0_up.d.next = self.request_up.val();
        self.s0_came_from_right.d.next = self.request_came_from_right.val();
        self.s0_x.d.next = self.request_x.val();
        self.s0_y.d.next = self.request_y.val();
        self.s0_z.d.next = self.request_z.val();
        self.s0_radius.d.next = self.request_radius.val();
        self.s0_full.d.next = self.request_full.val();

        // Stage W: register the word with its request (wires when not pipelined).
        self.w_word.d.next = self.word.val();
        self.w_valid.d.next = self.s0_valid.q.val();
        self.w_module.d.next = self.s0_module.q.val();
        self.w_address.d.next = self.s0_address.q.val();
        self.w_up.d.next = self.s0_up.q.val();
        self.w_came_from_right.d.next = self.s0_came_from_right.q.val();
        self.w_x.d.next = self.s0_x.q.val();
        self.w_y.d.next = self.s0_y.q.val();
        self.w_z.d.next = self.s0_z.q.val();
        self.w_radius.d.next = self.s0_radius.q.val();
        self.w_full.d.next = self.s0_full.q.val();
        if self.word_stage.val() {
            self.in_word.next = self.w_word.q.val();
            self.in_valid.next = self.w_valid.q.val();
            self.in_module.next = self.w_module.q.val();
            self.in_address.next = self.w_address.q.val();
            self.in_up.next = self.w_up.q.val();
            self.in_came_from_right.next = self.w_came_from_right.q.val();
            self.in_x.next = self.w_x.q.val();
            self.in_y.next = self.w_y.q.val();
            self.in_z.next = self.w_z.q.val();
            self.in_radius.next = self.w_radius.q.val();
            self.in_full.next = self.w_full.q.val();
        } else {
            self.in_word.next = self.word.val();
            self.in_valid.next = self.s0_valid.q.val();
            self.in_module.next = self.s0_module.q.val();
            self.in_address.next = self.s0_address.q.val();
            self.in_up.next = self.s0_up.q.val();
            self.in_came_from_right.next = self.s0_came_from_right.q.val();
            self.in_x.next = self.s0_x.q.val();
            self.in_y.next = self.s0_y.q.val();
            self.in_z.next = self.s0_z.q.val();
            self.in_radius.next = self.s0_radius.q.val();
            self.in_full.next = self.s0_full.q.val();
        }

        // Stage 1: unpack the photon word, distances in parallel.
        self.photon_x.next =
            bit_cast::<16, W>((self.in_word.val() >> self.offset_x.val()) & self.mask_x.val());
        self.photon_y.next =
            bit_cast::<16, W>((self.in_word.val() >> self.offset_y.val()) & self.mask_y.val());
        self.photon_z.next =
            bit_cast::<16, W>((self.in_word.val() >> self.offset_z.val()) & self.mask_z.val());
        self.axis_dist.query_x.next = self.in_x.val();
        self.axis_dist.query_y.next = self.in_y.val();
        self.axis_dist.query_z.next = self.in_z.val();
        self.axis_dist.photon_x.next = self.photon_x.val();
        self.axis_dist.photon_y.next = self.photon_y.val();
        self.axis_dist.photon_z.next = self.photon_z.val();
        self.axis_dist.axis.next =
            bit_cast::<2, W>((self.in_word.val() >> self.offset_axis.val()) & 3);
        self.dist_module.query_x.next = self.in_x.val();
        self.dist_module.query_y.next = self.in_y.val();
        self.dist_module.query_z.next = self.in_z.val();
        self.dist_module.photon_x.next = self.photon_x.val();
        self.dist_module.photon_y.next = self.photon_y.val();
        self.dist_module.photon_z.next = self.photon_z.val();
        self.dist_module.radius.next = self.in_radius.val();
        self.dist_module.full.next = self.in_full.val();
        self.s1_valid.d.next = self.in_valid.val();
        self.s1_module.d.next = self.in_module.val();
        self.s1_address.d.next = self.in_address.val();
        self.s1_up.d.next = self.in_up.val();
        self.s1_came_from_right.d.next = self.in_came_from_right.val();
        self.s1_radius.d.next = self.in_radius.val();
        self.s1_full.d.next = self.in_full.val();
        self.s1_axis_dist.d.next = self.axis_dist.axis_dist.val();
        self.s1_near_right.d.next = self.axis_dist.near_right.val();
        self.s1_dist.d.next = self.dist_module.distance.val();
        self.s1_in_range.d.next = self.dist_module.in_range.val();

        // Stage 2: the next traversal step.
        self.next_index.address.next = self.s1_address.q.val();
        self.next_index.up.next = self.s1_up.q.val();
        self.next_index.came_from_right.next = self.s1_came_from_right.q.val();
        self.next_index.near_right.next = self.s1_near_right.q.val();
        self.next_index.axis_dist.next = self.s1_axis_dist.q.val();
        self.next_index.radius.next = self.s1_radius.q.val();
        self.next_index.full.next = self.s1_full.q.val();
        self.next_index.photon_count.next = self.photon_count.val();
        self.s2_valid.d.next = self.s1_valid.q.val();
        self.s2_module.d.next = self.s1_module.q.val();
        self.s2_address.d.next = self.s1_address.q.val();
        // Only a first (downward) visit tests the photon against the found list.
        self.s2_in_range.d.next = self.s1_in_range.q.val() && (!self.s1_up.q.val());
        self.s2_dist.d.next = self.s1_dist.q.val();
        self.s2_axis_dist.d.next = self.s1_axis_dist.q.val();
        self.s2_far_pending.d.next = self.next_index.far_pending.val();
        self.s2_next_address.d.next = self.next_index.next_address.val();
        self.s2_next_up.d.next = self.next_index.next_up.val();
        self.s2_next_came_from_right.d.next = self.next_index.next_came_from_right.val();
        self.s2_done.d.next = self.next_index.done.val();

        if self.reset.val() {
            self.s0_valid.d.next = false;
            self.w_valid.d.next = false;
            self.s1_valid.d.next = false;
            self.s2_valid.d.next = false;
        }

        self.result_valid.next = self.s2_valid.q.val();
        self.result_module.next = self.s2_module.q.val();
        self.result_address.next = self.s2_address.q.val();
        self.result_in_range.next = self.s2_in_range.q.val();
        self.result_dist.next = self.s2_dist.q.val();
        self.result_next_address.next = self.s2_next_address.q.val();
        self.result_next_up.next = self.s2_next_up.q.val();
        self.result_next_came_from_right.next = self.s2_next_came_from_right.q.val();
        self.result_done.next = self.s2_done.q.val();
        self.result_axis_dist.next = self.s2_axis_dist.q.val();
        self.result_far_pending.next = self.s2_far_pending.q.val();
    }
}
