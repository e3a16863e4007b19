//! Labelling speed on a 4000 x 4000 map (target: < 50 ms on 2 cores), plus closing and the
//! full extraction.
#![allow(missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use blob_features::{BlobScratch, Blobs, Connectivity, Labeler, close};
use criterion::{Criterion, criterion_group, criterion_main};
use grid_core::{OccupancyGrid, Pose2};

fn bench(c: &mut Criterion) {
    let (w, h) = (4000, 4000);
    let plan = common::floor_plan(w, h, 120, 7);
    let noise = common::random_mask(w, h, 0.5, 7);
    let mut g = c.benchmark_group("label_4000x4000");
    g.sample_size(10);
    let mut labels = Vec::new();
    for (name, mask) in [("floor_plan", &plan), ("random_50pct", &noise)] {
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut labeler = Labeler::new(Connectivity::Eight);
            g.bench_function(format!("{name}/8conn/{threads}thr"), |b| {
                b.iter(|| {
                    pool.install(|| labeler.label(black_box(mask), w, h, &mut labels).unwrap())
                })
            });
        }
    }
    let mut labeler = Labeler::new(Connectivity::Four);
    g.bench_function("floor_plan/4conn/default", |b| {
        b.iter(|| labeler.label(black_box(&plan), w, h, &mut labels).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("extract_4000x4000");
    g.sample_size(10);
    let mut scratch_mask = plan.clone();
    let mut tmp = Vec::new();
    g.bench_function("close_r1", |b| {
        b.iter(|| {
            scratch_mask.copy_from_slice(&plan);
            close(&mut scratch_mask, w, h, 1, &mut tmp).unwrap()
        })
    });
    let cells: Vec<u8> = plan.iter().map(|&m| if m == 1 { 100 } else { 0 }).collect();
    let grid = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
    let blobs = Blobs::default();
    let mut scratch = BlobScratch::default();
    let mut out = Vec::new();
    g.bench_function("blobs_default", |b| {
        b.iter(|| {
            out.clear();
            blobs.extract_with(&grid, &mut scratch, &mut out);
            out.len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
