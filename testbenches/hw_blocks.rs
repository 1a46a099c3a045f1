//! Unit benches of the SearchModule's parts and the TreeModule: Dist (full and split axis) at
//! the coordinate extremes in both metrics (no overflow), NextIndex against the
//! traversal rule of knn.rs, TreeModule read-after-write on both ports, CellBound's
//! far-cell distances against offsets summed afresh; distances narrower than the
//! grid's diagonal (`CoreConfig::radius_bits`) saturating in Dist and FarCellDist.

use photon_fpga::hw::barrel::found_max::FoundMax;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::datapath::cell_bound::CellBound;
use photon_fpga::hw::datapath::dist_module::DistModule;
use photon_fpga::hw::datapath::far_cell_dist::FarCellDist;
use photon_fpga::hw::datapath::next_index::NextIndexModule;
use photon_fpga::hw::primitives::block_ram::BlockRam;
use photon_fpga::hw::primitives::port_arbiter::PortArbiter;
use photon_fpga::hw::store::tree_module::TreeModule;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{clock_cycle, settle};

/// Independent model of one axis distance.
fn axis_model(metric: Metric, q: u64, p: u64) -> u64 {
    let d = q.abs_diff(p);
    match metric {
        Metric::L2 => d * d,
        Metric::L1 => d,
    }
}

/// A DistModule's query and photon coordinates.
fn drive(uut: &mut DistModule, q: &[u64], p: &[u64]) {
    uut.query_x.next = q[0].into();
    uut.query_y.next = q[1].into();
    uut.query_z.next = q[2].into();
    uut.photon_x.next = p[0].into();
    uut.photon_y.next = p[1].into();
    uut.photon_z.next = p[2].into();
}

fn extremes(bits: u32) -> Vec<u64> {
    let m = (1u64 << bits) - 1;
    vec![0, 1, m / 2, m - 1, m]
}

