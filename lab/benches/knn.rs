//! The software kNN (the paper's search on the packed tree) against the `kiddo`
//! crate (the current release, `ImmutableKdTree<f32, 3>`), single thread, on the same
//! points and k, measured side by side.
//!
//! (a) the paper's workload (§3): 1023 photons uniform on [0,1023]^3, k = 10, 32, 64;
//! (b) a Cornell-box photon map of 200K photons, k = 10, 32, 64, 100, 500.
//! Photon reads and distance tests per query are printed once per workload and k
//! for both ascents (`Traversal`): counts, not times.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::{search, search_with, Traversal};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga_lab::workload as workloads;
use std::hint::black_box;

const QUERIES: usize = 20_000;

struct Workload {
    name: String,
    packed: PackedTree,
    kiddo: ImmutableKdTree<f32, 3>,
    queries: Vec<[u32; 3]>,
}

fn workload(name: &str, w: photon_fpga_lab::workload::Workload) -> Workload {
    // f32 holds the 10-bit grid coordinates and their squared distances exactly.
    let fpoints: Vec<[f32; 3]> = w.points.iter().map(|p| p.map(|c| c as f32)).collect();
    Workload {
        name: name.to_string(),
        packed: w.tree,
        kiddo: ImmutableKdTree::new_from_slice(&fpoints).expect("kiddo tree"),
        queries: w.queries,
    }
}

fn paper_workload() -> Workload {
    workload(
        "paper-1023",
        workloads::uniform(PhotonLayout::paper(), 1023, QUERIES, 2013),
    )
}

/// 200K photons of the built-in Cornell box, queried at the renderer's eye-ray hits.
fn cornell_workload() -> Workload {
    let w = workloads::cornell(110_000, 200_000, 10, 64, 1);
    assert_eq!(w.points.len(), 200_000, "emit more photons");
    workload("cornell-200k", w)
}

fn run(c: &mut Criterion, w: &Workload, ks: &[usize]) {
    let mut g = c.benchmark_group(&w.name);
    g.sample_size(10);
    g.throughput(Throughput::Elements(w.queries.len() as u64));
    for &k in ks {
        let nq = w.queries.len() as f64;
        for traversal in [Traversal::Reread, Traversal::Remember] {
            let (mut reads, mut tested) = (0u64, 0u64);
            for &q in &w.queries {
                let f = search_with(&w.packed, q, k, u64::MAX, Metric::L2, traversal);
                reads += f.visited as u64;
                tested += f.tested as u64;
            }
            eprintln!(
                "{} k={k} {traversal}: {:.1} photon reads, {:.1} distance tests per query",
                w.name,
                reads as f64 / nq,
                tested as f64 / nq
            );
        }
        g.bench_with_input(BenchmarkId::new("sw", k), &k, |b, &k| {
            b.iter(|| {
                for &q in &w.queries {
                    black_box(search(&w.packed, q, k, u64::MAX, Metric::L2));
                }
            })
        });
        let fq: Vec<[f32; 3]> = w.queries.iter().map(|q| q.map(|c| c as f32)).collect();
        let kq = std::num::NonZero::new(k).unwrap();
        g.bench_with_input(BenchmarkId::new("kiddo", k), &k, |b, _| {
            b.iter(|| {
                for q in &fq {
                    black_box(
                        w.kiddo
                            .query(q)
                            .nearest_n::<SquaredEuclidean<f32>>(kq)
                            .execute(),
                    );
                }
            })
        });
    }
    g.finish();
}

fn benches(c: &mut Criterion) {
    run(c, &paper_workload(), &[10, 32, 64]);
    run(c, &cornell_workload(), &[10, 32, 64, 100, 500]);
}

criterion_group!(knn, benches);
criterion_main!(knn);
