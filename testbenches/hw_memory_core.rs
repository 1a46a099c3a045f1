//! The external-memory core (`CoreConfig::memory`: the banked core whose banks are
//! a cache of the levels below its replicas, the map's image in a memory model
//! behind its AXI4 master): every result equals the software search read for
//! read and brute force, with a cache far smaller than the map (lines replaced
//! all the time), a memory with random extra latency and pauses on both AXI
//! channels and random stalls on every stream, across a second map; with the
//! cache's tags in BlockRAM and in LUT-RAM (only as wide as the map's tags).

use crate::common::*;
use crate::hw_banked::queries_for;
use photon_fpga::hw::config::bank_config::{BankMapping, BankPorts};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{Banking, CoreConfig};
use photon_fpga::hw::config::memory_config::CacheTags;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::axi_memory::AxiTiming;
use photon_fpga::hw::sim::native::{run_gather, CoreSim, SimOptions};

/// A memory core for `tree`: `replicas` replicas of `levels` levels, 2^`bank_bits`
/// cache banks of `lines` lines in all (their tags in `tags`), a memory of
/// `data_bits`-bit beats.
fn in_memory(
    tree: &photon_fpga::host::map::kdtree::PackedTree,
    k: usize,
    metric: Metric,
    (replicas, bank_bits, levels, ports, lines): (usize, u32, u32, BankPorts, u32),
    (data_bits, tags): (u32, CacheTags),
) -> CoreConfig {
    CoreConfig::builder()
        .k(k)
        .metric(metric)
        .controller(Controller::Barrel)
        .traversal(Traversal::Cell)
        .trees(replicas)
        .banking(Some(Banking {
            bank_bits,
            replicated_levels: levels,
            ports,
            mapping: BankMapping::Xor,
        }))
        .cache_lines(Some(lines))
        .memory_data_bits(Some(data_bits))
        .cache_tags(Some(tags))
        .build_for(tree.image())
        .expect("a memory core within the limits")
}

/// A slow, irregular memory: the tests' stress on every AXI channel.
fn unsteady(seed: u64) -> AxiTiming {
    AxiTiming {
        latency: 20,
        extra_latency: 30,
        ar_pause: 0.3,
        r_pause: 0.3,
        beat_interval: 1,
        sustained_bytes: 0.0,
        seed,
    }
}

#[test]
fn memory_core_matches_software_search() {
    let layout = PhotonLayout::new([7, 7, 6]);
    let cases = [
        // (metric, k, (replicas, bank bits, on-chip levels, ports, cache lines),
        // (memory data bits: one or two photon words a beat, tags), seed)
        (
            Metric::L2,
            6,
            (1usize, 2u32, 4u32, BankPorts::One, 8u32),
            (32u32, CacheTags::BlockRam),
            61u64,
        ),
        (
            Metric::L1,
            5,
            (2, 2, 5, BankPorts::Shared, 16),
            (64, CacheTags::LutRam),
            62,
        ),
        (
            Metric::L2,
            8,
            (2, 3, 3, BankPorts::Split, 64),
            (32, CacheTags::BlockRam),
            63,
        ),
        // Found lists as heaps (K > 64), tags in LUT-RAM (the ECP5-85k's plan at K = 500).
        (
            Metric::L2,
            70,
            (1, 2, 4, BankPorts::Split, 32),
            (64, CacheTags::LutRam),
            64,
        ),
    ];
    for (metric, k, shape, memory, seed) in cases {
        let mut r = rng(seed);
        let mut points = random_points(&mut r, 700, layout);
        points.extend(vec![[5, 6, 7]; 20]);
        let tree = pack(&points, layout);
        let cfg = in_memory(&tree, k, metric, shape, memory);
        let queries = queries_for(&mut r, &points, layout, metric, k);
        // The unsteady memory and stalls on every stream (the default memory,
        // prompt, runs in `memory_core_second_map`).
        let opts = SimOptions {
            memory: Some(unsteady(seed)),
            ..stalls(seed)
        };
        let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
        check_results(&cfg, &tree, &points, &queries, &results);
        let counted: u64 = stats.reads_per_port.iter().sum();
        let reported: u64 = results.iter().map(|r| r.visited as u64).sum();
        assert_eq!(counted, reported, "each read reaches the SearchModule once");
    }
}

/// A second map: the driver resets the core (emptying the cache) and writes the
/// new image; no line of the first map answers for the second.
#[test]
fn memory_core_second_map() {
    let layout = PhotonLayout::new([6, 6, 6]);
    let metric = Metric::L2;
    let mut r = rng(65);
    let first = random_points(&mut r, 900, layout);
    let second = random_points(&mut r, 700, layout);
    let (t1, t2) = (pack(&first, layout), pack(&second, layout));
    let cfg = in_memory(
        &t1,
        5,
        metric,
        (1, 2, 4, BankPorts::Split, 16),
        (64, CacheTags::LutRam),
    );
    let q1 = queries_for(&mut r, &first, layout, metric, 5);
    let q2 = queries_for(&mut r, &second, layout, metric, 5);
    let mut sim = CoreSim::new(&cfg, &stalls(66)).unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
    sim.load_map(t2.image()).unwrap();
    check_results(&cfg, &t2, &second, &q2, &sim.run_queries(&q2).unwrap());
}

/// The exported external-memory core under Verilator, its `m_axi` port answered
/// by the same memory model (same seed), gives the native simulation's results
/// in the same cycles.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn memory_core_under_verilator_equals_the_native_simulation() {
    use photon_fpga::hw::sim::native::Engine;
    let layout = PhotonLayout::new([7, 7, 6]);
    let mut r = rng(67);
    let points = random_points(&mut r, 900, layout);
    let tree = pack(&points, layout);
    let queries = queries_for(&mut r, &points, layout, Metric::L2, 6);
    for tags in [CacheTags::BlockRam, CacheTags::LutRam] {
        let shape = (2, 2, 4, BankPorts::Split, 16);
        let cfg = in_memory(&tree, 6, Metric::L2, shape, (64, tags));
        let run = |engine| {
            let opts = SimOptions {
                engine,
                memory: Some(unsteady(68)),
                ..stalls(69)
            };
            run_gather(&cfg, tree.image(), &queries, &opts).expect("simulation")
        };
        let (native, ns) = run(Engine::Native);
        let (verilated, vs) = run(Engine::Verilator);
        assert_eq!(native, verilated, "{tags:?}: results differ");
        assert_eq!(ns, vs, "{tags:?}: cycle and read counters differ");
        check_results(&cfg, &tree, &points, &queries, &verilated);
    }
}
