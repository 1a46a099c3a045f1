//! The external-memory cache model (`lab::memory`): the block layout is a bijection
//! onto (block, word) with subtree blocks, the cache equals a naive reference on
//! random traces, both models count every read of the software search exactly
//! once, a cache as large as the map misses once per block touched, the cycle
//! model meets its closed forms, and the report runs.

use photon_fpga::host::map::kdtree::{KdTree, PackedTree};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga_lab::banking::stream::read_stream;
use photon_fpga_lab::memory::cache::{Cache, CacheConfig, Policy};
use photon_fpga_lab::memory::layout::{BlockLayout, Place};
use photon_fpga_lab::memory::sim::{run, Machine, MemoryTiming};
use photon_fpga_lab::memory::trace::{replay, Replay, Sharing};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::collections::{HashMap, HashSet};

#[test]
fn the_layout_is_a_bijection_onto_blocks_of_subtrees() {
    for (h, t, s) in [
        (12, 3, 4),
        (13, 4, 3),
        (10, 0, 2),
        (11, 5, 6),
        (9, 2, 7),
        (8, 8, 3),
    ] {
        let lay = BlockLayout::new(h, t, s, 4, 16);
        let mut cells = HashSet::new();
        let mut bytes = HashSet::new();
        for a in 1u32..1 << h {
            match lay.place(a) {
                Place::OnChip => assert!(a < 1 << t, "{a} on chip below T = {t}"),
                Place::External { block, offset } => {
                    assert!(a >= 1 << t);
                    assert!(block < lay.blocks() && offset < (1 << s) - 1);
                    assert!(cells.insert((block, offset)), "{a} shares a word");
                    assert_eq!(lay.address(block, offset), Some(a));
                    let b = lay.byte_address(a).unwrap();
                    assert!(b + 4 <= lay.memory_bytes() && bytes.insert(b));
                    // A block is a subtree: a node's parent is in its block
                    // unless the node is the block's root (offset 0).
                    if offset > 0 {
                        match lay.place(a / 2) {
                            Place::External { block: pb, .. } => assert_eq!(pb, block),
                            Place::OnChip => panic!("{a}'s parent on chip"),
                        }
                    }
                }
            }
        }
        // Onto: every word of every block that holds a node is one of them.
        let mut held = 0;
        for b in 0..lay.blocks() {
            for o in 0..(1 << s) - 1 {
                if let Some(a) = lay.address(b, o) {
                    held += 1;
                    assert!(cells.contains(&(b, o)) && a < 1 << h);
                }
            }
        }
        assert_eq!(held, (1u32 << h) - (1 << t));
        assert_eq!(cells.len(), held as usize);
        // A descent touches one block per band: ceil((H − T) / s).
        for leaf in [1u32 << (h - 1), (1 << h) - 1, (1 << (h - 1)) + 5] {
            let mut blocks = HashSet::new();
            let mut a = leaf;
            while a >= 1 {
                if let Place::External { block, .. } = lay.place(a) {
                    blocks.insert(block);
                }
                a /= 2;
            }
            assert_eq!(
                blocks.len() as u32,
                (h - t).div_ceil(s),
                "H {h} T {t} s {s}"
            );
        }
    }
    // Block bytes: the nodes' words rounded up to whole bursts.
    assert_eq!(BlockLayout::new(21, 9, 4, 4, 16).block_bytes(), 64);
    assert_eq!(BlockLayout::new(21, 9, 3, 4, 64).block_bytes(), 64);
    assert_eq!(BlockLayout::new(21, 9, 5, 4, 64).block_bytes(), 128);
}

/// A naive cache: per set a list of (block, stamp); LRU stamps every use, FIFO
/// only the fill; a full set evicts the smallest stamp.
struct Naive {
    sets: Vec<Vec<(u32, u64)>>,
    ways: usize,
    lru: bool,
    clock: u64,
}

impl Naive {
    fn access(&mut self, b: u32) -> bool {
        self.clock += 1;
        let n = self.sets.len();
        let set = &mut self.sets[b as usize % n];
        if let Some(e) = set.iter_mut().find(|e| e.0 == b) {
            if self.lru {
                e.1 = self.clock;
            }
            return true;
        }
        if set.len() == self.ways {
            let (i, _) = set.iter().enumerate().min_by_key(|(_, e)| e.1).unwrap();
            set.remove(i);
        }
        set.push((b, self.clock));
        false
    }
}

