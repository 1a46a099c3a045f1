//! PathWrite (the barrel's path-memory writes held a stage, external memory only)
//! under random writes: each edge's outputs are exactly the writes driven before it.

use photon_fpga::hw::barrel::path_write::{PathWrite, PathWrites};
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{clock_cycle, settle};

/// PathWrite holds stage B's writes one cycle: after each edge its outputs are the
/// writes driven before it, and they do not follow the inputs between edges.
#[test]
fn path_write_is_one_cycle_later() {
    let mut uut = PathWrite::default();
    uut.connect_all();
    check_all(&uut).unwrap();
    let mut r = crate::common::rng(44);
    let mut before = PathWrites::default();
    for _ in 0..300 {
        let w = PathWrites {
            bound_write: r.gen(),
            level: r.gen_range(0..=255u64).into(),
            slot: r.gen_range(0..=255u64).into(),
            bound: r.gen_range(0..=u32::MAX as u64).into(),
            far_write: r.gen(),
            far_index: r.gen_range(0..=u16::MAX as u64).into(),
            far_xy: r.gen::<u64>().into(),
            far_zd: r.gen::<u64>().into(),
        };
        uut.bound_write.next = w.bound_write;
        uut.level.next = w.level;
        uut.slot.next = w.slot;
        uut.bound.next = w.bound;
        uut.far_write.next = w.far_write;
        uut.far_index.next = w.far_index;
        uut.far_xy.next = w.far_xy;
        uut.far_zd.next = w.far_zd;
        settle(&mut uut);
        let out = |u: &PathWrite| PathWrites {
            bound_write: u.c_bound_write.val(),
            level: u.c_level.val(),
            slot: u.c_slot.val(),
            bound: u.c_bound.val(),
            far_write: u.c_far_write.val(),
            far_index: u.c_far_index.val(),
            far_xy: u.c_far_xy.val(),
            far_zd: u.c_far_zd.val(),
        };
        assert_eq!(
            out(&uut),
            before,
            "the outputs followed the inputs before the edge"
        );
        clock_cycle(&mut uut, |u| &mut u.clock);
        assert_eq!(out(&uut), w);
        before = w;
    }
}
