//! The read stream the banks see: for every query of a rendered image, the kd-tree
//! addresses its search reads, in order. They come from the software search
//! (`knn::search_with`), which the barrel datapath matches read for read (its
//! module docs), so the stream is the hardware's own, only its interleaving across
//! slots and datapaths is left to the bank model.

use crate::workload;
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::{search_with, NodeSource};
use photon_fpga::host::render::RenderSettings;
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
        let (w, pixels) = workload::cornell_image_pixels(emitted, usize::MAX, bits, settings);
        let tree = w.tree;
        let queries: Vec<ImageQuery> = w
            .queries
            .into_iter()
            .zip(pixels)
            .map(|(coords, pixel)| ImageQuery { coords, pixel })
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
