//! The external memory's layout, in software (`MemoryLayout`, what the loader
//! writes) and in gates (`BlockMap`, what the core reads with), against the lab's
//! cache model's own layout (`memory::layout`, the model the layout was chosen
//! with): for several (H, T, s) shapes every address has the model's place; the
//! image holds every node once, at its word, and nothing else.

use crate::common::{rng, settle};
use photon_fpga::hw::config::memory_layout::{MemoryLayout, Place};
use photon_fpga::hw::config::photon_word::{PhotonLayout, TreeImage};
use photon_fpga::hw::memory::block_map::BlockMap;
use photon_fpga_lab::memory::layout::{BlockLayout, Place as ModelPlace};
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::HashSet;

const SHAPES: [(u32, u32, u32); 6] = [
    (8, 3, 4),
    (10, 2, 4),
    (12, 5, 3),
    (13, 9, 4),
    (16, 9, 4),
    (21, 9, 4),
];

fn model(h: u32, t: u32, s: u32) -> BlockLayout {
    BlockLayout::new(h, t, s, 4, 4)
}

fn same(p: Place, m: ModelPlace) -> bool {
    match (p, m) {
        (Place::OnChip, ModelPlace::OnChip) => true,
        (
            Place::External { block, offset },
            ModelPlace::External {
                block: b,
                offset: o,
            },
        ) => (block, offset) == (b, o),
        _ => false,
    }
}

#[test]
fn the_layout_places_every_node_where_the_model_does() {
    for (h, t, s) in SHAPES {
        let layout = MemoryLayout::new(h, t, s).unwrap();
        let m = model(h, t, s);
        assert_eq!(layout.blocks(), m.blocks(), "H {h} T {t} s {s}");
        let mut words = HashSet::new();
        for a in 1..(1u32 << h) {
            let p = layout.place(a);
            assert!(same(p, m.place(a)), "H {h} T {t} s {s}: {a}: {p:?}");
            if let Some(w) = layout.word_of(a) {
                assert!(w < layout.image_words() && words.insert(w), "{a}: word {w}");
            }
        }
    }
    assert!(MemoryLayout::new(10, 10, 4).is_err() && MemoryLayout::new(10, 3, 0).is_err());
}

#[test]
fn block_map_computes_the_models_place() {
    for (i, (h, t, s)) in SHAPES.into_iter().enumerate() {
        let layout = MemoryLayout::new(h, t, s).unwrap();
        let m = model(h, t, s);
        let mut uut = BlockMap::new(&layout);
        uut.connect_all();
        check_all(&uut).expect("BlockMap checks");
        let mut r = rng(40 + i as u64);
        let top = (1u32 << h) - 1;
        let mut addrs: Vec<u32> = (0..4000).map(|_| r.gen_range(1..=top)).collect();
        // Every level's first and last node.
        addrs.extend((0..h).flat_map(|l| [1 << l, (2 << l) - 1]));
        for a in addrs {
            uut.address.next = (a as u64).into();
            settle(&mut uut);
            match m.place(a) {
                ModelPlace::OnChip => assert!(uut.on_chip.val(), "H {h} T {t} s {s}: {a}"),
                ModelPlace::External { block, offset } => {
                    let got = (
                        uut.on_chip.val(),
                        uut.block.val().to_u64(),
                        uut.offset.val().to_u64(),
                        uut.word.val().to_u64(),
                    );
                    let word = ((block as u64) << s) + offset as u64;
                    assert_eq!(
                        got,
                        (false, block as u64, offset as u64, word),
                        "H {h} T {t} s {s}: {a}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_image_holds_every_node_once_at_its_word() {
    let layout = PhotonLayout::paper();
    let mut r = rng(7);
    for (h, t, s, n) in [
        (12u32, 5u32, 3u32, 3000usize),
        (13, 9, 4, 8191),
        (10, 2, 4, 700),
    ] {
        // Words that name their own address, so a misplaced word shows.
        let words: Vec<u64> = (0..=n as u64)
            .map(|a| if a == 0 { 0 } else { a * 8 + r.gen_range(0..8) })
            .collect();
        let tree = TreeImage {
            layout,
            words: &words,
        };
        let mem = MemoryLayout::new(h, t, s).unwrap();
        let image = mem.image(tree);
        assert_eq!(image.len() as u64, mem.image_words());
        let mut seen = 0;
        for (w, &v) in image.iter().enumerate() {
            if v == 0 {
                continue;
            }
            let a = (v / 8) as u32;
            assert!((1u32 << t..=n as u32).contains(&a), "word {w} holds {v}");
            assert_eq!(mem.word_of(a), Some(w as u64), "node {a}");
            assert_eq!(v, words[a as usize]);
            seen += 1;
        }
        assert_eq!(seen, n + 1 - (1 << t), "every node below T once");
    }
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints() {
    use photon_fpga::hw::export::verilog::export_block;
    let e = export_block(BlockMap::new(&MemoryLayout::new(21, 9, 4).unwrap())).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
    crate::common::lint_top(dir.path());
}
