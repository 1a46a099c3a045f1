//! QueryLimits against the rule of the software search: a radius beyond every
//! distance of the configuration is the largest distance (the same photons are
//! within it), a smaller one is kept, k is kept in count bits; for both metrics and
//! several layouts, at the edges and at random.

use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::datapath::query_limits::QueryLimits;
use photon_fpga::hw::primitives::stream::QueryBeat;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{rng, settle};

#[test]
fn radius_is_clamped_and_k_kept() {
    let mut r = rng(31);
    for (bits, metric, k) in [
        (10u32, Metric::L1, 10usize),
        (10, Metric::L2, 20),
        (6, Metric::L1, 3),
        (15, Metric::L2, 64),
    ] {
        let cfg = CoreConfig {
            layout: PhotonLayout::new([bits; 3]),
            metric,
            k,
            ..CoreConfig::paper()
        };
        let max = metric.max_dist(cfg.layout.bits);
        // The register holds distance bits: the largest value it can hold.
        let top = (1u64 << cfg.dist_bits()) - 1;
        assert!(top >= max);
        let mut uut = QueryLimits::new(&cfg);
        uut.connect_all();
        check_all(&uut).unwrap();
        let mut radii = vec![
            0u64,
            1,
            max,
            top,
            (top + 1).min(u32::MAX as u64),
            u32::MAX as u64,
        ];
        radii.extend((0..500).map(|_| r.gen_range(0..=u32::MAX as u64)));
        radii.extend((0..500).map(|_| r.gen_range(0..=top)));
        for radius in radii {
            let kq = r.gen_range(1..=k as u64);
            uut.query.next = QueryBeat {
                id: 7u64.into(),
                x: 1u64.into(),
                y: 2u64.into(),
                z: 3u64.into(),
                radius: radius.into(),
                k: kq.into(),
            };
            settle(&mut uut);
            assert_eq!(
                uut.radius.val().to_u64(),
                radius.min(top),
                "radius {radius}"
            );
            assert_eq!(uut.k.val().to_u64(), kq);
        }
    }
}
