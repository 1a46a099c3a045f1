//! The banked store's software model (`host::banking`): the recorded read streams
//! are real searches, the query orders are permutations (Hilbert's a path of unit
//! steps), the bank mappings are bijections onto (bank, row), the cycle model obeys
//! its bounds and closed forms, and the device plans fit and are the largest.

use photon_fpga::host::device::plan::{
    largest_map, plan, BankPlan, Limits, PlanError, ECP5_85K, XC6VSX475T,
};
use photon_fpga::host::map::kdtree::{KdTree, PackedTree};
use photon_fpga::host::map::knn::search_with;
use photon_fpga::hw::config::bank_config::BankPorts;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga_lab::banking::mapping::{level, BankMap, Mapping};
use photon_fpga_lab::banking::order::{hilbert, morton, QueryOrder};
use photon_fpga_lab::banking::sim::{run, Issue, Machine};
use photon_fpga_lab::banking::stream::{read_stream, ImageQuery};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::collections::HashSet;

fn random_tree(n: usize, seed: u64) -> PackedTree {
    let layout = PhotonLayout::new([10, 10, 10]);
    let mut r = Pcg64Mcg::seed_from_u64(seed);
    let pts: Vec<[u32; 3]> = (0..n)
        .map(|_| [0, 1, 2].map(|_| r.gen_range(0..1024)))
        .collect();
    PackedTree::from_tree(&KdTree::build(&pts), layout)
}

#[test]
fn a_read_stream_is_the_searchs_reads_each_a_child_of_an_earlier_one() {
    let tree = random_tree(5_000, 1);
    let mut r = Pcg64Mcg::seed_from_u64(2);
    for _ in 0..200 {
        let q = [0, 1, 2].map(|_| r.gen_range(0..1024));
        for t in [Traversal::Cell, Traversal::Remember] {
            let reads = read_stream(&tree, q, 32, Metric::L2, t);
            let max = Metric::L2.max_dist([10, 10, 10]);
            let f = search_with(&tree, q, 32, max, Metric::L2, t);
            assert_eq!(reads.len(), f.visited as usize);
            assert_eq!(reads[0], 1);
            let mut seen = HashSet::new();
            for &a in &reads {
                assert!(a >= 1 && a as usize <= tree.len());
                // Without re-reads every photon is read once, after its parent.
                assert!(a == 1 || seen.contains(&(a / 2)), "{a} before its parent");
                assert!(seen.insert(a), "{a} read twice");
            }
        }
    }
}

#[test]
fn orders_are_permutations_and_hilbert_steps_to_a_neighbour() {
    let bits = 3;
    let side = 1u32 << bits;
    let cube: Vec<[u32; 3]> = (0..side * side * side)
        .map(|i| [i % side, (i / side) % side, i / (side * side)])
        .collect();
    let mut by_key: Vec<(u64, [u32; 3])> = cube.iter().map(|&c| (hilbert(c, bits), c)).collect();
    by_key.sort();
    for (i, w) in by_key.windows(2).enumerate() {
        assert_eq!(w[0].0, i as u64, "Hilbert keys are 0..n");
        let step: u32 = (0..3).map(|a| w[0].1[a].abs_diff(w[1].1[a])).sum();
        assert_eq!(step, 1, "{:?} -> {:?}", w[0].1, w[1].1);
    }
    let morton_keys: HashSet<u64> = cube.iter().map(|&c| morton(c, bits)).collect();
    assert_eq!(morton_keys.len(), cube.len());
    assert_eq!(morton([1, 0, 0], 1), 0b100);
    let mut r = Pcg64Mcg::seed_from_u64(3);
    let qs: Vec<ImageQuery> = (0..500)
        .map(|i| ImageQuery {
            coords: [0, 1, 2].map(|_| r.gen_range(0..1024)),
            pixel: i / 2,
        })
        .collect();
    for o in QueryOrder::ALL {
        let mut p = o.permutation(&qs, 16, 10);
        p.sort();
        assert_eq!(p, (0..qs.len()).collect::<Vec<_>>(), "{o:?}");
    }
}

#[test]
fn mappings_are_bijections_onto_bank_and_row() {
    let n = 100_000u32;
    for (b, l) in [(3, 3), (5, 7), (7, 10)] {
        for m in Mapping::ALL {
            let map = BankMap {
                mapping: m,
                bank_bits: b,
                replicated: l,
            };
            let mut cells = HashSet::new();
            for a in 1..=n {
                match map.bank(a) {
                    None => assert!(a < 1 << l),
                    Some(bank) => {
                        assert!(a >= 1 << l && bank < 1 << b);
                        if m != Mapping::Subtree {
                            assert!(cells.insert((bank, a >> b)), "{m:?}: {a} shares a cell");
                        } else if level(a) >= l + b {
                            // The whole subtree under level L + b is in one bank.
                            let root = a >> (level(a) - (l + b));
                            assert_eq!(Some(bank), map.bank(root));
                        }
                    }
                }
            }
            let occ = map.occupancy(n as usize);
            assert_eq!(occ.iter().sum::<u64>(), (n - ((1 << l) - 1)) as u64);
        }
    }
}

