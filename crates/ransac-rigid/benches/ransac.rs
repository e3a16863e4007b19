//! RANSAC speed on 2 000 correspondences with 80 % outliers over a 2048 × 2048 map.
//! Run: `cargo bench -p ransac-rigid -- --quick`

use criterion::{Criterion, criterion_group, criterion_main};
use grid_core::{Correspondence, DVec2, EvidenceKind, Orientation, Rigid2};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ransac_rigid::{RansacConfig, Scoring, estimate_rigid};
use std::f64::consts::PI;

fn scene(n: usize, inlier_share: f64, area_share: f64, seed: u64) -> Vec<Correspondence> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let truth = Rigid2::new(1.1, 230.5, -180.25);
    let inv = truth.inverse();
    (0..n)
        .map(|i| {
            let a = DVec2::new(rng.random_range(0.0..2048.0), rng.random_range(0.0..2048.0));
            let inlier = (i as f64) < inlier_share * n as f64;
            let b = if inlier {
                inv.apply(a) + DVec2::new(rng.random_range(-0.7..0.7), rng.random_range(-0.7..0.7))
            } else {
                DVec2::new(rng.random_range(0.0..2048.0), rng.random_range(0.0..2048.0))
            };
            let area = rng.random::<f64>() < area_share;
            let ob: f64 = rng.random_range(0.0..PI);
            let oa = if inlier {
                ob + truth.theta
            } else {
                rng.random_range(0.0..PI)
            };
            Correspondence {
                a,
                b,
                orientation: area.then_some(Orientation {
                    a: oa,
                    b: ob,
                    period: PI,
                }),
                weight: rng.random_range(0.2..1.0),
                kind: if area {
                    EvidenceKind::Area
                } else {
                    EvidenceKind::Intensity
                },
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let pts = scene(2000, 0.2, 0.0, 1);
    let hybrid = scene(2000, 0.2, 0.1, 2);
    let cfg = RansacConfig::default();
    c.bench_function("2000 corr, 80% outliers, 2-point, msac", |b| {
        b.iter(|| estimate_rigid(&pts, &cfg).unwrap())
    });
    let count = RansacConfig {
        scoring: Scoring::InlierCount,
        ..cfg
    };
    c.bench_function("2000 corr, 80% outliers, 2-point, inlier count", |b| {
        b.iter(|| estimate_rigid(&pts, &count).unwrap())
    });
    c.bench_function("2000 corr, 80% outliers, 10% oriented area, msac", |b| {
        b.iter(|| estimate_rigid(&hybrid, &cfg).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
