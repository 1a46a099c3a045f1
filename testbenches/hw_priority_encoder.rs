//! PriorityEncoder against a plain-Rust model: the lowest set bit of random masks
//! (dense, sparse, empty, full, the top bit alone) for 32- and 64-bit masks of
//! several widths, and the one-hot mode's index of random one-hot masks.

use photon_fpga::hw::primitives::priority_encoder::PriorityEncoder;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{rng, settle};

/// The lowest set bit and its index (0 with none), bit by bit.
fn lowest_model(mask: u64) -> (u64, u64) {
    (0..64)
        .find(|&i| mask >> i & 1 == 1)
        .map_or((0, 0), |i| (1u64 << i, i as u64))
}

fn masks(r: &mut rand_pcg::Pcg64, width: usize, n: usize) -> Vec<u64> {
    let all = if width == 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    };
    let mut v = vec![0, all, 1, 1u64 << (width - 1)];
    for _ in 0..n {
        let m: u64 = match r.gen_range(0..3) {
            0 => r.gen::<u64>(),
            1 => r.gen::<u64>() & r.gen::<u64>() & r.gen::<u64>(),
            _ => 1u64 << r.gen_range(0..width) | 1u64 << r.gen_range(0..width),
        };
        v.push(m & all);
    }
    v
}

fn check_lowest<const N: usize>(width: usize, seed: u64) {
    let mut uut = PriorityEncoder::<N>::lowest(width);
    uut.connect_all();
    check_all(&uut).unwrap();
    let mut r = rng(seed);
    for m in masks(&mut r, width, 2000) {
        uut.mask.next = m.into();
        settle(&mut uut);
        let (lowest, index) = lowest_model(m);
        assert_eq!(uut.lowest.val().to_u64(), lowest, "N = {N}, mask {m:#x}");
        assert_eq!(uut.index.val().to_u64(), index, "N = {N}, mask {m:#x}");
    }
}

#[test]
fn lowest_set_bit_of_random_masks() {
    check_lowest::<32>(32, 1);
    check_lowest::<32>(21, 2);
    check_lowest::<32>(1, 3);
    check_lowest::<64>(64, 4);
    check_lowest::<64>(50, 5);
}

#[test]
fn index_of_one_hot_masks() {
    for width in [1usize, 10, 32] {
        let mut uut = PriorityEncoder::<32>::one_hot(width);
        uut.connect_all();
        check_all(&uut).unwrap();
        for i in 0..width {
            uut.mask.next = (1u64 << i).into();
            settle(&mut uut);
            assert_eq!(uut.lowest.val().to_u64(), 1u64 << i);
            assert_eq!(uut.index.val().to_u64(), i as u64, "width {width}");
        }
        uut.mask.next = 0u64.into();
        settle(&mut uut);
        assert_eq!(uut.index.val().to_u64(), 0);
    }
}