fn machine(d: usize, b: u32, l: u32, issue: Issue) -> Machine {
    Machine {
        datapaths: d,
        slots: 16,
        loop_cycles: 13,
        bank_ports: 1,
        map: BankMap {
            mapping: Mapping::XorFold,
            bank_bits: b,
            replicated: l,
        },
        issue,
    }
}

#[test]
fn the_cycle_model_meets_its_closed_forms_and_bounds() {
    // One query alone: each read waits for the one before, a whole slot loop.
    let one = vec![(1..=40).collect::<Vec<u32>>()];
    let m = run(&machine(1, 0, 32, Issue::Rotate), &one, &[0]);
    assert_eq!((m.cycles, m.reads, m.bank_reads), (40 * 13, 40, 0));
    // Real streams through a few machines.
    let tree = random_tree(20_000, 4);
    let mut r = Pcg64Mcg::seed_from_u64(5);
    let reads: Vec<Vec<u32>> = (0..600)
        .map(|_| {
            let q = [0, 1, 2].map(|_| r.gen_range(0..1024));
            read_stream(&tree, q, 16, Metric::L2, Traversal::Cell)
        })
        .collect();
    let total: u64 = reads.iter().map(|r| r.len() as u64).sum();
    let longest = reads.iter().map(Vec::len).max().unwrap() as u64;
    let order: Vec<usize> = (0..reads.len()).collect();
    for (d, b, l, issue) in [
        (1, 0, 0, Issue::InOrder),
        (4, 0, 0, Issue::Rotate),
        (4, 3, 4, Issue::InOrder),
        (8, 5, 6, Issue::Rotate),
        (8, 6, 32, Issue::Rotate),
    ] {
        let mc = machine(d, b, l, issue);
        let m = run(&mc, &reads, &order);
        assert_eq!(m.reads, total, "every read exactly once");
        assert_eq!(m.per_datapath.iter().sum::<u64>(), total);
        assert_eq!(m.per_bank.iter().sum::<u64>(), m.bank_reads);
        let replicated: u64 = reads
            .iter()
            .flatten()
            .filter(|&&a| a < 1u32.checked_shl(l).unwrap_or(u32::MAX))
            .count() as u64;
        assert_eq!(m.bank_reads, total - replicated);
        assert_eq!(m.refused, m.offered - m.bank_reads);
        // A bank serves one read per cycle, a datapath issues one.
        assert!(m.per_bank.iter().all(|&x| x <= m.cycles));
        assert!(m.per_datapath.iter().all(|&x| x <= m.cycles));
        assert!(m.cycles >= longest * 13);
        if l == 32 {
            assert_eq!(m.offered, 0);
        }
    }
    // One bank and no replica: the whole core reads at most one photon a cycle
    // per bank port, and with many datapaths it is kept busy.
    let m = run(&machine(8, 0, 0, Issue::Rotate), &reads, &order);
    assert!(m.cycles >= total && (m.cycles as f64) < total as f64 * 1.05);
    let two = Machine {
        bank_ports: 2,
        ..machine(8, 0, 0, Issue::Rotate)
    };
    let m = run(&two, &reads, &order);
    assert_eq!(m.reads, total);
    assert!(2 * m.cycles >= total && (2 * m.cycles) as f64 <= total as f64 * 1.1);
}

/// A plan's (L, B, BlockRAMs a bank, D, bank ports).
fn shape(p: &BankPlan) -> (u32, u32, u32, u32, BankPorts) {
    (
        p.replicated_levels,
        p.banks(),
        p.brams_per_bank,
        p.datapaths,
        p.ports,
    )
}

