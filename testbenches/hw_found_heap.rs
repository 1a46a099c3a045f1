//! FoundHeap against a model of what a found list holds: random inserts and
//! replacements from 16 slots, one operation a cycle, each slot's operations the
//! block's minimum spacing apart; every new root must be the maximum of the slot's
//! keys (the model's multiset), and at the end each slot's whole heap, drained by
//! replacing the root with key 0 until it is empty of real keys, must come out as
//! the model's keys in descending order. For heaps of 1, 3, 6 and 10 levels (K up
//! to 1, 7, 63 and 1023), full and partly filled lists. The exported Verilog is
//! checked by yosys, Verilator lint and Icarus.

use photon_fpga::hw::barrel::found_heap::{FoundHeap, MIN_SPACING};
use photon_fpga::hw::barrel::heap_stage::HeapOp;
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::VecDeque;
use std::process::Command;

use crate::common::{clock_cycle, lint_top, rng, settle};

fn cycle(uut: &mut FoundHeap) {
    clock_cycle(uut, |u| &mut u.clock);
}

fn op(replace: bool, slot: usize, key: u64, size: usize) -> HeapOp {
    HeapOp {
        valid: true,
        replace,
        slot: (slot as u64).into(),
        key: key.into(),
        size: (size as u64).into(),
        ..Default::default()
    }
}

/// One run: `k`-entry lists in a heap of `levels` levels, `steps` cycles, operations
/// from the first `slots` slots, each slot's `spacing` cycles apart at least (`None`:
/// the heap's own minimum).
fn run_spaced(
    levels: usize,
    k: usize,
    steps: usize,
    seed: u64,
    spacing: Option<usize>,
    slots: usize,
) {
    assert!(k < 1 << levels);
    let mut uut = FoundHeap::new(levels, 4);
    let spacing = spacing.unwrap_or(uut.min_spacing());
    uut.connect_all();
    check_all(&uut).unwrap();
    let mut r = rng(seed);
    let mut lists: Vec<Vec<u64>> = vec![vec![]; 16];
    let mut last = [-(spacing as i64); 16];
    // Expected (slot, max) per cycle, two cycles after the operation enters.
    let mut expect: VecDeque<Option<(usize, u64)>> = VecDeque::from([None, None]);
    // The drain: each slot's root replaced by 0 once per key, the slots in turn.
    let sorted: Vec<Vec<u64>> = vec![];
    let mut sorted = sorted;
    let mut drained = [0usize; 16];
    let mut turn = 0usize;
    let mut t = 0i64;
    loop {
        let mut o = HeapOp::default();
        let mut e = None;
        if (t as usize) < steps {
            let slot = r.gen_range(0..slots);
            if t - last[slot] >= spacing as i64 && r.gen_bool(0.8) {
                let l = &mut lists[slot];
                // Keys from a small range, so that equal keys occur too.
                let key = r.gen_range(1..400u64);
                let max = l.iter().copied().max();
                if l.len() < k {
                    l.push(key);
                    o = op(false, slot, key, l.len());
                } else if max.is_some_and(|m| key < m) {
                    let at = l.iter().position(|&x| Some(x) == max).unwrap();
                    l[at] = key;
                    o = op(true, slot, key, k);
                }
                if o.valid {
                    last[slot] = t;
                    e = Some((slot, l.iter().copied().max().unwrap()));
                }
            }
        } else {
            if sorted.is_empty() {
                sorted = lists
                    .iter()
                    .map(|l| {
                        let mut v = l.clone();
                        v.sort_unstable_by(|a, b| b.cmp(a));
                        v
                    })
                    .collect();
            }
            if (0..16).all(|s| drained[s] >= sorted[s].len()) && expect.iter().all(Option::is_none)
            {
                break;
            }
            // The next slot in turn with keys left and its spacing kept.
            for _ in 0..16 {
                let slot = turn;
                turn = (turn + 1) % 16;
                let n = sorted[slot].len();
                if drained[slot] < n && t - last[slot] >= spacing as i64 {
                    // Replacing the root with 0 (below every key) lifts the next
                    // largest key to the root; the size stays n.
                    let j = drained[slot];
                    o = op(true, slot, 0, n);
                    e = Some((slot, if j + 1 < n { sorted[slot][j + 1] } else { 0 }));
                    last[slot] = t;
                    drained[slot] += 1;
                    break;
                }
            }
        }
        uut.op.next = o;
        settle(&mut uut);
        let want = expect.pop_front().unwrap();
        assert_eq!(
            uut.max_valid.val(),
            want.is_some(),
            "levels {levels}, cycle {t}"
        );
        if let Some((slot, max)) = want {
            assert_eq!(uut.max_slot.val().to_u64() as usize, slot, "cycle {t}");
            assert_eq!(
                uut.max.val().to_u64(),
                max,
                "levels {levels}, k {k}, cycle {t}: slot {slot}'s new root"
            );
        }
        expect.push_back(e);
        cycle(&mut uut);
        t += 1;
    }
    // Every slot was drained whole (its roots, checked above, were its keys in
    // descending order); a slot whose list was never full was drained too.
    assert!(lists.iter().any(|l| l.len() == k), "no list filled up");
}