#[test]
fn the_cache_hits_and_misses_as_a_naive_reference() {
    let mut r = Pcg64Mcg::seed_from_u64(7);
    for lines in [8usize, 64, 256] {
        for ways in [Some(1), Some(2), Some(4), Some(8), None] {
            for policy in Policy::ALL {
                let cfg = CacheConfig {
                    lines,
                    ways,
                    policy,
                };
                let blocks = 4 * lines;
                let mut cache = Cache::new(cfg, blocks);
                let w = ways.unwrap_or(lines);
                let mut naive = Naive {
                    sets: vec![vec![]; lines / w],
                    ways: w,
                    lru: policy == Policy::Lru,
                    clock: 0,
                };
                // Mostly near the last block (reuse), sometimes anywhere.
                let mut last = 0u32;
                let mut hits = 0;
                for _ in 0..20_000 {
                    let b = if r.gen_bool(0.7) {
                        (last as i64 + r.gen_range(-6i64..=6)).rem_euclid(blocks as i64) as u32
                    } else {
                        r.gen_range(0..blocks as u32)
                    };
                    last = b;
                    let hit = cache.access(b);
                    assert_eq!(hit, naive.access(b), "{cfg:?} at block {b}");
                    hits += hit as u32;
                }
                assert!(hits > 1_000 && hits < 19_000, "{cfg:?}: {hits}");
            }
        }
    }
}

fn random_tree(n: usize, seed: u64) -> PackedTree {
    let mut r = Pcg64Mcg::seed_from_u64(seed);
    let pts: Vec<[u32; 3]> = (0..n)
        .map(|_| [0, 1, 2].map(|_| r.gen_range(0..1024)))
        .collect();
    PackedTree::from_tree(&KdTree::build(&pts), PhotonLayout::new([10, 10, 10]))
}

fn streams(tree: &PackedTree, n: usize, k: usize, seed: u64) -> Vec<Vec<u32>> {
    let mut r = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let q = [0, 1, 2].map(|_| r.gen_range(0..1024));
            read_stream(tree, q, k, Metric::L2, Traversal::Cell)
        })
        .collect()
}

fn machine(lay: BlockLayout, cache: CacheConfig, sharing: Sharing, d: usize, s: usize) -> Machine {
    Machine {
        datapaths: d,
        slots: s,
        loop_cycles: 14,
        layout: lay,
        cache,
        sharing,
        memory: MemoryTiming {
            latency: 22,
            bytes_per_cycle: 6.4,
        },
    }
}

#[test]
fn every_read_is_counted_once_and_a_whole_map_cache_misses_once_a_block() {
    let tree = random_tree(30_000, 3);
    let reads = streams(&tree, 400, 16, 4);
    let total: u64 = reads.iter().map(|r| r.len() as u64).sum();
    let order: Vec<usize> = (0..reads.len()).collect();
    let h = tree.address_bits();
    for (t, s) in [(6, 3), (9, 4), (0, 5)] {
        let lay = BlockLayout::new(h, t, s, 4, 16);
        let on_chip = reads.iter().flatten().filter(|&&a| a < 1 << t).count() as u64;
        let touched: HashSet<u32> = reads
            .iter()
            .flatten()
            .filter_map(|&a| match lay.place(a) {
                Place::External { block, .. } => Some(block),
                Place::OnChip => None,
            })
            .collect();
        for (lines, ways) in [(64, Some(2)), (512, Some(8)), (1 << 16, None)] {
            for sharing in Sharing::ALL {
                let cache = CacheConfig {
                    lines,
                    ways,
                    policy: Policy::Lru,
                };
                let rep = Replay {
                    datapaths: 4,
                    slots: 16,
                    layout: lay,
                    cache,
                    sharing,
                };
                let c = replay(&rep, &reads, &order);
                assert_eq!((c.reads, c.on_chip, c.queries), (total, on_chip, 400));
                assert_eq!(c.hits + c.misses, total - on_chip);
                let m = run(&machine(lay, cache, sharing, 4, 16), &reads, &order);
                assert_eq!((m.reads, m.on_chip, m.queries), (total, on_chip, 400));
                assert_eq!(m.hits + m.misses + m.merged, total - on_chip);
                if ways.is_none() && sharing == Sharing::Shared {
                    // As large as the map: only the compulsory misses.
                    assert!(lines as u32 >= lay.blocks());
                    assert_eq!(c.misses, touched.len() as u64);
                    assert_eq!(m.misses, touched.len() as u64);
                }
                // Every miss is one burst on the bus.
                let transfer = f64::from(lay.block_bytes()) / 6.4;
                assert!((m.bus_cycles - m.misses as f64 * transfer).abs() < 1e-6);
                assert!(m.bus_cycles <= m.cycles as f64 + transfer);
            }
        }
    }
}

