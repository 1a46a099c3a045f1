//! MaxFinder (paper §4.4) against a plain `iter().max()` model: random lists, all
//! equal lists, ties (the lowest slot wins), one cycle per distance bit plus the
//! priming cycle that gathers the first row.

use photon_fpga::hw::modules::max_finder::MaxFinder;
use rand::Rng;
use rust_hdl::prelude::*;

struct Bench<const S: usize> {
    uut: MaxFinder<S>,
    dist_bits: u32,
}

impl<const S: usize> Bench<S> {
    fn new(dist_bits: u32) -> Self {
        let mut uut = MaxFinder::<S>::new(dist_bits, S);
        uut.connect_all();
        check_all(&uut).expect("MaxFinder checks");
        let mut b = Bench { uut, dist_bits };
        b.settle();
        b
    }
    fn settle(&mut self) {
        crate::common::settle(&mut self.uut);
    }
    fn tick(&mut self) {
        self.uut.clock.next = true.into();
        self.settle();
        self.uut.clock.next = false.into();
        self.settle();
    }
    fn write(&mut self, slot: usize, d: u64) {
        self.uut.write_enable.next = true;
        self.uut.write_slot.next = (1u64 << slot).into();
        self.uut.write_dist.next = d.into();
        self.settle();
        self.tick();
        self.uut.write_enable.next = false;
        self.settle();
    }
    /// Run a search over `candidates`; returns (max, filter, max slot one-hot, cycles busy).
    fn find(&mut self, candidates: u64) -> (u64, u64, u64, u32) {
        self.uut.start.next = true;
        self.uut.candidates.next = candidates.into();
        self.settle();
        self.tick();
        self.uut.start.next = false;
        self.settle();
        let busy_cycles = self.run();
        let (max, filter, slot) = self.result();
        (max, filter, slot, busy_cycles)
    }
    /// Clock until not busy; the cycles it was busy.
    fn run(&mut self) -> u32 {
        let mut busy_cycles = 0;
        while self.uut.busy.val() {
            busy_cycles += 1;
            assert!(busy_cycles <= 64, "MaxFinder never finished");
            self.tick();
        }
        busy_cycles
    }
    /// (max, filter, max slot one-hot).
    fn result(&self) -> (u64, u64, u64) {
        (
            self.uut.max_dist.val().to_u64(),
            self.uut.filter.val().to_u64(),
            self.uut.max_slot.val().to_u64(),
        )
    }
}

/// Independent model: the maximum, every slot holding it, the lowest such slot.
fn model(list: &[u64]) -> (u64, u64, u64) {
    let max = *list.iter().max().unwrap();
    let filter = list
        .iter()
        .enumerate()
        .filter(|&(_, &d)| d == max)
        .fold(0u64, |f, (i, _)| f | 1 << i);
    let lowest = list.iter().position(|&d| d == max).unwrap();
    (max, filter, 1 << lowest)
}

fn check_list<const S: usize>(b: &mut Bench<S>, list: &[u64]) {
    for (s, &d) in list.iter().enumerate() {
        b.write(s, d);
    }
    let candidates = u64::MAX >> (64 - list.len());
    let (max, filter, slot, cycles) = b.find(candidates);
    assert_eq!((max, filter, slot), model(list), "list {list:?}");
    assert_eq!(
        cycles,
        b.dist_bits + 1,
        "one cycle per distance bit plus one, independent of K"
    );
}

#[test]
fn random_lists() {
    let mut r = crate::common::rng(7);
    for &bits in &[1u32, 5, 12, 22, 32] {
        let mut b = Bench::<32>::new(bits);
        let top = if bits == 64 {
            u64::MAX
        } else {
            (1u64 << bits) - 1
        };
        for _ in 0..30 {
            let k = r.gen_range(1..=32usize);
            let list: Vec<u64> = (0..k).map(|_| r.gen_range(0..=top)).collect();
            check_list(&mut b, &list);
        }
    }
}

#[test]
fn all_equal_and_extremes() {
    for &bits in &[12u32, 32] {
        let mut b = Bench::<32>::new(bits);
        let top = (1u64 << bits) - 1;
        for &v in &[0, 1, top, top / 2] {
            for &k in &[1usize, 2, 10, 32] {
                check_list(&mut b, &vec![v; k]);
            }
        }
    }
}

#[test]
fn ties_pick_the_lowest_slot() {
    let mut r = crate::common::rng(11);
    let mut b = Bench::<32>::new(12);
    for _ in 0..40 {
        let k = r.gen_range(2..=32usize);
        // Few distinct values: many ties at the maximum and below.
        let list: Vec<u64> = (0..k).map(|_| r.gen_range(0..4u64) * 1000).collect();
        check_list(&mut b, &list);
    }
    // The maximum at the last and at the first slot only.
    check_list(&mut b, &[3, 3, 3, 7]);
    check_list(&mut b, &[7, 3, 3, 7]);
}

/// The 64-bit slot masks of K > 32 (K = 50 and all 64 slots), ties included.
#[test]
fn wide_lists() {
    let mut r = crate::common::rng(13);
    for &bits in &[12u32, 32] {
        let mut b = Bench::<64>::new(bits);
        let top = (1u64 << bits) - 1;
        for k in [33usize, 50, 64] {
            for spread in [top, 3] {
                let list: Vec<u64> = (0..k).map(|_| r.gen_range(0..=spread)).collect();
                check_list(&mut b, &list);
            }
        }
        check_list(&mut b, &vec![top; 64]);
    }
}

#[test]
fn only_the_configured_slots_exist() {
    // A 5-slot MaxFinder ignores writes and candidates beyond slot 4.
    let mut uut = MaxFinder::<32>::new(8, 5);
    uut.connect_all();
    let mut b = Bench { uut, dist_bits: 8 };
    b.settle();
    for (s, &d) in [10u64, 20, 30, 40, 50].iter().enumerate() {
        b.write(s, d);
    }
    b.write(7, 255);
    let (max, filter, slot, _) = b.find(0xFF);
    assert_eq!((max, filter, slot), (50, 1 << 4, 1 << 4));
}

#[test]
fn candidates_restrict_the_search() {
    // Only the candidate slots take part (the list is not full yet).
    let mut b = Bench::<32>::new(12);
    let list = [4000u64, 5, 9, 100, 4095];
    for (s, &d) in list.iter().enumerate() {
        b.write(s, d);
    }
    let (max, filter, slot, _) = b.find(0b01110);
    assert_eq!((max, filter, slot), (100, 0b01000, 0b01000));
}

#[test]
fn a_write_with_start_takes_part_and_candidates_are_read_a_cycle_later() {
    // The QueryModule appends the K-th photon in the cycle it starts the search
    // and its occupied mask has that slot only from the next cycle on.
    let mut b = Bench::<32>::new(12);
    for (s, &d) in [30u64, 700, 9].iter().enumerate() {
        b.write(s, d);
    }
    b.uut.write_enable.next = true;
    b.uut.write_slot.next = (1u64 << 3).into();
    b.uut.write_dist.next = 2000u64.into();
    b.uut.start.next = true;
    b.uut.candidates.next = 0b0111u64.into();
    b.settle();
    b.tick();
    b.uut.write_enable.next = false;
    b.uut.start.next = false;
    b.uut.candidates.next = 0b1111u64.into();
    b.settle();
    let cycles = b.run();
    let got = b.result();
    assert_eq!(got, model(&[30, 700, 9, 2000]));
    assert_eq!(cycles, 13);
}
