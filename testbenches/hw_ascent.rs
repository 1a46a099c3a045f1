//! Ascent (the barrel datapath's pruning bounds and one-step ascent) against a
//! model that climbs level by level as the software search does: from the node's
//! level up, the first pending level whose bound is within R (`<` full, `≤` not).
//! Full-width distances and 12-bit ones (compared on their low 16 bits), random
//! bounds written per slot and level, ties at R on purpose.

use crate::common::{clock_cycle, rng, settle};
use photon_fpga::hw::barrel::ascent::Ascent;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use rand::Rng;
use rust_hdl::prelude::*;

#[test]
fn ascent_climbs_to_the_deepest_pending_level_within_r() {
    for radius_bits in [None, Some(12)] {
        let cfg = CoreConfig::builder()
            .layout(PhotonLayout::new([10, 10, 10]))
            .address_bits(12)
            .k(8)
            .metric(Metric::L2)
            .controller(Controller::Barrel)
            .traversal(Traversal::Cell)
            .queries_per_port(6)
            .radius_bits(radius_bits)
            .build()
            .unwrap();
        let (slots, levels) = (cfg.queries_per_port, cfg.path_levels());
        let top = cfg.dist_mask();
        let mut uut = Ascent::new(&cfg);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mut r = rng(61 + radius_bits.unwrap_or(0) as u64);
        // Bounds from a small set around R so that ties and both sides occur.
        let pick = |r: &mut rand_pcg::Pcg64| match r.gen_range(0..4) {
            0 => top,
            1 => r.gen_range(0..=top),
            _ => r.gen_range(900..1100u64),
        };
        let mut bound = vec![vec![0u64; levels]; slots];
        uut.write_enable.next = true;
        for (s, row) in bound.iter_mut().enumerate() {
            for (l, b) in row.iter_mut().enumerate() {
                *b = pick(&mut r);
                uut.write_slot.next = (s as u64).into();
                uut.write_level.next = (l as u64).into();
                uut.write_bound.next = (*b).into();
                clock_cycle(&mut uut, |u| &mut u.clock);
            }
        }
        let (mut found, mut none) = (0, 0);
        for _ in 0..3000 {
            // Rewrite one entry now and then (the next read sees it).
            let (s, l) = (r.gen_range(0..slots), r.gen_range(0..levels));
            let w = r.gen_bool(0.2);
            uut.write_enable.next = w;
            if w {
                bound[s][l] = pick(&mut r);
                uut.write_slot.next = (s as u64).into();
                uut.write_level.next = (l as u64).into();
                uut.write_bound.next = bound[s][l].into();
            }
            clock_cycle(&mut uut, |u| &mut u.clock);
            uut.write_enable.next = false;
            let slot = r.gen_range(0..slots);
            let level = r.gen_range(0..=levels);
            let pending: u64 = r.gen_range(0..1u64 << levels);
            let full = r.gen_bool(0.5);
            let radius = r.gen_range(900..1100u64).min(top - 1);
            uut.read_slot.next = (slot as u64).into();
            uut.level.next = (level as u64).into();
            uut.pending.next = pending.into();
            uut.full.next = full;
            uut.radius.next = radius.into();
            settle(&mut uut);
            // The software search's climb: up from the node, the first match.
            let want = (0..level.min(levels)).rev().find(|&l| {
                let b = bound[slot][l];
                pending >> l & 1 == 1 && if full { b < radius } else { b <= radius }
            });
            let got = uut.climb.val();
            assert_eq!(got.found, want.is_some(), "slot {slot} level {level}");
            if let Some(t) = want {
                assert_eq!(got.target.to_u64(), t as u64, "slot {slot} level {level}");
                found += 1;
            } else {
                none += 1;
            }
        }
        assert!(found > 300 && none > 300, "{found} climbs, {none} ends");
    }
}