#[test]
fn the_cycle_model_meets_its_closed_forms() {
    // One query alone, each read in a new band's block: a read waits for its
    // burst's transfer (16 B at 8 B/cycle: 2 cycles), the latency and the loop.
    let lay = BlockLayout::new(12, 2, 2, 4, 16);
    let path: Vec<u32> = (2..12).step_by(2).map(|l| 1u32 << l).collect();
    let blocks: HashSet<u32> = path
        .iter()
        .map(|&a| match lay.place(a) {
            Place::External { block, .. } => block,
            Place::OnChip => panic!("{a} on chip"),
        })
        .collect();
    assert_eq!(blocks.len(), path.len());
    let cache = CacheConfig {
        lines: 64,
        ways: Some(4),
        policy: Policy::Lru,
    };
    let mut m = machine(lay, cache, Sharing::Shared, 1, 16);
    m.memory = MemoryTiming {
        latency: 30,
        bytes_per_cycle: 8.0,
    };
    let r = run(&m, std::slice::from_ref(&path), &[0]);
    assert_eq!(r.cycles, path.len() as u64 * (2 + 30 + 14));
    assert_eq!((r.misses, r.hits), (path.len() as u64, 0));
    // The same query in two slots at once: the second waits on the first's
    // bursts in flight and fetches nothing itself.
    let r = run(&m, &[path.clone(), path.clone()], &[0, 1]);
    assert_eq!(
        (r.misses, r.merged, r.hits),
        (path.len() as u64, path.len() as u64, 0)
    );
    // Everything on chip: the banking model's slot loop alone.
    let all_on_chip = BlockLayout::new(12, 12, 3, 4, 16);
    let m = machine(all_on_chip, cache, Sharing::Shared, 1, 16);
    let r = run(&m, std::slice::from_ref(&path), &[0]);
    assert_eq!(
        (r.cycles, r.on_chip),
        (path.len() as u64 * 14, path.len() as u64)
    );
    // Many slots, a slow memory: the bus is the bound (every miss a burst).
    let tree = random_tree(20_000, 5);
    let reads = streams(&tree, 300, 8, 6);
    let order: Vec<usize> = (0..reads.len()).collect();
    let lay = BlockLayout::new(tree.address_bits(), 4, 3, 4, 16);
    let tiny = CacheConfig {
        lines: 4,
        ways: Some(1),
        policy: Policy::Fifo,
    };
    let mut m = machine(lay, tiny, Sharing::Shared, 4, 64);
    m.memory.bytes_per_cycle = 1.0;
    let r = run(&m, &reads, &order);
    assert!(r.cycles as f64 >= r.misses as f64 * 32.0);
    assert!(r.bus_utilisation() > 0.9, "{}", r.bus_utilisation());
    // More slots never slow a latency-bound datapath.
    let big = CacheConfig {
        lines: 256,
        ways: Some(4),
        policy: Policy::Lru,
    };
    let per: HashMap<usize, u64> = [8, 16, 32]
        .into_iter()
        .map(|s| {
            (
                s,
                run(&machine(lay, big, Sharing::Shared, 2, s), &reads, &order).cycles,
            )
        })
        .collect();
    assert!(per[&32] < per[&8], "{per:?}");
}