/// DistModule's split-axis distance and near side (the paper's AxisDistModule) at
/// the coordinate extremes, unregistered and registered (a cycle later).
#[test]
fn axis_dist_extremes() {
    for metric in [Metric::L2, Metric::L1] {
        for registered in [false, true] {
            for bits in [10u32, 15] {
                let mut uut = DistModule::pipelined(metric, [bits; 3], 32, registered);
                uut.connect_all();
                check_all(&uut).unwrap();
                for axis in 0..4u64 {
                    // Axis code 3 never occurs in a word; it reads as z.
                    let a = axis.min(2) as usize;
                    for &q in &extremes(bits) {
                        for &p in &extremes(bits) {
                            let mut qs = [5u64, 6, 7];
                            let mut ps = [1u64, 2, 3];
                            qs[a] = q;
                            ps[a] = p;
                            drive(&mut uut, &qs, &ps);
                            uut.axis.next = axis.into();
                            if registered {
                                clock_cycle(&mut uut, |u| &mut u.clock);
                                // The next inputs must not show before their cycle.
                                uut.axis.next = ((axis + 1) % 3).into();
                                uut.query_x.next = ps[0].into();
                                uut.query_y.next = ps[1].into();
                                uut.query_z.next = ps[2].into();
                            }
                            settle(&mut uut);
                            let d: u64 = (0..3).map(|i| axis_model(metric, qs[i], ps[i])).sum();
                            assert_eq!(uut.distance.val().to_u64(), d);
                            assert_eq!(
                                uut.axis_dist.val().to_u64(),
                                axis_model(metric, q, p),
                                "{metric} registered={registered} axis={axis} q={q} p={p}"
                            );
                            assert_eq!(uut.near_right.val(), q >= p);
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn dist_extremes() {
    let mut r = crate::common::rng(3);
    for metric in [Metric::L2, Metric::L1] {
        let mut uut = DistModule::new(metric);
        uut.connect_all();
        check_all(&uut).unwrap();
        // [15,15,15] is the widest layout whose L2 distance still fits 32 bits.
        for bits in [10u32, 15] {
            let ex = extremes(bits);
            for _ in 0..400 {
                let q: Vec<u64> = (0..3).map(|_| ex[r.gen_range(0..ex.len())]).collect();
                let p: Vec<u64> = (0..3).map(|_| ex[r.gen_range(0..ex.len())]).collect();
                let d: u64 = (0..3).map(|a| axis_model(metric, q[a], p[a])).sum();
                drive(&mut uut, &q, &p);
                settle(&mut uut);
                assert_eq!(uut.distance.val().to_u64(), d, "{metric} q={q:?} p={p:?}");
            }
            // The very corners: the largest distance of the grid.
            let m = (1u64 << bits) - 1;
            uut.query_x.next = 0.into();
            uut.query_y.next = 0.into();
            uut.query_z.next = 0.into();
            uut.photon_x.next = m.into();
            uut.photon_y.next = m.into();
            uut.photon_z.next = m.into();
            settle(&mut uut);
            assert_eq!(uut.distance.val().to_u64(), metric.max_dist([bits; 3]));
        }
    }
}

/// Distances narrower than the grid's diagonal: DistModule's split-axis distance
/// is exact below the all-ones value and saturates at it above (the model
/// `min(d, 2^b - 1)`), its full distance stays exact, in both metrics, registered
/// or not.
#[test]
fn dist_saturates_at_narrow_widths() {
    let mut r = crate::common::rng(31);
    for metric in [Metric::L2, Metric::L1] {
        for registered in [false, true] {
            // Narrow enough that about half of the random distances saturate.
            let (dist_bits, near) = match metric {
                Metric::L2 => (14, 150i64),
                Metric::L1 => (9, 300),
            };
            let sat = (1u64 << dist_bits) - 1;
            let mut uut = DistModule::pipelined(metric, [10; 3], dist_bits, registered);
            uut.connect_all();
            check_all(&uut).unwrap();
            let (mut below, mut above) = (0, 0);
            for _ in 0..600 {
                let q: Vec<u64> = (0..3).map(|_| r.gen_range(0..1024)).collect();
                // Photons near the query, so that both sides of the width are hit.
                let p: Vec<u64> = q
                    .iter()
                    .map(|&c| (c as i64 + r.gen_range(-near..=near)).clamp(0, 1023) as u64)
                    .collect();
                let axis = r.gen_range(0..3usize);
                drive(&mut uut, &q, &p);
                uut.axis.next = (axis as u64).into();
                if registered {
                    clock_cycle(&mut uut, |u| &mut u.clock);
                }
                settle(&mut uut);
                let d: u64 = (0..3).map(|a| axis_model(metric, q[a], p[a])).sum();
                let ad = axis_model(metric, q[axis], p[axis]);
                if d < sat {
                    below += 1;
                } else {
                    above += 1;
                }
                // The full distance stays whole: the in-range test is exact on it.
                assert_eq!(uut.distance.val().to_u64(), d, "{metric} {q:?} {p:?}");
                assert_eq!(
                    uut.axis_dist.val().to_u64(),
                    ad.min(sat),
                    "{metric} axis {axis}"
                );
            }
            assert!(
                below > 100 && above > 100,
                "{metric}: {below} below, {above} above"
            );
        }
    }
}

/// FarCellDist against `cell_dist - off[axis] + axis_dist` computed afresh, at full
/// width and saturating at 12 bits (where an axis distance may itself be the
/// saturated value).
#[test]
fn far_cell_dist_against_model() {
    let mut r = crate::common::rng(33);
    // 15 bits is the widest whose saturation is tested on a 16-bit sum, 16 the
    // narrowest on the whole one.
    for (bits, saturate) in [(12u32, false), (12, true), (15, true), (16, true)] {
        let sat = (1u64 << bits) - 1;
        let mut uut = FarCellDist::new(bits, saturate);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mut saturated = 0;
        for _ in 0..2000 {
            // A cell entered within R: offsets summing to at most the saturated value.
            let off: Vec<u64> = (0..3).map(|_| r.gen_range(0..=sat / 3)).collect();
            let cell: u64 = off.iter().sum();
            let axis = r.gen_range(0..4u64);
            let a = if axis == 1 || axis == 2 {
                axis as usize
            } else {
                0
            };
            let ad = if saturate && r.gen_bool(0.2) {
                sat
            } else {
                off[a] + r.gen_range(0..=sat - cell)
            };
            uut.off_x.next = off[0].into();
            uut.off_y.next = off[1].into();
            uut.off_z.next = off[2].into();
            uut.cell_dist.next = cell.into();
            uut.axis.next = axis.into();
            uut.axis_dist.next = ad.into();
            settle(&mut uut);
            let far = cell - off[a] + ad;
            let want = if saturate { far.min(sat) } else { far & sat };
            saturated += usize::from(far > sat);
            assert_eq!(uut.axis_off.val().to_u64(), off[a], "axis {axis}");
            assert_eq!(
                uut.far_dist.val().to_u64(),
                want,
                "axis {axis} {off:?} {ad}"
            );
        }
        assert!(
            !saturate || saturated > 100,
            "{bits} bits: {saturated} saturated sums"
        );
    }
}

#[test]
fn next_index_follows_the_traversal_rule() {
    let mut r = crate::common::rng(5);
    // 7 address bits: photon counts below 128, child addresses below 256.
    let mut uut = NextIndexModule::new(7);
    uut.connect_all();
    check_all(&uut).unwrap();
    for _ in 0..3000 {
        let n: u64 = r.gen_range(1..100);
        let addr: u64 = r.gen_range(1..=n);
        let up = r.gen_bool(0.5);
        let from = r.gen_bool(0.5);
        let near_right = r.gen_bool(0.5);
        let ad: u64 = r.gen_range(0..20);
        let radius: u64 = r.gen_range(0..20);
        let full = r.gen_bool(0.5);
        // Model, written from the doc comment of knn.rs.
        let near = 2 * addr + near_right as u64;
        let far = 2 * addr + 1 - near_right as u64;
        let within = if full { ad < radius } else { ad <= radius };
        let down = if !up {
            if near <= n {
                Some(near)
            } else if far <= n && within {
                Some(far)
            } else {
                None
            }
        } else if from == near_right && far <= n && within {
            Some(far)
        } else {
            None
        };
        uut.address.next = addr.into();
        uut.up.next = up;
        uut.came_from_right.next = from;
        uut.near_right.next = near_right;
        uut.axis_dist.next = ad.into();
        uut.radius.next = radius.into();
        uut.full.next = full;
        uut.photon_count.next = n.into();
        settle(&mut uut);
        match down {
            Some(child) => {
                assert_eq!(uut.next_address.val().to_u64(), child);
                assert!(!uut.next_up.val());
                assert!(!uut.done.val());
            }
            None => {
                assert_eq!(uut.done.val(), addr == 1);
                assert!(uut.next_up.val());
                assert_eq!(uut.next_address.val().to_u64(), addr / 2);
                assert_eq!(uut.next_came_from_right.val(), addr & 1 == 1);
            }
        }
    }
}

fn tick<const W: usize>(uut: &mut TreeModule<W>) {
    uut.clock.next = true.into();
    settle(uut);
    uut.clock.next = false.into();
    settle(uut);
}

/// Random reads and writes on a TreeModule with `W`-bit ports holding `word_bits`-bit
/// words, against a Vec model: registered read-first reads on both ports, and only
/// the word's own bits are stored.
fn tree_module_against_model<const W: usize>(word_bits: u32, seed: u64) {
    let h = 6;
    let mut uut = TreeModule::<W>::new(h, word_bits);
    uut.connect_all();
    check_all(&uut).unwrap();
    let port_mask = if W == 64 { u64::MAX } else { (1u64 << W) - 1 };
    let word_mask = if word_bits == 64 {
        u64::MAX
    } else {
        (1u64 << word_bits) - 1
    };
    let mut model = vec![0u64; 1 << h];
    let mut r = crate::common::rng(seed);
    for _ in 0..500 {
        let a: u64 = r.gen_range(0..1 << h);
        let b: u64 = r.gen_range(0..1 << h);
        let we = r.gen_bool(0.5);
        // Any value the port can carry; bits above the word are dropped.
        let w: u64 = r.gen::<u64>() & port_mask;
        uut.a_address.next = a.into();
        uut.b_address.next = b.into();
        uut.a_write_enable.next = we;
        uut.a_write_data.next = w.into();
        settle(&mut uut);
        tick(&mut uut);
        // Registered, read-first: the words before this cycle's write.
        assert_eq!(uut.a_read_data.val().to_u64(), model[a as usize]);
        assert_eq!(uut.b_read_data.val().to_u64(), model[b as usize]);
        if we {
            model[a as usize] = w & word_mask;
            // Read after write, both ports, next cycle.
            uut.a_write_enable.next = false;
            uut.b_address.next = a.into();
            settle(&mut uut);
            tick(&mut uut);
            assert_eq!(uut.a_read_data.val().to_u64(), w & word_mask);
            assert_eq!(uut.b_read_data.val().to_u64(), w & word_mask);
        }
    }
}

#[test]
fn tree_module_read_after_write_on_both_ports() {
    tree_module_against_model::<32>(32, 9);
    // A narrower word keeps only its own bits.
    tree_module_against_model::<32>(20, 10);
}

/// 12-bit coordinates: a 38-bit word on the 64-bit ports.
#[test]
fn tree_module_wide_word() {
    tree_module_against_model::<64>(38, 11);
    tree_module_against_model::<64>(47, 12);
}

fn clock_cell(uut: &mut CellBound) {
    clock_cycle(uut, |u| &mut u.clock);
}

/// CellBound on random root-to-leaf walks: down visits, ascent steps that enter a
/// far child or pass a level, and reloads. The model keeps the three offsets and a
/// record per level and sums the offsets afresh at every visit, where the block
/// adds incrementally (`cell_dist - off[axis] + axis_dist`).
#[test]
fn cell_bound_sums_the_offsets_of_the_cell() {
    let (levels, bits) = (9usize, 12u32);
    let mut uut = CellBound::new(levels, bits, false);
    uut.connect_all();
    check_all(&uut).unwrap();
    let mut r = crate::common::rng(21);
    // (axis, offset before, axis distance, far cell distance) per level.
    let mut rec = vec![(0usize, 0u64, 0u64, 0u64); levels];
    let mut off = [0u64; 3];
    let mut level = 0usize;
    let mut checked = 0;
    let idle = |uut: &mut CellBound| {
        uut.load.next = false;
        uut.visit.next = false;
        uut.step.next = false;
        uut.enter.next = false;
    };
    idle(&mut uut);
    uut.load.next = true;
    clock_cell(&mut uut);
    for _ in 0..3000 {
        idle(&mut uut);
        // A down visit at `level`: the split is inside the cell, so its axis
        // distance is at least the offset along its axis.
        let a = r.gen_range(0..3usize);
        let d = off[a] + r.gen_range(0..200u64);
        uut.visit.next = true;
        uut.axis.next = (a as u64).into();
        uut.axis_dist.next = d.into();
        uut.write_index.next = (level as u64).into();
        settle(&mut uut);
        let want = off.iter().sum::<u64>() - off[a] + d;
        assert_eq!(uut.far_cell_dist.val().to_u64(), want, "level {level}");
        checked += 1;
        rec[level] = (a, off[a], d, want);
        clock_cell(&mut uut);
        idle(&mut uut);
        if level + 1 < levels && r.gen_bool(0.6) {
            level += 1; // near child: the cell's offsets stay
            continue;
        }
        // Climb: pass levels until one is entered, or reload at the root.
        loop {
            if level == 0 || r.gen_bool(0.05) {
                uut.load.next = true;
                clock_cell(&mut uut);
                off = [0; 3];
                level = 0;
                break;
            }
            let p = level - 1;
            let (pa, old, far, bound) = rec[p];
            let enter = r.gen_bool(0.4);
            uut.step.next = true;
            uut.enter.next = enter;
            uut.enter_bound.next = bound.into();
            uut.read_index.next = (p as u64).into();
            clock_cell(&mut uut);
            idle(&mut uut);
            if enter {
                off[pa] = far; // the sibling's cell, at the same level
                break;
            }
            off[pa] = old;
            level = p;
        }
    }
    assert!(checked == 3000);
}

/// BlockRam against a Vec model: random writes and reads of other entries, the
/// read data registered (the entry at last cycle's index), only `width` bits kept.
#[test]
fn block_ram_against_model() {
    for (bits, width, seed) in [(4u32, 24u32, 41u64), (7, 64, 42), (1, 1, 43)] {
        let mut uut = BlockRam::new(bits, width);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mask = if width == 64 {
            u64::MAX
        } else {
            (1u64 << width) - 1
        };
        let mut model = vec![0u64; 1 << bits];
        let mut r = crate::common::rng(seed);
        for _ in 0..400 {
            let w: u64 = r.gen_range(0..1 << bits);
            let rd: u64 = r.gen_range(0..1 << bits);
            let we = r.gen_bool(0.6) && w != rd;
            let data: u64 = r.gen();
            uut.write_enable.next = we;
            uut.write_index.next = w.into();
            uut.write_data.next = data.into();
            uut.read_index.next = rd.into();
            clock_cycle(&mut uut, |u| &mut u.clock);
            // Registered: the entry at the index of the cycle just ended.
            assert_eq!(uut.read_data.val().to_u64(), model[rd as usize]);
            if we {
                model[w as usize] = data & mask;
            }
            // Holding the index holds the data; the write shows a cycle later.
            uut.write_enable.next = false;
            uut.read_index.next = w.into();
            clock_cycle(&mut uut, |u| &mut u.clock);
            assert_eq!(uut.read_data.val().to_u64(), model[w as usize]);
        }
    }
}

/// FoundMax against a model: random found lists (small distances, so ties are
/// common) in random slots; each slot's maximum over its first k entries and the
/// lowest entry holding it come out two clock edges after the read, a new slot
/// read every cycle.
#[test]
fn found_max_is_the_lowest_maximum() {
    use photon_fpga::hw::config::core_config::CoreConfig;
    for (k, seed) in [(1usize, 61u64), (3, 62), (10, 63), (33, 64), (64, 65)] {
        let cfg = CoreConfig::builder()
            .k(k)
            .queries_per_port(6)
            .build()
            .unwrap();
        let mut uut = FoundMax::new(&cfg);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mut r = crate::common::rng(seed);
        let mut model = vec![vec![0u64; k]; 6];
        let mut expected = std::collections::VecDeque::new();
        let mut last_ws = 0;
        for step in 0..300 {
            // A write to one slot, a read of another, or (half the time) of the slot
            // written in the cycle before: the registered write is forwarded.
            let ws: usize = r.gen_range(0..6);
            let wp: usize = r.gen_range(0..k);
            let d: u64 = r.gen_range(0..6);
            uut.write_enable.next = true;
            uut.write_slot.next = (ws as u64).into();
            uut.write_pos.next = (wp as u64).into();
            uut.write_dist.next = d.into();
            let rs: usize = if r.gen_bool(0.5) {
                last_ws
            } else {
                r.gen_range(0..6)
            };
            last_ws = ws;
            let rk: usize = r.gen_range(1..=k);
            uut.read_slot.next = (rs as u64).into();
            uut.read_k.next = (rk as u64).into();
            settle(&mut uut);
            // The model as read now (the write shows after this edge).
            let list = &model[rs][..rk];
            let max = *list.iter().max().unwrap();
            let pos = list.iter().position(|&x| x == max).unwrap();
            expected.push_back((max, pos));
            clock_cycle(&mut uut, |u| &mut u.clock);
            model[ws][wp] = d;
            // Two edges after its read (this step's tick is the second for the
            // read of the step before).
            if step >= 1 {
                let (max, pos) = expected.pop_front().unwrap();
                assert_eq!(uut.max.val().to_u64(), max, "k = {k}, step {step}");
                assert_eq!(
                    uut.max_pos.val().to_u64() as usize,
                    pos,
                    "k = {k}, step {step}"
                );
            }
        }
    }
}

/// PortArbiter against a round-robin model: the lowest request above the last
/// used grant, else the lowest request; `hold` grants the last grant again; the
/// turn moves only on `advance`. Random requests (dense and sparse), advances and
/// holds, for 1, 5, 12 and 32 requesters, grant checked every cycle.
#[test]
fn port_arbiter_is_round_robin() {
    for (n, seed) in [(1usize, 51u64), (5, 52), (12, 53), (32, 54)] {
        let mut uut = PortArbiter::new(n);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mut r = crate::common::rng(seed);
        // The model: the last used grant (None: none yet, or an advance without one).
        let mut last: Option<usize> = None;
        for step in 0..2000 {
            let density = if step % 400 < 200 { 0.5 } else { 0.08 };
            let requests: u64 = (0..n).filter(|_| r.gen_bool(density)).map(|i| 1 << i).sum();
            let hold = r.gen_bool(0.1);
            let advance = r.gen_bool(0.7);
            uut.requests.next = requests.into();
            uut.hold.next = hold;
            uut.advance.next = advance;
            settle(&mut uut);
            let lowest_from = |from: usize| (from..n).find(|&i| requests >> i & 1 == 1);
            let want = if hold {
                last
            } else {
                last.and_then(|l| lowest_from(l + 1))
                    .or_else(|| lowest_from(0))
            };
            let want_mask = want.map_or(0, |i| 1u64 << i);
            assert_eq!(
                uut.grant.val().to_u64(),
                want_mask,
                "n = {n}, step {step}: requests {requests:#x}, hold {hold}, last {last:?}"
            );
            assert_eq!(uut.granted.val(), requests != 0);
            clock_cycle(&mut uut, |u| &mut u.clock);
            if advance {
                last = want;
            }
        }
    }
}
