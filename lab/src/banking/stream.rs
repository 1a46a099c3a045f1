//! The read stream the banks see: for every query of a rendered image, the kd-tree
//! addresses its search reads, in order. They come from the software search
//! (`knn::search_with`), which the barrel datapath matches read for read (its
//! module docs), so the stream is the hardware's own, only its interleaving across
//! slots and datapaths is left to the bank model.

use photon_fpga::host::map::kdtree::{KdTree, PackedTree};
use photon_fpga::host::map::knn::{search_with, NodeSource};
use photon_fpga::host::map::quantize::{GridPoint, Quantizer};
use photon_fpga::host::render::photons::trace_photons;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, eye_queries, RenderSettings};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use rayon::prelude::*;
use std::cell::RefCell;

/// A node source that records every address read, in order.
struct Recording<'a> {
    tree: &'a PackedTree,
    reads: RefCell<Vec<u32>>,
}

impl NodeSource<u32> for Recording<'_> {
    fn len(&self) -> usize {
        self.tree.len()
    }
    fn node(&self, addr: usize) -> ([u32; 3], u8) {
        self.reads.borrow_mut().push(addr as u32);
        self.tree.node(addr)
    }
}

/// The addresses one search reads, in order (the first is the root, 1).
pub fn read_stream(
    tree: &PackedTree,
    q: [u32; 3],
    k: usize,
    metric: Metric,
    traversal: Traversal,
) -> Vec<u32> {
    let rec = Recording {
        tree,
        reads: RefCell::new(Vec::with_capacity(256)),
    };
    let max = metric.max_dist(tree.layout.bits);
    let found = search_with(&rec, q, k, max, metric, traversal);
    let reads = rec.reads.into_inner();
    debug_assert_eq!(reads.len(), found.visited as usize);
    reads
}

/// One query of the image: its grid point and the pixel its eye ray left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageQuery {
    pub coords: [u32; 3],
    pub pixel: u32,
}

/// The Cornell box's photon map (every stored photon of `emitted` emitted ones, on
/// a `bits`-bit grid) and its image's queries in pixel order, as the renderer
/// builds them (`workload::cornell_image`, with the pixels kept).
pub struct ImageStream {
    pub tree: PackedTree,
    pub queries: Vec<ImageQuery>,
    pub width: u32,
    pub height: u32,
    /// Per query (in pixel order), the addresses its search reads.
    pub reads: Vec<Vec<u32>>,
}

impl ImageStream {
    /// Build the map and the queries and record every query's reads (k nearest,
    /// unbounded radius, `metric`, `traversal`).
    pub fn cornell(
        emitted: usize,
        bits: u32,
        settings: &RenderSettings,
        k: usize,
        metric: Metric,
        traversal: Traversal,
    ) -> Self {
        let scene = Scene::cornell_box();
        let photons = trace_photons(&scene, emitted, settings.seed, false);
        let world = render::photon_points(&photons);
        let quant = Quantizer::from_points(&world, bits).expect("a Cornell-box photon map");
        let points: Vec<[u32; 3]> = world.iter().map(|&p| quant.quantize(p)).collect();
        let tree = PackedTree::from_tree(&KdTree::build(&points), quant.layout);
        let (eye, _) = eye_queries(&scene, settings);
        let queries: Vec<ImageQuery> = eye
            .iter()
            .filter_map(|q| match quant.grid(q.pos.as_dvec3().to_array()) {
                Ok(GridPoint::Inside(c)) => Some(ImageQuery {
                    coords: c,
                    pixel: q.pixel,
                }),
                _ => None,
            })
            .collect();
        let reads = queries
            .par_iter()
            .map(|q| read_stream(&tree, q.coords, k, metric, traversal))
            .collect();
        ImageStream {
            tree,
            queries,
            width: settings.width,
            height: settings.height,
            reads,
        }
    }

    /// Reads of the whole stream.
    pub fn total_reads(&self) -> u64 {
        self.reads.iter().map(|r| r.len() as u64).sum()
    }
}