/// [`run_spaced`] at the block's minimum spacing, from all 16 slots.
fn run(levels: usize, k: usize, steps: usize, seed: u64) {
    run_spaced(levels, k, steps, seed, None, 16);
}

/// Operations of one slot back to back at the heap's minimum spacing (three slots
/// in turn), and a spacing one shorter must break the heap (the rule is tight): with
/// LUT-RAM levels only (3 levels: 3 cycles), one registered BlockRAM level (6: 4)
/// and two in a row (7 and 10: 5, the bound for every heap).
#[test]
fn the_minimum_spacing_is_enough_and_tight() {
    let spacing = |levels| FoundHeap::new(levels, 4).min_spacing();
    assert_eq!([3, 6, 7, 10].map(spacing), [3, 4, MIN_SPACING, MIN_SPACING]);
    for (levels, k) in [(3, 7), (6, 50), (7, 100), (10, 600)] {
        run_spaced(levels, k, 6000, 48, None, 3);
        let short = std::panic::catch_unwind(|| {
            run_spaced(levels, k, 6000, 49, Some(spacing(levels) - 1), 1)
        });
        assert!(
            short.is_err(),
            "levels {levels}: one slot's operations closer than the rule still worked"
        );
    }
}

#[test]
fn roots_are_the_maxima_and_the_heaps_hold_the_lists() {
    run(1, 1, 400, 41);
    run(3, 7, 1500, 42);
    run(3, 5, 1500, 43);
    run(6, 63, 6000, 44);
    run(6, 40, 6000, 45);
    run(10, 600, 20_000, 46);
}

#[test]
fn found_heap_verilog_is_clean() {
    let mut uut = FoundHeap::new(10, 4);
    uut.connect_all();
    check_all(&uut).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), generate_verilog(&uut)).unwrap();

    lint_top(dir.path());
}

/// The levels of fewer than 256 pairs are distributed RAM: yosys maps a 9-level heap
/// of 16 slots to the DP16KD of levels 5–8 alone, each level's 64-bit pairs two
/// DP16KD wide and 512 deep (levels 0–4, 16 to 128 pairs, go to LUT-RAM).
#[test]
fn found_heap_upper_levels_take_no_blockram() {
    let (levels, slot_bits) = (9usize, 4u32);
    let mut uut = FoundHeap::new(levels, slot_bits);
    uut.connect_all();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), generate_verilog(&uut)).unwrap();
    crate::common::require("yosys");
    let out = Command::new("yosys")
        .current_dir(dir.path())
        .args(["-q", "-p", "read_verilog top.v; synth_ecp5 -top top -noflatten -run begin:map_luts; tee -o stat.txt stat"])
        .output()
        .expect("yosys");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stat = std::fs::read_to_string(dir.path().join("stat.txt")).unwrap();
    // The totals of the design hierarchy (the last count of each cell type).
    let count = |cell: &str| -> usize {
        stat.lines()
            .rev()
            .find_map(|l| {
                l.trim()
                    .strip_prefix(cell)
                    .map(|n| n.trim().parse().unwrap_or(0))
            })
            .unwrap_or(0)
    };
    // Level l (l >= 1) holds 2^(l-1) pairs per slot.
    let want: usize = (1..levels)
        .map(|l| 1usize << (slot_bits as usize + l - 1))
        .filter(|&pairs| pairs >= 256)
        .map(|pairs| 2 * pairs.div_ceil(512))
        .sum();
    assert_eq!(want, 2 + 2 + 4 + 8);
    assert_eq!(count("DP16KD"), want, "{stat}");
    assert!(count("TRELLIS_DPR16X4") > 0, "{stat}");
}