#[test]
fn the_memory_command_writes_its_report_and_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("MEMORY.md");
    let run = |extra: &[&str]| {
        assert_cmd::Command::cargo_bin("photon-fpga-lab")
            .unwrap()
            .arg("memory")
            .args(extra)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap()
    };
    let ok = run(&["--quick"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    for part in [
        "Regenerate: `photon-fpga-lab memory --quick",
        "**modelled**",
        "## Query order",
        "## Block levels",
        "## Sharing",
        "## Throughput: the cycle model",
        "## The choice, and why",
        "ECP5-85k",
        "XC6VSX475T",
    ] {
        assert!(text.contains(part), "{part} missing from\n{text}");
    }
    std::fs::remove_file(&out).unwrap();
    for (bad, message) in [
        (vec!["--k", "0"], "--k: each must be in 1..=512"),
        (vec!["--k", "32,5000"], "--k: each must be in 1..=512"),
        (vec!["--photons", "0"], "--photons must be in"),
        (
            vec!["--spp", "20000"],
            "the read streams are held in memory",
        ),
    ] {
        let o = run(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(message), "{bad:?}: {err}");
        assert!(!out.exists());
    }
}

/// A point of the external-memory core's sweep with round counts: 1,000 queries,
/// 100,000 reads (50,000 below the on-chip levels) in 40,000 cycles, 1,000 line
/// fills of 16 beats of 4 bytes, 17 result beats a query, at half the port's
/// bandwidth.
fn core_point() -> photon_fpga_lab::memory::core_sweep::CorePoint {
    photon_fpga_lab::memory::core_sweep::CorePoint {
        emitted: 1_000,
        photons: 1_950,
        k: 32,
        order: photon_fpga_lab::banking::order::StreamOrder::Morton,
        beat_bytes: 4,
        beat_interval: 2,
        cache_lines: 1_024,
        queries: 1_000,
        reads: 100_000,
        cached_reads: 50_000,
        cycles: 40_000,
        fills: 1_000,
        beats: 16_000,
        result_beats: 17_000,
        kiddo: 50_000.0,
        kiddo_all: 90_000.0,
        threads: 2,
    }
}

#[test]
fn the_memory_core_sweep_derives_its_figures_from_the_counts() {
    use photon_fpga_lab::memory::core_report::{csv, parse_csv, table};
    let p = core_point();
    assert_eq!(p.bytes_per_cycle(), 2.0);
    assert_eq!(p.reads_per_cycle(), 2.5);
    assert_eq!(p.reads_per_query(), 100.0);
    assert_eq!(p.hit_rate(), 0.98);
    assert_eq!(p.dram_bytes_per_query(), 64.0);
    // 16,000 beats of the 20,000 a beat every other cycle allows.
    assert_eq!(p.channel_busy(), 0.8);
    // 1,000 queries in 40,000 cycles at 80 MHz.
    assert_eq!(p.queries_per_s(80.0), 2_000_000.0);
    assert_eq!(p.link_bytes_per_query(), 16.0 + 17.0 * 32.0);
    let t = table(std::slice::from_ref(&p), 80.0, "cmd");
    let row = t.lines().last().unwrap();
    for cell in [
        "| 1 K | 1.95 K | 32 | 1000 | Morton | 2 | 1024 | 100.0 | 98.00 % | 1.00 | 64 | 80.0 % | 2.500 |",
        "| 2 M | 50 K | 40.0x | 90 K (2) | 22.2x | 1120 |",
    ] {
        assert!(row.contains(cell), "{cell} in {row}");
    }
    let c = csv(std::slice::from_ref(&p));
    assert_eq!(
        c.lines().nth(1),
        Some("1000,1950,32,Morton,2,1024,1000,100000,50000,40000,1000,16000,17000,50000,90000,2,4")
    );
    // The CSV renders the table and plots again: it holds every count; one
    // without the beat's bytes is of 4-byte beats.
    assert_eq!(parse_csv(&c), Some(vec![p.clone()]));
    let old = c.replace(",2,4\n", ",2\n").replace(",beat_bytes", "");
    assert_eq!(parse_csv(&old), Some(vec![p.clone()]));
    // 8-byte beats at the DRAM's sustained 6.4 bytes a cycle: a beat a cycle.
    let wide = photon_fpga_lab::memory::core_sweep::CorePoint {
        beat_bytes: 8,
        beat_interval: 1,
        ..p.clone()
    };
    assert_eq!(wide.bytes_per_cycle(), 6.4);
    assert_eq!(wide.dram_bytes_per_query(), 128.0);
    assert_eq!(
        parse_csv(&csv(std::slice::from_ref(&wide))),
        Some(vec![wide])
    );
    assert_eq!(parse_csv("header\n1,2,3\n"), None);
    assert!(t.contains("| cache lines |"), "{t}");
}

/// The sweep measures both k against the memory's bandwidth (at the paper's map,
/// in the coherent order) as well as against the map's size.
#[test]
fn the_memory_core_sweep_covers_bandwidth_at_both_k() {
    use photon_fpga_lab::banking::order::StreamOrder;
    use photon_fpga_lab::memory::core_sweep::specs;
    let v = specs(&[1_000, 2_000], &[2_000], 2_000, (64, 32), None);
    for (k, side) in [(32, 64), (500, 32)] {
        let mut intervals: Vec<u64> = v
            .iter()
            .filter(|p| p.k == k && p.emitted == 2_000 && p.order == StreamOrder::Morton)
            .map(|p| {
                assert_eq!(p.side, side);
                p.beat_interval
            })
            .collect();
        intervals.sort();
        assert_eq!(intervals, [1, 2, 4], "k = {k}");
    }
    // Each size at its k, both orders, the full bandwidth.
    assert_eq!(v.iter().filter(|p| p.beat_interval == 1).count(), 2 * 3);
}
