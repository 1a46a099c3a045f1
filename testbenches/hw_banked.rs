//! The banked core (`CoreConfig::banking`: T replicas of the top L levels, two
//! barrel datapaths each, the levels below over B banks behind the BankCrossbar):
//! every result equals the software search read for read and brute force, under
//! random stalls on every stream, across a second map and a reset mid-search;
//! every photon read is counted once (no read lost or repeated by the
//! interconnect); configurations it cannot build are refused by name.

use crate::common::*;
use crate::hw_core::hard_queries;
use photon_fpga::hw::config::bank_config::{BankMapping, BankPorts};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{Banking, CoreConfig};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::{HwQuery, HwResult, SimStats};
use photon_fpga::hw::sim::native::{run_gather, CoreSim, SimOptions};
use rand_pcg::Pcg64;

/// A banked barrel core for `tree`: `trees` replicas of `levels` levels, 2^`bank_bits` banks.
fn banked(
    tree: &photon_fpga::host::map::kdtree::PackedTree,
    k: usize,
    metric: Metric,
    traversal: Traversal,
    (trees, bank_bits, levels, ports): (usize, u32, u32, BankPorts),
) -> CoreConfig {
    CoreConfig::builder()
        .k(k)
        .metric(metric)
        .controller(Controller::Barrel)
        .traversal(traversal)
        .trees(trees)
        .banking(Some(Banking {
            bank_bits,
            replicated_levels: levels,
            ports,
            mapping: BankMapping::Xor,
        }))
        .build_for(tree.image())
        .expect("a banked configuration within the limits")
}

/// The interconnect neither loses nor repeats a read: the reads the ports
/// counted are the reads the results report.
fn check_reads_counted(stats: &SimStats, results: &[HwResult]) {
    let counted: u64 = stats.reads_per_port.iter().sum();
    let reported: u64 = results.iter().map(|r| r.visited as u64).sum();
    assert_eq!(
        counted, reported,
        "reads counted by the ports vs the results"
    );
}

/// Every one of the `d` datapaths read something.
fn check_every_datapath_read(stats: &SimStats, d: usize) {
    assert_eq!(stats.reads_per_port.len(), d);
    for (p, &reads) in stats.reads_per_port.iter().enumerate() {
        assert!(reads > 0, "datapath {p} never read: {stats:?}");
    }
}

/// Every one of the `r` result streams carried a beat.
fn check_every_stream_used(stats: &SimStats, r: usize) {
    assert_eq!(stats.result_beats_per_stream.len(), r);
    for (s, &b) in stats.result_beats_per_stream.iter().enumerate() {
        assert!(b > 0, "stream {s} of {r} carried nothing: {stats:?}");
    }
}

pub fn queries_for(
    r: &mut Pcg64,
    points: &[[u32; 3]],
    layout: PhotonLayout,
    metric: Metric,
    k: usize,
) -> Vec<HwQuery> {
    let mut queries = random_queries(r, 50, layout, k, metric);
    queries.extend(hard_queries(points, layout, metric, k, 7));
    for (i, q) in queries.iter_mut().enumerate() {
        q.id = i as u32;
    }
    queries
}

#[test]
fn banked_core_matches_software_search() {
    let layout = PhotonLayout::new([7, 7, 6]);
    let cases = [
        // (metric, traversal, k, (trees, bank bits, replicated levels, bank
        // ports), seed)
        (
            Metric::L2,
            Traversal::Cell,
            6,
            (1usize, 2u32, 3u32, BankPorts::One),
            91u64,
        ),
        (
            Metric::L1,
            Traversal::Remember,
            5,
            (2, 3, 4, BankPorts::Shared),
            92,
        ),
        (
            Metric::L2,
            Traversal::Cell,
            8,
            (3, 4, 4, BankPorts::Split),
            93,
        ),
        (
            Metric::L2,
            Traversal::Cell,
            8,
            (2, 4, 4, BankPorts::Shared),
            99,
        ),
        // Found lists as heaps (K > 64) behind the banks.
        (
            Metric::L2,
            Traversal::Cell,
            70,
            (2, 3, 5, BankPorts::Split),
            94,
        ),
    ];
    for (metric, traversal, k, shape, seed) in cases {
        let mut r = rng(seed);
        let mut points = random_points(&mut r, 400, layout);
        points.extend(vec![[5, 6, 7]; 20]);
        let tree = pack(&points, layout);
        let cfg = banked(&tree, k, metric, traversal, shape);
        let queries = queries_for(&mut r, &points, layout, metric, k);
        for opts in [SimOptions::default(), stalls(seed)] {
            let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
            check_results(&cfg, &tree, &points, &queries, &results);
            check_reads_counted(&stats, &results);
            check_every_datapath_read(&stats, 2 * shape.0);
        }
    }
}

/// The banks picked by the address's low bits alone (`--bank-map modulo`): the
/// same answers and reads as the software search, only other banks.
#[test]
fn banked_core_with_the_modulo_bank_map_matches_software_search() {
    let layout = PhotonLayout::new([7, 7, 6]);
    let mut r = rng(95);
    let points = random_points(&mut r, 500, layout);
    let tree = pack(&points, layout);
    let xor = banked(
        &tree,
        8,
        Metric::L2,
        Traversal::Cell,
        (2, 3, 4, BankPorts::Split),
    );
    let cfg = xor
        .to_builder()
        .bank_mapping(BankMapping::Modulo)
        .build()
        .expect("the same core with the modulo map");
    assert_eq!(cfg.bank_mapping(), BankMapping::Modulo);
    let queries = queries_for(&mut r, &points, layout, Metric::L2, 8);
    for opts in [SimOptions::default(), stalls(95)] {
        let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
        check_results(&cfg, &tree, &points, &queries, &results);
        check_reads_counted(&stats, &results);
        check_every_datapath_read(&stats, 4);
    }
}