/// `o` as the hexadecimal of the exported `op` port (the `LogicStruct`'s bits),
/// most significant nibble first.
fn op_hex(o: HeapOp) -> String {
    let b: Bits<{ HeapOp::BITS }> = o.into();
    (0..HeapOp::BITS.div_ceil(4))
        .rev()
        .map(|n| {
            let nibble = (0..4)
                .filter(|&i| 4 * n + i < HeapOp::BITS && b.get_bit(4 * n + i))
                .fold(0, |v, i| v | 1 << i);
            format!("{nibble:x}")
        })
        .collect()
}

/// The exported Verilog under Icarus, fed the rust-hdl run's inputs cycle by cycle,
/// gives the same outputs in every cycle (after the pipeline's flip-flops, which
/// start undefined in Verilog, are flushed by idle cycles).
#[test]
fn found_heap_verilog_matches_the_simulation_cycle_for_cycle() {
    // Levels 5 and 6 registered, a pair in a row.
    let levels = 7;
    let mut uut = FoundHeap::new(levels, 4);
    uut.connect_all();
    check_all(&uut).unwrap();
    let verilog = photon_fpga::hw::export::verilog::glitch_free(&generate_verilog(&uut)).unwrap();
    let mut r = rng(47);
    let (k, spacing, flush) = (70usize, uut.min_spacing(), 2 * levels + 4);
    let mut sizes = [0usize; 16];
    let mut last = [-100i64; 16];
    let mut stim = vec![];
    let mut want = vec![];
    for t in 0..4000i64 {
        let mut o = HeapOp::default();
        if t >= flush as i64 {
            let slot = r.gen_range(0..16);
            if t - last[slot] >= spacing as i64 {
                let key = r.gen_range(1..1000u64);
                o = if sizes[slot] < k {
                    sizes[slot] += 1;
                    op(false, slot, key, sizes[slot])
                } else {
                    // Not necessarily below the root: the block must still follow
                    // its own model cycle for cycle.
                    op(true, slot, key, k)
                };
                last[slot] = t;
            }
        }
        uut.op.next = o;
        settle(&mut uut);
        stim.push(op_hex(o));
        want.push(format!(
            "{} {:02x} {:08x}",
            uut.max_valid.val() as u8,
            uut.max_slot.val().to_u64(),
            uut.max.val().to_u64()
        ));
        cycle(&mut uut);
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), verilog).unwrap();
    std::fs::write(dir.path().join("stim.hex"), stim.join("\n") + "\n").unwrap();
    let n = stim.len();
    let tb = format!(
        "module tb;
reg clock = 0;
reg [{msb}:0] op;
wire max_valid;
wire [7:0] max_slot;
wire [31:0] max;
top dut(.clock(clock), .op(op), .max_valid(max_valid), .max_slot(max_slot), .max(max));
reg [{msb}:0] stim[0:{last}];
integer i;
initial begin
  $readmemh(\"stim.hex\", stim);
  for (i = 0; i < {n}; i = i + 1) begin
    op = stim[i];
    #1 $display(\"%0d %02x %08x\", max_valid, max_slot, max);
    #4 clock = 1;
    #5 clock = 0;
  end
  $finish;
end
endmodule
",
        last = n - 1,
        msb = HeapOp::BITS - 1
    );
    std::fs::write(dir.path().join("tb.v"), tb).unwrap();
    let ok = |out: std::process::Output, what: &str| {
        assert!(
            out.status.success(),
            "{what}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    ok(
        Command::new("iverilog")
            .current_dir(dir.path())
            .args(["-g2005", "-o", "sim", "tb.v", "top.v"])
            .output()
            .expect("iverilog (apt-get install -y iverilog)"),
        "iverilog",
    );
    let got = ok(
        Command::new("vvp")
            .current_dir(dir.path())
            .arg("sim")
            .output()
            .expect("vvp"),
        "vvp",
    );
    let got: Vec<&str> = got.lines().filter(|l| !l.starts_with("VCD")).collect();
    assert_eq!(got.len(), n);
    for (c, (g, w)) in got.iter().zip(&want).enumerate().skip(flush) {
        assert_eq!(g, w, "cycle {c}: Verilog against rust-hdl");
    }
}
