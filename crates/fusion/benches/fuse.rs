//! Speed of the fusion: two 2048 x 2048 real-building maps fused, and the poses of a team of
//! ten maps solved from answers between every pair.
//!
//! `cargo bench -p fusion --bench fuse`

use criterion::{Criterion, criterion_group, criterion_main};
use fusion::{FusionConfig, MapPlacement, PairEdge, PoseGraphConfig, fuse, solve_poses};
use grid_core::io::{LoadOptions, load_map};
use grid_core::{DVec2, Rigid2};

fn bench(c: &mut Criterion) {
    let path = format!(
        "{}/../../fixtures/maps/uos_cic/uos_cic.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let floor = load_map(path, &LoadOptions::default()).expect("fixture loads");
    // The CIC floor on a 2048 x 2048 canvas, and turned by 30 degrees on another, as in the
    // registration benches; each placed back by the inverse of its canvas pose.
    let to_a = Rigid2::new(0.0, 500.0, 280.0);
    let to_b = Rigid2::new(30f64.to_radians(), 900.0, 150.0);
    let a = floor.warp(&to_a, 2048, 2048).expect("canvas");
    let b = floor.warp(&to_b, 2048, 2048).expect("canvas");
    let placements = [
        MapPlacement {
            grid: &a,
            pose: Rigid2::IDENTITY,
            weight: 1.0,
        },
        MapPlacement {
            grid: &b,
            pose: to_a.compose(&to_b.inverse()),
            weight: 1.0,
        },
    ];
    let config = FusionConfig::default();
    c.bench_function("fuse_two_2048_maps", |bch| {
        bch.iter(|| fuse(&a.geometry(), &placements, &config).expect("fused"))
    });

    // Ten maps in a ring of turns and shifts, answers between every pair, 0.5 px off.
    let truth: Vec<Rigid2> = (0..10)
        .map(|k| {
            let k = k as f64;
            Rigid2::new(0.6 * k, 300.0 * k.cos(), 300.0 * k.sin())
        })
        .collect();
    let mut edges = Vec::new();
    for i in 0..10 {
        for j in i + 1..10 {
            let nudge = Rigid2::new(0.0, 0.5, -0.5);
            edges.push(PairEdge {
                a: i,
                b: j,
                b_to_a: truth[i].inverse().compose(&truth[j]).compose(&nudge),
                weight: 0.9,
            });
        }
    }
    let centres = vec![DVec2::new(500.0, 400.0); 10];
    let pg = PoseGraphConfig::default();
    c.bench_function("solve_poses_ten_maps_all_pairs", |bch| {
        bch.iter(|| solve_poses(&centres, 0, &edges, &pg).expect("solved"))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
