//! CoreConfig: the paper's core, what `for_map` derives from a map, and the limits.

use crate::common::*;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{CoreConfig, BARREL_SLOTS, MAX_K_MODULES, PORTS};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;

#[test]
fn paper_core() {
    let cfg = CoreConfig::paper();
    assert_eq!(cfg.layout.bits, [10, 10, 10]);
    assert_eq!(cfg.layout.word_bits(), 32, "paper: 32-bit photon word");
    assert_eq!(cfg.k, 10);
    assert_eq!(
        cfg.query_modules(),
        42,
        "paper: 21 QueryModules per port, 2 ports"
    );
    assert_eq!(PORTS, 2);
    // The paper's 12-bit distance: L1 of 10-bit coordinates, max 3 * 1023 = 3069.
    assert_eq!(cfg.metric, Metric::L1);
    assert_eq!(cfg.dist_bits(), 12);
    assert!(
        cfg.queries_per_port >= cfg.issue_interval(),
        "a port can read every cycle"
    );
    assert!(cfg.tree_words() > 1023, "holds the paper's 1023-photon map");
    cfg.validate().unwrap();
}

#[test]
fn for_map_models_only_what_the_scene_needs() {
    let layout = PhotonLayout::new([9, 4, 7]);
    let mut r = rng(71);
    for (n, h) in [
        (1usize, 1u32),
        (2, 2),
        (3, 2),
        (7, 3),
        (8, 4),
        (300, 9),
        (511, 9),
        (512, 10),
    ] {
        let tree = pack(&random_points(&mut r, n, layout), layout);
        for metric in [Metric::L2, Metric::L1] {
            let cfg = CoreConfig::for_map(tree.image(), 7, metric).unwrap();
            assert_eq!(cfg.address_bits, h, "{n} photons");
            assert!(n < cfg.tree_words());
            assert_eq!(cfg.layout, layout);
            assert_eq!(cfg.k, 7);
            assert_eq!(cfg.queries_per_port, cfg.issue_interval());
            let max = match metric {
                Metric::L2 => 511u64 * 511 + 15 * 15 + 127 * 127,
                Metric::L1 => 511 + 15 + 127,
            };
            assert_eq!(cfg.max_dist(), max);
            assert_eq!(cfg.dist_bits(), 64 - max.leading_zeros());
        }
    }
}

#[test]
fn limits_are_errors_not_panics() {
    let layout = PhotonLayout::new([10, 10, 10]);
    let tree = pack(&[[1, 2, 3]], layout);
    assert!(CoreConfig::for_map(tree.image(), 0, Metric::L2).is_err());
    assert!(CoreConfig::for_map(tree.image(), MAX_K_MODULES + 1, Metric::L2).is_err());
    assert!(CoreConfig::for_map(tree.image(), MAX_K_MODULES, Metric::L2).is_ok());
    // 3 x 11 bits + 2 need the 64-bit word; 16 bits on an axis exceed the datapath.
    let wide = pack(&[[1, 2, 3]], PhotonLayout::new([11, 10, 10]));
    let cfg = CoreConfig::for_map(wide.image(), 4, Metric::L1).unwrap();
    assert_eq!((cfg.layout.word_bits(), cfg.word_width()), (33, 64));
    let paper_word = CoreConfig::paper();
    assert_eq!(
        (paper_word.layout.word_bits(), paper_word.word_width()),
        (32, 32)
    );
    let too_wide = pack(&[[1, 2, 3]], PhotonLayout::new([16, 10, 10]));
    let err = CoreConfig::for_map(too_wide.image(), 4, Metric::L1).unwrap_err();
    assert!(err.to_string().contains("coordinate widths"), "{err}");
    cfg.validate().unwrap();
    let mut no_trees = cfg;
    no_trees.trees = 0;
    assert!(no_trees.validate().is_err());
    // 15 + 8 + 7 bits fit the word, and L2 still fits 32 distance bits.
    let skewed = pack(&[[1, 2, 3]], PhotonLayout::new([15, 8, 7]));
    assert!(CoreConfig::for_map(skewed.image(), 4, Metric::L2).is_ok());
    let mut cfg = CoreConfig::paper();
    cfg.address_bits = 21;
    assert!(cfg.validate().is_err());
    cfg = CoreConfig::paper();
    cfg.queries_per_port = 33;
    assert!(cfg.validate().is_err());
    // A map larger than the core.
    let big = pack(&vec![[1, 2, 3]; 1024], layout);
    assert!(CoreConfig::paper().check_map(big.image()).is_err());
}

/// The builder refuses every combination the datapath cannot build when it is
/// built, naming the option and its value; Q is named after the controller.
#[test]
fn the_builder_refuses_bad_combinations_by_name() {
    let err = |b: photon_fpga::hw::config::config_builder::CoreBuilder| {
        b.build().unwrap_err().to_string()
    };
    let barrel = CoreConfig::builder().controller(Controller::Barrel);
    let e = err(barrel.traversal(Traversal::Reread));
    assert!(
        e.contains("traversal = reread") && e.contains("barrel"),
        "{e}"
    );
    // Q is one option whichever the controller, named with what it counts.
    let e = err(barrel.queries_per_port(33));
    assert!(
        e.contains("queries_per_port = 33") && e.contains("query slots"),
        "{e}"
    );
    let e = err(CoreConfig::builder().queries_per_port(0));
    assert!(
        e.contains("queries_per_port = 0") && e.contains("QueryModules"),
        "{e}"
    );
    // The order of the options does not matter: Q given before the controller.
    let q_first = CoreConfig::builder()
        .queries_per_port(8)
        .controller(Controller::Barrel);
    assert_eq!(q_first.build().unwrap().queries_per_port, 8);
    let k = MAX_K_MODULES + 1;
    assert!(err(CoreConfig::builder().k(k)).contains(&format!("K = {k}")));
    assert!(err(CoreConfig::builder().trees(9)).contains("trees = 9"));
    assert!(err(CoreConfig::builder().address_bits(21)).contains("address_bits (H) = 21"));
    let e = err(CoreConfig::builder().layout(PhotonLayout::new([16, 4, 4])));
    assert!(e.contains("[16, 4, 4]"), "{e}");
    // Q left unset: the controller's default; given: exactly that.
    let b = barrel.build().unwrap();
    assert_eq!(b.queries_per_port, BARREL_SLOTS);
    assert_eq!(
        barrel.queries_per_port(5).build().unwrap().queries_per_port,
        5
    );
    let m = CoreConfig::builder().build().unwrap();
    assert_eq!(m.queries_per_port, m.issue_interval());
    // A configuration round-trips through its builder, also with the barrel port.
    for cfg in [CoreConfig::paper(), b, barrel.trees(3).build().unwrap()] {
        assert_eq!(cfg.to_builder().build().unwrap(), cfg);
    }
}