#[test]
fn the_plans_fit_their_devices_and_name_the_largest_map() {
    let lim = Limits::default();
    // XC6VSX475T, the default render's 388,826 photons of 32 bits: 1K × 36 RAMB36,
    // L = 10 (1,023 nodes in one RAMB36). B = 128: rows of 388,826 >> 7 = 3,037 + 1
    // words = 3 RAMB36 a bank, 384 in all (D <= 32); B = 64: 6 a bank, 384 too,
    // but D <= 16. Logic budget 60 % of 297,600 = 178,560 LUTs (the costs of
    // synth/device_costs.toml): at B = 128 a datapath costs 5,162 with split ports
    // plus 29.242 × 128 = 3,743 of crossbar, so at most 20 (an even number);
    // shared ports 5,162 + 9,563, only 12. B = 256 (1,519 rows = 2 RAMB36, 512):
    // split 12,648 a datapath, 14. Datapaths' BlockRAM: 20 × (1 replica + 4) = 100.
    let p = plan(388_826, 32, XC6VSX475T.datapath_brams, &XC6VSX475T, &lim).unwrap();
    assert_eq!(shape(&p), (10, 128, 3, 20, BankPorts::Split));
    assert_eq!((p.bank_brams, p.datapath_brams), (384, 100));
    assert_eq!((p.datapath_luts, p.crossbar_luts), (103_240, 74_860));
    for dev in [&ECP5_85K, &XC6VSX475T] {
        let big = largest_map(dev.datapath_brams, dev, &lim);
        assert!(big > 1_000, "{}", dev.name);
        for n in [1_000, big / 3, big / 2 + 17, big] {
            let p = plan(n, 32, dev.datapath_brams, dev, &lim).unwrap();
            assert!(p.total_brams() <= dev.brams);
            assert!(p.datapaths >= lim.min_datapaths && p.datapaths <= lim.max_datapaths);
            assert_eq!(p.datapaths % 2, 0, "two datapaths a replica");
            let logic = (p.datapath_luts + p.crossbar_luts) as f64;
            assert!(logic <= dev.luts as f64 * lim.logic_share, "{p:?}");

            assert!((1u32 << p.replicated_levels) - 1 <= dev.shape.0);
            if n >= 1 << p.replicated_levels {
                // Every address's row is in its bank; the banks' BlockRAMs hold them.
                assert_eq!(p.bank_rows as usize, (n >> p.bank_bits) + 1);
                assert!(p.brams_per_bank * dev.shape.0 >= p.bank_rows);
                assert!(p.banks() >= lim.banks_per_datapath * p.datapaths);
                assert!(p.banks() <= 1 << p.replicated_levels);
                assert_eq!(
                    p.crossbar_luts,
                    dev.crossbar_luts(p.datapaths, p.banks(), p.ports)
                );
            }
        }
        match plan(big + 1, 32, dev.datapath_brams, dev, &lim) {
            Err(e @ PlanError::MapTooLarge { largest, .. }) => {
                assert_eq!(largest, big);
                assert!(e.to_string().contains(&big.to_string()));
            }
            other => panic!("{}: {other:?}", dev.name),
        }
    }
    // ECP5-85k, the 64,894-photon Cornell map of synth/REPORT.md's banked rows:
    // 512 × 36 DP16KD, L = 9. Budget 60 % of 83,640 = 50,184 LUT4s; a datapath
    // 9,386, so D = 6 (56,316) is over it, and D = 4 (37,544) it is. The crossbar
    // per requester and bank: split 64.234, shared 148.195. B = 16 (8 DP16KD a
    // bank): split 4,111 or shared 9,485; B = 32 (2,028 rows, 4 a bank): split
    // 8,222 fits, shared 18,969 does not; B = 64: split 16,444 does not. The same
    // 128 DP16KD for B = 16 and 32: the more banks, 32, with split ports.
    // Datapaths' DP16KD: 4 × (1 replica + 8) = 36.
    let p = plan(64_894, 32, ECP5_85K.datapath_brams, &ECP5_85K, &lim).unwrap();
    assert_eq!(shape(&p), (9, 32, 4, 4, BankPorts::Split));
    assert_eq!((p.bank_brams, p.datapath_brams), (128, 36));
    assert_eq!((p.datapath_luts, p.crossbar_luts), (37_544, 8_222));
    // The ECP5-85k's 3.7 Mbit cannot hold the default render's map.
    assert!(matches!(
        plan(388_826, 32, ECP5_85K.datapath_brams, &ECP5_85K, &lim),
        Err(PlanError::MapTooLarge { .. })
    ));
    assert!(largest_map(ECP5_85K.datapath_brams, &ECP5_85K, &lim) >= 64 * 1024);
    assert!(matches!(
        plan(1000, 40, ECP5_85K.datapath_brams, &ECP5_85K, &lim),
        Err(PlanError::WordTooWide { .. })
    ));
}

#[test]
fn the_banking_command_writes_its_report_and_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("BANKING.md");
    let run = |extra: &[&str]| {
        let mut args = vec!["banking", "--quick", "--size", "16x16"];
        args.extend_from_slice(extra);
        assert_cmd::Command::cargo_bin("photon-fpga-lab")
            .unwrap()
            .args(&args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap()
    };
    let ok = run(&["--spp", "1", "--photons", "3000"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    for part in [
        "Regenerate: `photon-fpga-lab banking",
        "Bank-conflict curve",
        "Chosen from",
    ] {
        assert!(text.contains(part), "{part} missing from\n{text}");
    }
    std::fs::remove_file(&out).unwrap();
    for (bad, message) in [
        (["--k", "0"], "--k must be in 1..=1024, got 0"),
        (["--k", "5000"], "--k must be in 1..=1024, got 5000"),
        (["--spp", "20000"], "at most 4194304 queries"),
        (["--spp", "0"], "--spp must be at least 1"),
        (["--photons", "0"], "--photons must be in"),
    ] {
        let o = run(&bad);
        assert_eq!(o.status.code(), Some(2));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(message), "{bad:?}: {err}");
        assert!(!out.exists());
    }
}
