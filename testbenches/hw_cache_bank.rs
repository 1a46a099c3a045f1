//! CacheBank with FillArbiter, LineFill and the AXI memory model (`hw::sim::axi_memory`): two
//! read ports ask for random words of the bank's blocks (with locality, as a
//! search's reads have), each read repeated until it hits, while the memory
//! answers with latency and random pauses. A hit must be the image's word of the
//! row's block (never another block's that shares the line, never a line being
//! filled); every read must hit within a bound (the miss was fetched); lines
//! are replaced as blocks that share them are read. Run with one photon word a
//! memory beat and with two (a 64-bit memory: each RAM word a pair), and with
//! the tags in LUT-RAM only as wide as the largest block's tag (a tag one bit too
//! narrow would alias two blocks of a line, and hits would be other blocks' words).

use crate::common::{rng, settle};
use photon_fpga::hw::config::memory_config::CacheTags;
use photon_fpga::hw::memory::cache_bank::CacheBank;
use photon_fpga::hw::memory::cache_port::{LineShape, TagShape};
use photon_fpga::hw::memory::fill_arbiter::FillArbiter;
use photon_fpga::hw::memory::line_fill::LineFill;
use photon_fpga::hw::sim::axi_memory::{AxiBurst, AxiMemory, AxiTiming};
use rand::Rng;
use rust_hdl::prelude::*;

/// Banks, this bank, its lines, block levels (16 words), blocks in memory.
const BANK_BITS: u32 = 2;
const BANK: u64 = 2;
const LINE_BITS: u32 = 3;
const S: u32 = 4;
const BLOCKS: u64 = 96;
const WORD: u32 = 32;

/// The row of word `offset` of `block` (a block of this bank).
fn row(block: u64, offset: u64) -> u64 {
    let lines = 1u64 << (LINE_BITS + BANK_BITS);
    let (tag, line) = (block / lines, (block % lines) >> BANK_BITS);
    (tag << (LINE_BITS + S)) | (line << S) | offset
}

/// The line of `2^lane_shift` 32-bit words a beat.
fn shape(lane_shift: u32) -> LineShape {
    LineShape {
        block_levels: S,
        word_bits: WORD,
        lane_shift,
        lane_bits: 32,
    }
}

/// The bank's tags in `tags`.
fn tags(tags: CacheTags) -> TagShape {
    TagShape::new(tags, BLOCKS as u32, BANK_BITS, LINE_BITS)
}

#[test]
fn hits_are_the_blocks_words_and_every_read_hits_in_time() {
    hits_are_the_blocks_words(0, CacheTags::BlockRam);
}

#[test]
fn hits_are_the_blocks_words_with_two_words_a_beat() {
    hits_are_the_blocks_words(1, CacheTags::BlockRam);
}

#[test]
fn hits_are_the_blocks_words_with_the_tags_in_lut_ram() {
    // 96 blocks over 4 banks of 8 lines: tags 0 to 2, two bits.
    assert_eq!(tags(CacheTags::LutRam).bits, 2);
    hits_are_the_blocks_words(1, CacheTags::LutRam);
}

