//! LutRam against a memory model: random writes (in range, past `depth` and past the
//! power-of-two memory) and random reads, every cycle. The model is the documented
//! behaviour: `depth` entries of `width` bits starting at zero, a write stores the
//! low `width` bits at its rising edge and a write past `depth` is dropped; the read
//! is asynchronous (the old entry before the edge, the new one after it) and an
//! index of the power-of-two memory past `depth` reads zero.

use photon_fpga::hw::primitives::lut_ram::LutRam;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::settle;

fn low_bits(width: u32) -> u64 {
    if width >= 32 {
        u32::MAX as u64
    } else {
        (1u64 << width) - 1
    }
}

fn lut_ram_against_model(depth: usize, width: u32, seed: u64) {
    let mut uut = LutRam::new(depth, width);
    uut.connect_all();
    check_all(&uut).expect("LutRam checks");
    let mut model = vec![0u64; depth];
    // The memory rounded up to a power of two: reads of indices below it are safe.
    let entries = depth.next_power_of_two();
    let mut r = crate::common::rng(seed);
    let read_model = |model: &[u64], i: usize| model.get(i).copied().unwrap_or(0);
    for step in 0..3000 {
        let we = r.gen_bool(0.5);
        let wi: usize = match r.gen_range(0..10) {
            0 => r.gen_range(0..256),
            1 => r.gen_range(depth..entries.max(depth + 1)),
            _ => r.gen_range(0..depth),
        };
        let data: u32 = r.gen();
        // Half the reads look at the entry being written.
        let ri: usize = if r.gen_bool(0.5) && wi < entries {
            wi
        } else {
            r.gen_range(0..entries)
        };
        uut.write_enable.next = we;
        uut.write_index.next = (wi as u64).into();
        uut.write_data.next = (data as u64).into();
        uut.read_index.next = (ri as u64).into();
        settle(&mut uut);
        // Before the edge: the entry as it was.
        assert_eq!(
            uut.read_data.val().to_u64(),
            read_model(&model, ri),
            "depth {depth} width {width} step {step}: read {ri} before the edge"
        );
        uut.clock.next = true.into();
        settle(&mut uut);
        if we && wi < depth {
            model[wi] = data as u64 & low_bits(width);
        }
        // After the edge: this cycle's write shows.
        assert_eq!(
            uut.read_data.val().to_u64(),
            read_model(&model, ri),
            "depth {depth} width {width} step {step}: read {ri} after writing {wi} (we {we})"
        );
        uut.clock.next = false.into();
        settle(&mut uut);
    }
    // Every entry, in order, at the end.
    uut.write_enable.next = false;
    for (i, &want) in model.iter().enumerate() {
        uut.read_index.next = (i as u64).into();
        settle(&mut uut);
        assert_eq!(uut.read_data.val().to_u64(), want, "final entry {i}");
    }
}

#[test]
fn lut_ram_against_a_memory_model() {
    for (depth, width, seed) in [
        (1usize, 1u32, 71u64),
        (5, 7, 72),
        (16, 32, 73),
        (21, 12, 74),
        (33, 24, 75),
        (64, 5, 76),
    ] {
        lut_ram_against_model(depth, width, seed);
    }
}