/// A second, smaller map over the first without reset (every replica and bank
/// rewritten), then a reset in the middle of a search.
#[test]
fn banked_reload_and_reset() {
    let layout = PhotonLayout::new([6, 6, 6]);
    let metric = Metric::L2;
    let mut r = rng(95);
    let first = random_points(&mut r, 500, layout);
    let second = random_points(&mut r, 90, layout);
    let (t1, t2) = (pack(&first, layout), pack(&second, layout));
    let cfg = banked(&t1, 5, metric, Traversal::Cell, (2, 3, 4, BankPorts::Split));
    let q1 = queries_for(&mut r, &first, layout, metric, 5);
    let q2 = queries_for(&mut r, &second, layout, metric, 5);
    let mut sim = CoreSim::new(&cfg, &stalls(96)).unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
    sim.load_map(t2.image()).unwrap();
    check_results(&cfg, &t2, &second, &q2, &sim.run_queries(&q2).unwrap());
    let partial = sim.run_queries_for(&q1, 80).unwrap();
    assert!(partial.iter().any(Option::is_none), "the run was cut short");
    sim.reset().unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
}

/// R result streams, each the merge of D / R datapaths: every result whole and
/// right whichever stream it left on, every stream used, under stalls on each.
#[test]
fn results_leave_on_several_streams() {
    let layout = PhotonLayout::new([7, 7, 6]);
    let metric = Metric::L2;
    let mut r = rng(97);
    let points = random_points(&mut r, 600, layout);
    let tree = pack(&points, layout);
    let queries = queries_for(&mut r, &points, layout, metric, 7);
    let base = |trees| {
        banked(
            &tree,
            7,
            metric,
            Traversal::Cell,
            (trees, 3, 5, BankPorts::Shared),
        )
        .to_builder()
    };
    for (builder, streams) in [
        (base(2).result_streams(2), 2usize),
        (base(2).result_streams(4), 4),
        (base(3).result_streams(3), 3),
        // One whole tree (no banks): its two ports on a stream each.
        (base(1).banking(None).result_streams(2), 2),
    ] {
        let cfg = builder.build().expect("streams within the limits");
        for opts in [SimOptions::default(), stalls(98)] {
            let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
            check_results(&cfg, &tree, &points, &queries, &results);
            check_reads_counted(&stats, &results);
            check_every_stream_used(&stats, streams);
            // Each result is 1 + ceil(count / 2) beats: the streams carried them all.
            let beats: u64 = results
                .iter()
                .map(|r| 1 + r.found.len().div_ceil(2) as u64)
                .sum();
            assert_eq!(stats.result_beats, beats, "{streams} streams");
        }
    }
}

/// The widest banked core: 16 replicas, D = 32 datapaths (every bit of the
/// crossbar's request masks), on 8 result streams, both port modes; every
/// datapath and every stream carries work, every answer is right.
#[test]
fn thirty_two_datapaths_share_the_banks() {
    let layout = PhotonLayout::new([7, 7, 6]);
    let metric = Metric::L2;
    let mut r = rng(101);
    let points = random_points(&mut r, 700, layout);
    let tree = pack(&points, layout);
    let mut queries = random_queries(&mut r, 600, layout, 6, metric);
    for (i, q) in queries.iter_mut().enumerate() {
        q.id = i as u32;
    }
    for ports in [BankPorts::Split, BankPorts::Shared] {
        let cfg = banked(&tree, 6, metric, Traversal::Cell, (16, 4, 5, ports))
            .to_builder()
            .result_streams(8)
            .build()
            .expect("D = 32 within the limits");
        let opts = if ports == BankPorts::Split {
            stalls(102)
        } else {
            SimOptions::default()
        };
        let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
        check_results(&cfg, &tree, &points, &queries, &results);
        check_reads_counted(&stats, &results);
        check_every_datapath_read(&stats, 32);
        check_every_stream_used(&stats, 8);
    }
}

#[test]
fn banked_configurations_it_cannot_build_are_refused() {
    let base = CoreConfig::builder()
        .address_bits(12)
        .controller(Controller::Barrel)
        .traversal(Traversal::Cell);
    let bank = |bank_bits, replicated_levels| {
        Some(Banking {
            bank_bits,
            replicated_levels,
            ports: BankPorts::Shared,
            mapping: BankMapping::Xor,
        })
    };
    for (builder, needle) in [
        (
            CoreConfig::builder().address_bits(12).banking(bank(2, 4)),
            "controller modules",
        ),
        (base.banking(bank(0, 4)), "banks = 1"),
        (base.banking(bank(11, 11)), "banks = 2048"),
        (base.banking(bank(4, 3)), "replicated levels = 3"),
        (base.banking(bank(4, 12)), "replicated levels = 12"),
        (base.address_bits(20).banking(bank(3, 6)), "2^17 rows"),
        (
            base.trees(2).banking(bank(2, 4)).result_streams(3),
            "result_streams = 3",
        ),
        (
            base.banking(bank(2, 4)).result_streams(0),
            "result_streams = 0",
        ),
        (base.result_streams(4), "result_streams = 4"),
        (base.trees(2).result_streams(2), "one result stream"),
        // D <= 32 (the crossbar's 32-bit request masks), R <= 16, arrays T <= 8.
        (base.trees(17).banking(bank(3, 5)), "trees = 17"),
        (
            base.trees(16).banking(bank(3, 5)).result_streams(32),
            "result_streams = 32",
        ),
        (base.trees(9), "trees = 9"),
    ] {
        let e = builder.build().expect_err(needle).to_string();
        assert!(e.contains(needle), "{e:?} should name {needle:?}");
    }
}
