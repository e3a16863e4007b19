//! Criterion bench: SIFT extraction and matching on a 2048 x 2048 pair (a tiled real map and
//! a turned, shifted copy of it on the same canvas), stage by stage.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use grid_core::{CorrespondenceSource, Rigid2};
use sift_desc::{
    DESCRIPTOR_LEN, MatchConfig, Sift, SiftCorrespondences, SiftFeature, match_features,
};

const SIDE: usize = 2048;

fn pair() -> (grid_core::OccupancyGrid, grid_core::OccupancyGrid) {
    let a = common::tiled(&common::fixture(), SIDE);
    let c = SIDE as f64 / 2.0;
    // Turn by 30 degrees about the centre and shift: the corners fall off the canvas.
    let rot = Rigid2::new(30f64.to_radians(), 0.0, 0.0);
    let p = rot.apply(grid_core::DVec2::new(c, c));
    let b = a
        .warp(
            &Rigid2::new(rot.theta, c - p.x + 40.0, c - p.y - 25.0),
            SIDE,
            SIDE,
        )
        .unwrap();
    (a, b)
}

/// The same ratio test on f32 descriptors, to compare against the u8 kernel.
fn match_f32(a: &[[f32; DESCRIPTOR_LEN]], b: &[[f32; DESCRIPTOR_LEN]], ratio: f32) -> usize {
    use rayon::prelude::*;
    a.par_iter()
        .filter(|q| {
            let (mut d1, mut d2) = (f32::MAX, f32::MAX);
            for t in b {
                let mut acc = [0f32; 8];
                for (cq, ct) in q.chunks_exact(8).zip(t.chunks_exact(8)) {
                    for i in 0..8 {
                        let d = cq[i] - ct[i];
                        acc[i] += d * d;
                    }
                }
                let d: f32 = acc.iter().sum();
                if d < d1 {
                    d2 = d1;
                    d1 = d;
                } else if d < d2 {
                    d2 = d;
                }
            }
            d1 < ratio * ratio * d2
        })
        .count()
}

fn to_f32(f: &[SiftFeature]) -> Vec<[f32; DESCRIPTOR_LEN]> {
    f.iter()
        .map(|f| std::array::from_fn(|i| f.descriptor[i] as f32 / 512.0))
        .collect()
}

fn bench(c: &mut Criterion) {
    let (a, b) = pair();
    let sift = Sift::default();
    let (fa, fb) = (sift.extract_features(&a), sift.extract_features(&b));
    eprintln!("features: A {} B {}", fa.len(), fb.len());
    let mut group = c.benchmark_group("sift_2048");
    group.sample_size(10);
    group.bench_function("extract_one_map", |bench| {
        bench.iter(|| black_box(sift.extract_features(black_box(&a))).len())
    });
    let mut out = Vec::new();
    // Forward ratio test only, comparable with `match_f32`; then the default with cross-check.
    let forward = MatchConfig {
        cross_check: false,
        ..MatchConfig::default()
    };
    group.bench_function("match_u8", |bench| {
        bench.iter(|| {
            match_features(&fa, &fb, &forward, &mut out);
            out.len()
        })
    });
    group.bench_function("match_u8_cross_check", |bench| {
        bench.iter(|| {
            match_features(&fa, &fb, &MatchConfig::default(), &mut out);
            out.len()
        })
    });
    let (ga, gb) = (to_f32(&fa), to_f32(&fb));
    group.bench_function("match_f32", |bench| {
        bench.iter(|| match_f32(black_box(&ga), black_box(&gb), 0.65))
    });
    let source = SiftCorrespondences::default();
    let mut corr = Vec::new();
    group.bench_function("pair_end_to_end", |bench| {
        bench.iter(|| {
            corr.clear();
            source.correspondences(&a, &b, &mut corr);
            corr.len()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
