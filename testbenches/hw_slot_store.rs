//! SlotStore against a memory model: one record per query slot of the state fields
//! a `SlotEvent` carries between events (level, pending, R, full, count, k, the
//! maximum's entry, photon reads and, with `Traversal::Cell`, the cell offsets and
//! the cell's distance). Random writes of random in-range states to random slots and
//! a random slot read every cycle, for both traversals that remember the path. The
//! model is the block's documented behaviour: the read is asynchronous (before the
//! edge the state as it was, after it this cycle's write), `slot` is the slot read,
//! the event-only fields read zero, and without `Cell` the offsets are not kept
//! (zero).

use photon_fpga::hw::barrel::slot_store::{SlotEvent, SlotStore};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{bits_for, low_mask, CoreConfig, BARREL_SLOTS};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use rand::Rng;
use rand_pcg::Pcg64;
use rust_hdl::prelude::*;

use crate::common::settle;

/// The stored fields of one slot, as plain integers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct State {
    level: u64,
    pending: u64,
    radius: u64,
    full: bool,
    count: u64,
    k: u64,
    max_pos: u64,
    visited: u64,
    off: [u64; 3],
    cell_dist: u64,
}

/// The widths of the fields, from the configuration: tree levels 0..H-1, one
/// pending bit per level with children, distances of the metric, counts 0..=K,
/// entries 0..K-1, photon reads below 2^(H+1).
struct Widths {
    level: u32,
    pending: u32,
    dist: u32,
    count: u32,
    entry: u32,
    visited: u32,
}

impl Widths {
    fn of(cfg: &CoreConfig) -> Self {
        Widths {
            level: bits_for(cfg.address_bits as u64 - 1),
            pending: cfg.address_bits - 1,
            dist: cfg.dist_bits(),
            count: bits_for(cfg.k as u64),
            entry: bits_for(cfg.k as u64 - 1),
            visited: cfg.address_bits + 1,
        }
    }
}

fn random_state(r: &mut Pcg64, w: &Widths) -> State {
    let mut bits = |b: u32| r.gen::<u64>() & low_mask(b);
    State {
        level: bits(w.level),
        pending: bits(w.pending),
        radius: bits(w.dist),
        full: bits(1) == 1,
        count: bits(w.count),
        k: bits(w.count),
        max_pos: bits(w.entry),
        visited: bits(w.visited),
        off: [bits(w.dist), bits(w.dist), bits(w.dist)],
        cell_dist: bits(w.dist),
    }
}

/// A write event carrying `s`, with random event-only fields (not stored).
fn event(r: &mut Pcg64, s: &State) -> SlotEvent {
    SlotEvent {
        valid: r.gen(),
        load: r.gen(),
        slot: r.gen_range(0..32u64).into(),
        run_max: r.gen(),
        full: s.full,
        radius: s.radius.into(),
        count: s.count.into(),
        k: s.k.into(),
        max_pos: s.max_pos.into(),
        visited: s.visited.into(),
        level: s.level.into(),
        pending: s.pending.into(),
        up: r.gen(),
        address: r.gen_range(0..1u64 << 24).into(),
        next_address: r.gen_range(0..1u64 << 24).into(),
        result: r.gen(),
        axis: r.gen_range(0..4u64).into(),
        axis_dist: (r.gen::<u32>() as u64).into(),
        far_pending: r.gen(),
        off_x: s.off[0].into(),
        off_y: s.off[1].into(),
        off_z: s.off[2].into(),
        cell_dist: s.cell_dist.into(),
    }
}

/// What a read of `slot` holding `s` shows.
fn expected_read(slot: usize, s: &State, cell: bool) -> SlotEvent {
    let off = if cell { s.off } else { [0; 3] };
    SlotEvent {
        slot: (slot as u64).into(),
        full: s.full,
        radius: s.radius.into(),
        count: s.count.into(),
        k: s.k.into(),
        max_pos: s.max_pos.into(),
        visited: s.visited.into(),
        level: s.level.into(),
        pending: s.pending.into(),
        off_x: off[0].into(),
        off_y: off[1].into(),
        off_z: off[2].into(),
        cell_dist: if cell { s.cell_dist } else { 0 }.into(),
        ..Default::default()
    }
}

fn slot_store_against_model(cfg: CoreConfig, seed: u64) {
    let q = cfg.queries_per_port;
    let cell = cfg.traversal == Traversal::Cell;
    let w = Widths::of(&cfg);
    let mut uut = SlotStore::new(&cfg);
    uut.connect_all();
    check_all(&uut).expect("SlotStore checks");
    let mut model = vec![State::default(); q];
    let mut r = crate::common::rng(seed);
    for step in 0..2000 {
        let we = r.gen_bool(0.6);
        let wi = r.gen_range(0..q);
        let s = random_state(&mut r, &w);
        let ri = if r.gen_bool(0.3) {
            wi
        } else {
            r.gen_range(0..q)
        };
        uut.write_enable.next = we;
        uut.write_index.next = (wi as u64).into();
        uut.write.next = event(&mut r, &s);
        uut.read_index.next = (ri as u64).into();
        settle(&mut uut);
        assert_eq!(
            uut.read.val(),
            expected_read(ri, &model[ri], cell),
            "{} step {step}: slot {ri} before the edge",
            cfg.traversal
        );
        uut.clock.next = true.into();
        settle(&mut uut);
        if we {
            model[wi] = s;
        }
        assert_eq!(
            uut.read.val(),
            expected_read(ri, &model[ri], cell),
            "{} step {step}: slot {ri} after a write to {wi} (we {we})",
            cfg.traversal
        );
        uut.clock.next = false.into();
        settle(&mut uut);
    }
}

#[test]
fn slot_store_against_a_memory_model() {
    let barrel = CoreConfig {
        controller: Controller::Barrel,
        queries_per_port: BARREL_SLOTS,
        ..CoreConfig::paper()
    };
    let cases = [
        (Traversal::Remember, Metric::L1, 10, 81),
        (Traversal::Cell, Metric::L1, 10, 82),
        (Traversal::Cell, Metric::L2, 33, 83),
        (Traversal::Remember, Metric::L2, 1, 84),
    ];
    for (cfg, seed) in crate::common::variants(barrel, &cases) {
        slot_store_against_model(cfg, seed);
    }
    // Slots that are not a power of two, a tall tree.
    let odd = CoreConfig {
        traversal: Traversal::Cell,
        queries_per_port: 11,
        address_bits: 20,
        ..barrel
    };
    slot_store_against_model(odd, 85);
}