fn hits_are_the_blocks_words(lane_shift: u32, tag_ram: CacheTags) {
    let timing = AxiTiming {
        latency: 14,
        extra_latency: 8,
        ar_pause: 0.3,
        r_pause: 0.25,
        beat_interval: 1,
        sustained_bytes: 0.0,
        seed: 3,
    };
    let mut r = rng(17);
    let image: Vec<u64> = (0..BLOCKS << S).map(|_| r.gen::<u32>() as u64).collect();
    let mut memory = AxiMemory::from_words(&image, 4, timing);
    let mut fill = LineFill::<64>::new(0, 4 << S, 4 << lane_shift);
    let mut bank = CacheBank::new(
        BANK as u32,
        BANK_BITS,
        1 << LINE_BITS,
        2,
        shape(lane_shift),
        tags(tag_ram),
    );
    let mut arbiter = FillArbiter::new(1);
    fill.connect_all();
    bank.connect_all();
    arbiter.connect_all();
    check_all(&arbiter).expect("FillArbiter checks");
    check_all(&fill).expect("LineFill checks");
    check_all(&bank).expect("CacheBank checks");
    // This bank's blocks: block mod B = this bank.
    let mine: Vec<u64> = (0..BLOCKS)
        .filter(|b| b % (1 << BANK_BITS) == BANK)
        .collect();
    let pick = |r: &mut rand_pcg::Pcg64, near: Option<u64>| -> (u64, u64) {
        let block = match near {
            Some(b) if r.gen_bool(0.6) => b,
            _ => mine[r.gen_range(0..mine.len())],
        };
        (block, r.gen_range(0..1 << S))
    };
    // Per port: the read it wants, since when, and the read in flight.
    let mut want: Vec<(u64, u64)> = (0..2).map(|_| pick(&mut r, None)).collect();
    let mut since = [0u64; 2];
    let mut in_flight: [Option<(u64, u64)>; 2] = [None, None];
    let (mut hits, mut misses, mut done_reads) = (0u64, 0u64, 0u64);
    fill.reset.next = true;
    bank.reset.next = true;
    for cycle in 0..30_000u64 {
        let resetting = cycle < 2;
        fill.reset.next = resetting;
        bank.reset.next = resetting;
        arbiter.reset.next = resetting;
        let out = memory.drive();
        fill.m_axi.arready.next = out.arready;
        fill.m_axi.rvalid.next = out.rvalid;
        fill.m_axi.rdata.next = out.rdata.into();
        fill.m_axi.rlast.next = out.rlast;
        fill.m_axi.rresp.next = (out.rresp as u64).into();
        settle(&mut fill);
        // Last cycle's reads answer now.
        for p in 0..2 {
            if let Some((block, offset)) = in_flight[p].take() {
                let port = if p == 0 { &bank.read } else { &bank.second };
                let word = port.word.val().to_u64();
                if word >> WORD & 1 == 0 {
                    assert_eq!(
                        word,
                        image[((block << S) + offset) as usize],
                        "cycle {cycle} port {p}: a hit on block {block} word {offset}"
                    );
                    hits += 1;
                    done_reads += 1;
                    want[p] = pick(&mut r, Some(block));
                    since[p] = cycle;
                } else {
                    misses += 1;
                    assert!(
                        cycle - since[p] < 2_000,
                        "port {p}: block {block} never arrived"
                    );
                }
            }
        }
        for p in 0..2 {
            let ask = !resetting && r.gen_bool(0.8);
            let port = if p == 0 {
                &mut bank.read
            } else {
                &mut bank.second
            };
            port.enable.next = ask;
            port.row.next = row(want[p].0, want[p].1).into();
            if ask {
                in_flight[p] = Some(want[p]);
            }
        }
        bank.fill_taken.next = arbiter.taken.val().any();
        bank.write_enable.next = fill.write_enable.val();
        bank.write_index.next = fill.write_index.val();
        bank.write_data.next = fill.write_data.val().to_u64().into();
        bank.filled_valid.next = fill.filled_valid.val();
        bank.filled_line.next = fill.filled_line.val();
        settle(&mut bank);
        arbiter.requests.next = u64::from(bank.fill_valid.val()).into();
        arbiter.chosen_block.next = bank.fill_block.val();
        arbiter.chosen_line.next = bank.fill_line.val();
        arbiter.fill_ready.next = fill.fill_ready.val();
        settle(&mut arbiter);
        fill.fill_valid.next = arbiter.fill_valid.val();
        fill.fill_block.next = arbiter.fill_block.val();
        fill.fill_line.next = arbiter.fill_line.val();
        settle(&mut fill);
        assert!(!fill.error.val());
        let ar = fill.m_axi.arvalid.val().then(|| AxiBurst {
            addr: fill.m_axi.araddr.val().to_u64(),
            len: fill.m_axi.arlen.val().to_u64() as u8,
            size: fill.m_axi.arsize.val().to_u64() as u8,
            burst: fill.m_axi.arburst.val().to_u64() as u8,
        });
        memory.edge(ar, fill.m_axi.rready.val());
        fill.clock.next = true.into();
        bank.clock.next = true.into();
        arbiter.clock.next = true.into();
        settle(&mut fill);
        settle(&mut bank);
        settle(&mut arbiter);
        fill.clock.next = false.into();
        bank.clock.next = false.into();
        arbiter.clock.next = false.into();
    }
    // Every burst was one of this bank's blocks; lines were reused (more blocks
    // fetched than there are lines), and the locality paid: far fewer fills than
    // reads answered (a miss is asked again every cycle until its block is there).
    assert!(memory
        .bursts
        .iter()
        .all(|b| (b.addr / (4 << S)) % (1 << BANK_BITS) == BANK));
    let fills = memory.bursts.len() as u64;
    assert!(fills > 1 << LINE_BITS, "{fills} fills");
    assert!(
        done_reads > 2_000 && fills < done_reads / 2,
        "{done_reads} reads answered ({hits} hits), {fills} fills, {misses} missed tries"
    );
}

