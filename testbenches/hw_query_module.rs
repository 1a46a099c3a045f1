//! QueryModule (paper §4.2) on its own, one query at a time, against the software
//! search `knn::search_with` read for read. The bench is the rest of a port: it
//! grants the module's read requests at random, answers each read after a random
//! delay with the result of a model SearchModule (the photon at the address read
//! from a small map in a model BlockRAM, the distance and traversal step computed in
//! software, as in the SearchModule's bench), and broadcasts unrelated results with
//! `result_valid` low in between. Each read the module issues must be the next read
//! of the software search on the same map (recorded through a `NodeSource` that logs
//! every photon it is asked for); at the end the module's read-out (count, reads,
//! the found list entry by entry) must be the software search's found list in slot
//! order. Also from the documentation: one read outstanding at a time, the read and
//! the read-out zero unless granted or selected, free again after `result_taken`.

use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::{self, NodeSource};
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::modules::query_module::QueryModule;
use photon_fpga::hw::primitives::stream::{QueryBeat, ReadRequest, ReadResult};
use rand::Rng;
use rand_pcg::Pcg64;
use rust_hdl::prelude::*;
use std::cell::RefCell;

use crate::common::settle;
use crate::hw_search_module::expect;

/// The map as the software search reads it, logging every photon read.
struct Logged<'a> {
    tree: &'a PackedTree,
    reads: RefCell<Vec<usize>>,
}

impl NodeSource<u32> for Logged<'_> {
    fn len(&self) -> usize {
        self.tree.len()
    }
    fn node(&self, addr: usize) -> ([u32; 3], u8) {
        self.reads.borrow_mut().push(addr);
        self.tree.node(addr)
    }
}

struct Bench<const S: usize> {
    uut: QueryModule<S>,
    index: usize,
    r: Pcg64,
}

impl<const S: usize> Bench<S> {
    fn tick(&mut self) {
        settle(&mut self.uut);
        self.uut.clock.next = true.into();
        settle(&mut self.uut);
        self.uut.clock.next = false.into();
        settle(&mut self.uut);
    }

    /// A result on the broadcast that is not this module's.
    fn other_result(&mut self) -> ReadResult {
        let r = &mut self.r;
        ReadResult {
            query_module: r.gen_range(0..32u64).into(),
            address: r.gen_range(0..1u64 << 24).into(),
            in_range: r.gen(),
            distance: r.gen_range(0..1u64 << 32).into(),
            next_address: r.gen_range(0..1u64 << 24).into(),
            next_up: r.gen(),
            next_came_from_right: r.gen(),
            done: r.gen(),
            axis_dist: r.gen_range(0..1u64 << 32).into(),
            far_pending: r.gen(),
            axis: r.gen_range(0..3u64).into(),
        }
    }

    /// Run one query to its end and check it read for read and its found list.
    /// Returns the reads.
    fn query(
        &mut self,
        cfg: &CoreConfig,
        tree: &PackedTree,
        q: [u32; 3],
        k: usize,
        radius: u64,
    ) -> usize {
        let what = format!(
            "{} {} K {} query {q:?} k {k} r {radius}",
            cfg.traversal, cfg.metric, cfg.k
        );
        let logged = Logged {
            tree,
            reads: RefCell::new(Vec::new()),
        };
        let sw = knn::search_with(&logged, q, k, radius, cfg.metric, cfg.traversal);
        let reads = logged.reads.into_inner();
        assert_eq!(reads.len(), sw.visited as usize);

        assert!(self.uut.free.val(), "{what}: not free before the load");
        self.uut.load.next = true;
        self.uut.load_query.next = QueryBeat {
            id: self.r.gen_range(0..1u64 << 32).into(),
            // Not the module's: the port keeps the coordinates.
            x: self.r.gen_range(0..1u64 << 16).into(),
            y: self.r.gen_range(0..1u64 << 16).into(),
            z: self.r.gen_range(0..1u64 << 16).into(),
            radius: radius.min(u32::MAX as u64).into(),
            k: (k as u64).into(),
        };
        self.tick();
        self.uut.load.next = false;
        settle(&mut self.uut);
        assert!(!self.uut.free.val(), "{what}: free after the load");

        let mut issued = 0usize;
        // The result owed: (cycles until it is delivered, the result).
        let mut owed: Option<(u32, ReadResult)> = None;
        let mut cycles = 0;
        while !self.uut.finished.val() {
            cycles += 1;
            assert!(
                cycles < 200 * (reads.len() + 2),
                "{what}: stuck after {issued} reads"
            );
            // Deliver a result that is due, else broadcast another module's.
            self.uut.result_valid.next = false;
            let other = self.other_result();
            self.uut.result.next = other;
            if let Some((0, res)) = owed {
                self.uut.result_valid.next = true;
                self.uut.result.next = res;
                owed = None;
            } else if let Some((t, res)) = owed {
                owed = Some((t - 1, res));
            }
            self.uut.read_grant.next = false;
            settle(&mut self.uut);
            let req = self.uut.read_request.val();
            assert!(
                !(req && (owed.is_some() || self.uut.result_valid.val())),
                "{what}: a second read requested while one is outstanding"
            );
            let grant = req && self.r.gen_bool(0.6);
            if grant {
                self.uut.read_grant.next = true;
                settle(&mut self.uut);
                let rd: ReadRequest = self.uut.read.val();
                assert_eq!(
                    rd.query_module.to_u64() as usize,
                    self.index,
                    "{what}: index"
                );
                assert!(
                    issued < reads.len(),
                    "{what}: read {issued} is one too many"
                );
                assert_eq!(
                    rd.address.to_u64() as usize,
                    reads[issued],
                    "{what}: read {issued} (software reads {reads:?})"
                );
                issued += 1;
                let e = expect(tree, cfg.metric, self.index, q, &rd);
                let res = ReadResult {
                    query_module: (self.index as u64).into(),
                    address: e.address.into(),
                    in_range: e.in_range,
                    distance: e.distance.into(),
                    next_address: e.next_address.into(),
                    next_up: e.next_up,
                    next_came_from_right: e.next_came_from_right,
                    done: e.done,
                    axis_dist: e.axis_dist.into(),
                    far_pending: e.far_pending,
                    axis: e.axis.into(),
                };
                // The SearchModule's pipeline (three or four cycles), or longer.
                owed = Some((self.r.gen_range(2..6), res));
            } else {
                assert_eq!(
                    self.uut.read.val(),
                    ReadRequest::default(),
                    "{what}: read not granted"
                );
            }
            self.tick();
            self.uut.read_grant.next = false;
        }
        assert_eq!(issued, reads.len(), "{what}: reads");
        assert!(owed.is_none());

        // The read-out: zero unless selected.
        settle(&mut self.uut);
        assert_eq!(self.uut.out_count.val().to_u64(), 0);
        assert_eq!(self.uut.out_visited.val().to_u64(), 0);
        self.uut.out_enable.next = true;
        settle(&mut self.uut);
        assert_eq!(
            self.uut.out_count.val().to_u64() as usize,
            sw.slots.len(),
            "{what}: count"
        );
        assert_eq!(
            self.uut.out_visited.val().to_u64(),
            sw.visited as u64,
            "{what}: reads"
        );
        let mut found = Vec::new();
        for e in 0..sw.slots.len() {
            self.uut.out_entry.next = (e as u64).into();
            self.uut.out_reading.next = false;
            settle(&mut self.uut);
            assert_eq!(self.uut.out_address.val().to_u64(), 0);
            assert_eq!(self.uut.out_dist.val().to_u64(), 0);
            self.uut.out_reading.next = true;
            settle(&mut self.uut);
            found.push((
                self.uut.out_address.val().to_u64() as u32,
                self.uut.out_dist.val().to_u64(),
            ));
        }
        assert_eq!(found, sw.slots, "{what}: found list");
        self.uut.out_reading.next = false;
        self.uut.out_enable.next = false;
        self.uut.result_taken.next = true;
        self.tick();
        self.uut.result_taken.next = false;
        settle(&mut self.uut);
        assert!(self.uut.free.val(), "{what}: not free after the read-out");
        assert!(!self.uut.finished.val());
        issued
    }
}

