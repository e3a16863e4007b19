//! Case generation speed: the paper preset, a 400 x 400 lidar case, and (behind
//! `MAPSIM_BENCH_LARGE=1`, since it takes seconds per iteration) a 4000 x 4000 case.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mapsim::{CaseConfig, RobotConfig, WorldConfig, WorldKind, generate_case};

fn config(kind: WorldKind, size: usize, robot: RobotConfig) -> CaseConfig {
    CaseConfig {
        world: WorldConfig {
            kind,
            width: size,
            height: size,
            ..WorldConfig::default()
        },
        robots: vec![robot.clone(), robot],
        overlap_tolerance: f64::INFINITY,
        ..CaseConfig::default()
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("generate_case");
    g.sample_size(10);
    let paper = CaseConfig {
        overlap_tolerance: f64::INFINITY,
        ..CaseConfig::paper()
    };
    g.bench_function("paper_150", |b| {
        b.iter(|| generate_case(black_box(&paper), 1).unwrap())
    });
    let disaster = config(WorldKind::Disaster, 400, RobotConfig::default());
    g.bench_function("disaster_400_lidar", |b| {
        b.iter(|| generate_case(black_box(&disaster), 1).unwrap())
    });
    let indoor = config(WorldKind::Indoor, 400, RobotConfig::default());
    g.bench_function("indoor_400_lidar", |b| {
        b.iter(|| generate_case(black_box(&indoor), 1).unwrap())
    });
    if std::env::var_os("MAPSIM_BENCH_LARGE").is_some() {
        let large = config(
            WorldKind::Disaster,
            4000,
            RobotConfig {
                max_range: 200.0,
                ..RobotConfig::default()
            },
        );
        g.bench_function("disaster_4000_lidar", |b| {
            b.iter(|| generate_case(black_box(&large), 1).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
