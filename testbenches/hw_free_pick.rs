//! FreePick against a cycle model: random free masks and takes (and resets) for
//! 1, 6, 16 and 32 entries; every cycle the registered pick (one-hot, index,
//! valid) must be the lowest of the previous cycle's free entries less the one
//! taken then, and `still_free` that set.

use photon_fpga::hw::primitives::free_pick::FreePick;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{clock_cycle, rng, settle};

fn cycle(uut: &mut FreePick) {
    clock_cycle(uut, |u| &mut u.clock);
}

#[test]
fn registered_pick_is_the_lowest_still_free() {
    for (entries, seed) in [(1usize, 11u64), (6, 12), (16, 13), (32, 14)] {
        let all = if entries == 32 {
            0xFFFF_FFFF
        } else {
            (1u64 << entries) - 1
        };
        let mut uut = FreePick::new(entries);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mut r = rng(seed);
        // The model's registers: the pick (0: none).
        let mut pick = 0u64;
        uut.reset.next = true;
        cycle(&mut uut);
        uut.reset.next = false;
        for step in 0..3000 {
            let free = match r.gen_range(0..4) {
                0 => 0,
                1 => all,
                _ => r.gen::<u64>() & all,
            };
            let take = r.gen_bool(0.5);
            let reset = r.gen_range(0..200) == 0;
            uut.free.next = free.into();
            uut.take.next = take;
            uut.reset.next = reset;
            settle(&mut uut);
            assert_eq!(
                uut.pick.val().to_u64(),
                pick,
                "entries {entries}, step {step}"
            );
            assert_eq!(uut.pick_valid.val(), pick != 0, "step {step}");
            if pick != 0 {
                assert_eq!(uut.pick_index.val().to_u64(), pick.trailing_zeros() as u64);
            }
            let still = if take { free & !pick } else { free };
            assert_eq!(uut.still_free.val().to_u64(), still, "step {step}");
            cycle(&mut uut);
            pick = if reset {
                0
            } else {
                still & still.wrapping_neg()
            };
        }
    }
}