fn query_module_against_software<const S: usize>(
    cfg: CoreConfig,
    points: &[[u32; 3]],
    queries: usize,
    seed: u64,
) {
    let tree = crate::common::pack(points, cfg.layout);
    let cfg = CoreConfig {
        address_bits: tree.address_bits().max(1),
        ..cfg
    };
    cfg.validate().expect("config");
    assert_eq!(cfg.slot_bits(), S);
    let index = (seed % cfg.queries_per_port as u64) as usize;
    let mut uut = QueryModule::<S>::new(&cfg, index);
    uut.connect_all();
    check_all(&uut).expect("QueryModule checks");
    let mut b = Bench {
        uut,
        index,
        r: crate::common::rng(seed),
    };
    b.uut.reset.next = true;
    b.tick();
    b.uut.reset.next = false;
    let hw_queries =
        crate::common::random_queries(&mut b.r, queries, cfg.layout, cfg.k, cfg.metric);
    let reads: usize = hw_queries
        .iter()
        .map(|hq| b.query(&cfg, &tree, hq.coords, hq.k as usize, hq.radius))
        .sum();
    assert!(
        reads >= 10 * queries,
        "only {reads} reads in {queries} queries"
    );
}

#[test]
fn query_module_against_the_software_search() {
    let layout = PhotonLayout::paper();
    let mut r = crate::common::rng(131);
    let points = crate::common::random_points(&mut r, 300, layout);
    let cases = [
        (Traversal::Remember, Metric::L1, 10, 132),
        (Traversal::Reread, Metric::L2, 7, 133),
        (Traversal::Cell, Metric::L1, 10, 134),
        (Traversal::Cell, Metric::L2, 1, 135),
    ];
    for (cfg, seed) in crate::common::variants(CoreConfig::paper(), &cases) {
        query_module_against_software::<32>(cfg, &points, 40, seed);
    }
}

/// Ties everywhere (a few distinct points, each many times) and K > 32.
#[test]
fn query_module_ties_and_wide_lists() {
    let mut r = crate::common::rng(141);
    let points: Vec<[u32; 3]> = (0..200)
        .map(|_| [0, 1, 2].map(|_| r.gen_range(0..4u32) * 5))
        .collect();
    for (traversal, k, seed) in [
        (Traversal::Remember, 10usize, 142u64),
        (Traversal::Reread, 4, 143),
    ] {
        let cfg = CoreConfig {
            traversal,
            k,
            metric: Metric::L1,
            ..CoreConfig::paper()
        };
        query_module_against_software::<32>(cfg, &points, 12, seed);
    }
    let wide = CoreConfig {
        traversal: Traversal::Cell,
        k: 40,
        metric: Metric::L2,
        ..CoreConfig::paper()
    };
    query_module_against_software::<64>(wide, &points, 8, 144);
}
