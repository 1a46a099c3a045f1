//! ResultRegister: a register slice on a SearchPort's result stream (the skid buffer
//! of verilog-axis' `axis_register`, REG_TYPE = 2).
//!
//! Why: without it, the read-out path runs from the read-out sequencer's registers
//! through the found-list mux of the selected QueryModule, the OR of all Q modules'
//! outputs, the merge of the two ports and out of the core in one cycle; place and
//! route named it the critical path (synth/REPORT.md). The slice cuts it at the port:
//! every result output is a flip-flop, and so is `in_ready`, so a downstream stall
//! does not reach back into the sequencer combinationally either. Full throughput (a
//! beat per cycle) is kept by the second, "skid" register that catches the beat sent
//! in the cycle the output stalls.
//!
//! With `bypass` (an elaboration constant, `CoreConfig::pipelined` false) the
//! slice is wires, as verilog-axis' REG_TYPE = 0, so the unpipelined core can still be
//! built and measured.

use crate::hw::config::{Addr, Count, Dist, QueryId, ReadCount};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct ResultRegister {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    // Upstream beat (from the read-out sequencer).
    pub in_valid: Signal<In, bool>,
    pub in_ready: Signal<Out, bool>,
    pub in_header: Signal<In, bool>,
    pub in_last: Signal<In, bool>,
    pub in_id: Signal<In, QueryId>,
    pub in_count: Signal<In, Count>,
    pub in_visited: Signal<In, ReadCount>,
    pub in_address: Signal<In, Addr>,
    pub in_dist: Signal<In, Dist>,
    // Downstream beat.
    pub out_valid: Signal<Out, bool>,
    pub out_ready: Signal<In, bool>,
    pub out_header: Signal<Out, bool>,
    pub out_last: Signal<Out, bool>,
    pub out_id: Signal<Out, QueryId>,
    pub out_count: Signal<Out, Count>,
    pub out_visited: Signal<Out, ReadCount>,
    pub out_address: Signal<Out, Addr>,
    pub out_dist: Signal<Out, Dist>,
    bypass: Constant<bool>,
    /// The output register.
    out_valid_reg: DFF<bool>,
    out_header_reg: DFF<bool>,
    out_last_reg: DFF<bool>,
    out_id_reg: DFF<QueryId>,
    out_count_reg: DFF<Count>,
    out_visited_reg: DFF<ReadCount>,
    out_address_reg: DFF<Addr>,
    out_dist_reg: DFF<Dist>,
    /// The skid register: holds the beat accepted while the output was stalled.
    skid_valid: DFF<bool>,
    skid_header: DFF<bool>,
    skid_last: DFF<bool>,
    skid_id: DFF<QueryId>,
    skid_count: DFF<Count>,
    skid_visited: DFF<ReadCount>,
    skid_address: DFF<Addr>,
    skid_dist: DFF<Dist>,
    /// The output register may load this cycle (it is empty or being emptied).
    out_free: Signal<Local, bool>,
}

impl ResultRegister {
    /// A register slice, or wires if `bypass`.
    pub fn new(bypass: bool) -> Self {
        ResultRegister {
            clock: Default::default(),
            reset: Default::default(),
            in_valid: Default::default(),
            in_ready: Default::default(),
            in_header: Default::default(),
            in_last: Default::default(),
            in_id: Default::default(),
            in_count: Default::default(),
            in_visited: Default::default(),
            in_address: Default::default(),
            in_dist: Default::default(),
            out_valid: Default::default(),
            out_ready: Default::default(),
            out_header: Default::default(),
            out_last: Default::default(),
            out_id: Default::default(),
            out_count: Default::default(),
            out_visited: Default::default(),
            out_address: Default::default(),
            out_dist: Default::default(),
            bypass: Constant::new(bypass),
            out_valid_reg: Default::default(),
            out_header_reg: Default::default(),
            out_last_reg: Default::default(),
            out_id_reg: Default::default(),
            out_count_reg: Default::default(),
            out_visited_reg: Default::default(),
            out_address_reg: Default::default(),
            out_dist_reg: Default::default(),
            skid_valid: Default::default(),
            skid_header: Default::default(),
            skid_last: Default::default(),
            skid_id: Default::default(),
            skid_count: Default::default(),
            skid_visited: Default::default(),
            skid_address: Default::default(),
            skid_dist: Default::default(),
            out_free: Default::default(),
        }
    }
}

