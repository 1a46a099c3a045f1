//! The simulated core on Cornell-box photon maps made by the host (photon tracing,
//! quantization, packing, eye-ray queries), with random stalls on every stream:
//! every result equals the software search (same found set, same photon reads) and
//! brute force (sorted distances), for both metrics and a bounded radius.

use photon_fpga::host::gather::{GatherParams, QuantizedMap};
use photon_fpga::host::map::knn::{brute_force, search_with};
use photon_fpga::host::render::photons::trace_photons;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, eye_queries, RenderSettings};
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{run_gather, SimOptions};

#[test]
fn cornell_box_maps_match_the_software_search() {
    let scene = Scene::cornell_box();
    let photons = render::photon_points(&trace_photons(&scene, 600, 5, false));
    let settings = RenderSettings {
        width: 8,
        height: 6,
        spp: 1,
        ..RenderSettings::default()
    };
    let (queries, _) = eye_queries(&scene, &settings);
    let queries = render::query_points(&queries);
    for (metric, k, radius) in [(Metric::L2, 8, None), (Metric::L1, 5, Some(0.2))] {
        let params = GatherParams {
            k,
            radius,
            metric,
            ..GatherParams::default()
        };
        let map = QuantizedMap::new(&photons, &params).unwrap();
        let cfg = CoreConfig::for_map(map.tree.image(), k, metric).unwrap();
        let hw: Vec<HwQuery> = queries
            .iter()
            .enumerate()
            .map(|(i, &q)| HwQuery {
                id: i as u32,
                coords: map.quant.quantize(q),
                radius: map.radius_bound,
                k: k as u32,
            })
            .collect();
        let opts = SimOptions {
            stall_seed: Some(17),
            ..SimOptions::default()
        };
        let (results, _) = run_gather(&cfg, map.tree.image(), &hw, &opts).unwrap();
        let grid: Vec<[u32; 3]> = photons.iter().map(|&p| map.quant.quantize(p)).collect();
        assert_eq!(results.len(), hw.len());
        for (q, r) in hw.iter().zip(&results) {
            assert_eq!(r.id, q.id);
            let sw = search_with(&map.tree, q.coords, k, q.radius, metric, cfg.traversal);
            let mut got = r.found.clone();
            let mut want = sw.slots.clone();
            got.sort();
            want.sort();
            assert_eq!(got, want, "query {}: found set differs", q.id);
            assert_eq!(r.visited, sw.visited, "query {}: photon reads differ", q.id);
            let truth: Vec<u64> = brute_force(&grid, q.coords, k, q.radius, metric)
                .iter()
                .map(|t| t.1)
                .collect();
            assert_eq!(sw.sorted_dists(), truth);
        }
    }
}