/// FillArbiter among five banks that each hold a request until it is taken, and a
/// fill that is ready at random: every request reaches the fill exactly once,
/// in the order taken, at most one bank is told a cycle, and a bank that
/// keeps asking waits at most one turn of the others (with the one chosen when it
/// asked).
#[test]
fn fill_arbiter_takes_each_request_once_in_turn() {
    const N: usize = 5;
    let mut r = rng(29);
    let mut arbiter = FillArbiter::new(N);
    arbiter.connect_all();
    check_all(&arbiter).expect("FillArbiter checks");
    // Per bank: its request (a serial number), how long it has waited in picks.
    let mut request: [Option<u64>; N] = [None; N];
    let mut waited = [0usize; N];
    let mut serial = 0u64;
    let (mut taken_order, mut started) = (Vec::new(), Vec::new());
    for cycle in 0..20_000u64 {
        arbiter.reset.next = cycle < 2;
        // The bank told it was taken drops its request, as CacheBank does, and
        // asks again from the next cycle at the earliest.
        let taken = arbiter.taken.val().to_u64();
        assert!(taken.count_ones() <= 1, "cycle {cycle}: {taken:b}");
        let told = (0..N).find(|j| taken >> j & 1 == 1);
        if let Some(j) = told {
            let id = request[j].take().expect("a bank taken without a request");
            taken_order.push(id);
            for (k, w) in waited.iter_mut().enumerate() {
                *w = if k == j {
                    0
                } else {
                    *w + usize::from(request[k].is_some())
                };
            }
        }
        for (j, (req, w)) in request.iter_mut().zip(waited.iter_mut()).enumerate() {
            if req.is_none() && told != Some(j) && cycle >= 2 && r.gen_bool(0.3) {
                *req = Some(serial);
                serial += 1;
                *w = 0;
            }
        }
        assert!(waited.iter().all(|&w| w < N), "cycle {cycle}: {waited:?}");
        let mask = (0..N).fold(0u64, |m, j| m | u64::from(request[j].is_some()) << j);
        arbiter.requests.next = mask.into();
        settle(&mut arbiter);
        let choice = arbiter.choice.val().to_u64();
        let chosen = (0..N).find(|j| choice >> j & 1 == 1);
        let id = chosen.and_then(|j| request[j]).unwrap_or(0);
        arbiter.chosen_block.next = id.into();
        arbiter.chosen_line.next = (id & 0xffff).into();
        let ready = r.gen_bool(0.5);
        arbiter.fill_ready.next = ready;
        settle(&mut arbiter);
        if ready && arbiter.fill_valid.val() {
            started.push(arbiter.fill_block.val().to_u64());
            assert_eq!(
                arbiter.fill_line.val().to_u64(),
                started[started.len() - 1] & 0xffff
            );
        }
        arbiter.clock.next = true.into();
        settle(&mut arbiter);
        arbiter.clock.next = false.into();
    }
    assert!(taken_order.len() > 3_000, "{} taken", taken_order.len());
    let mut sorted = taken_order.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), taken_order.len(), "a request taken twice");
    assert_eq!(
        started[..],
        taken_order[..started.len()],
        "the fills are the requests taken"
    );
    assert!(taken_order.len() - started.len() <= 1);
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints() {
    use photon_fpga::hw::export::verilog::export_block;
    let t = TagShape::new(CacheTags::LutRam, BLOCKS as u32, BANK_BITS, 8);
    let e = export_block(CacheBank::new(BANK as u32, BANK_BITS, 256, 2, shape(1), t)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
    crate::common::lint_top(dir.path());
}