impl Logic for ResultRegister {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            out_valid_reg,
            out_header_reg,
            out_last_reg,
            out_id_reg,
            out_count_reg,
            out_visited_reg,
            out_address_reg,
            out_dist_reg,
            skid_valid,
            skid_header,
            skid_last,
            skid_id,
            skid_count,
            skid_visited,
            skid_address,
            skid_dist
        );
        self.out_free.next = self.out_ready.val() || (!self.out_valid_reg.q.val());
        if self.out_free.val() {
            if self.skid_valid.q.val() {
                // Drain the skid register first; the input waits (in_ready is low).
                self.out_valid_reg.d.next = true;
                self.out_header_reg.d.next = self.skid_header.q.val();
                self.out_last_reg.d.next = self.skid_last.q.val();
                self.out_id_reg.d.next = self.skid_id.q.val();
                self.out_count_reg.d.next = self.skid_count.q.val();
                self.out_visited_reg.d.next = self.skid_visited.q.val();
                self.out_address_reg.d.next = self.skid_address.q.val();
                self.out_dist_reg.d.next = self.skid_dist.q.val();
                self.skid_valid.d.next = false;
            } else {
                self.out_valid_reg.d.next = self.in_valid.val();
                self.out_header_reg.d.next = self.in_header.val();
                self.out_last_reg.d.next = self.in_last.val();
                self.out_id_reg.d.next = self.in_id.val();
                self.out_count_reg.d.next = self.in_count.val();
                self.out_visited_reg.d.next = self.in_visited.val();
                self.out_address_reg.d.next = self.in_address.val();
                self.out_dist_reg.d.next = self.in_dist.val();
            }
        } else if self.in_valid.val() && (!self.skid_valid.q.val()) {
            // The output stalled in the cycle this beat was sent: keep it aside.
            self.skid_valid.d.next = true;
            self.skid_header.d.next = self.in_header.val();
            self.skid_last.d.next = self.in_last.val();
            self.skid_id.d.next = self.in_id.val();
            self.skid_count.d.next = self.in_count.val();
            self.skid_visited.d.next = self.in_visited.val();
            self.skid_address.d.next = self.in_address.val();
            self.skid_dist.d.next = self.in_dist.val();
        }
        if self.reset.val() {
            self.out_valid_reg.d.next = false;
            self.skid_valid.d.next = false;
        }

        if self.bypass.val() {
            self.in_ready.next = self.out_ready.val();
            self.out_valid.next = self.in_valid.val();
            self.out_header.next = self.in_header.val();
            self.out_last.next = self.in_last.val();
            self.out_id.next = self.in_id.val();
            self.out_count.next = self.in_count.val();
            self.out_visited.next = self.in_visited.val();
            self.out_address.next = self.in_address.val();
            self.out_dist.next = self.in_dist.val();
        } else {
            self.in_ready.next = !self.skid_valid.q.val();
            self.out_valid.next = self.out_valid_reg.q.val();
            self.out_header.next = self.out_header_reg.q.val();
            self.out_last.next = self.out_last_reg.q.val();
            self.out_id.next = self.out_id_reg.q.val();
            self.out_count.next = self.out_count_reg.q.val();
            self.out_visited.next = self.out_visited_reg.q.val();
            self.out_address.next = self.out_address_reg.q.val();
            self.out_dist.next = self.out_dist_reg.q.val();
        }
    }
}
