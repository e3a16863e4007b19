//! Criterion bench: intensity image, scale space and detection on a 2048 x 2048 building-like
//! map (mirrored tiles of the real wpi_ilab map shipped with the sift-desc tests).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use grid_core::{OccupancyGrid, Pose2, UNKNOWN};
use scale_space::{
    IntensityMapping, ScaleSpace, ScaleSpaceConfig, intensity_image_in, known_bounding_box,
};

const SIDE: usize = 2048;

/// Minimal P5 reader with map_server trinary thresholds (bench input only).
fn read_fixture() -> OccupancyGrid {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../sift-desc/tests/data/wpi_ilab.pgm");
    let bytes = std::fs::read(&path).unwrap();
    // Header: "P5", comments, width, height, maxval, one whitespace byte.
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(512)]).to_string();
    let mut fields = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        offset += line.len();
        if !line.starts_with('#') {
            fields.extend(line.split_whitespace().map(str::to_string));
        }
        if fields.len() >= 4 {
            break;
        }
    }
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let cells = bytes[offset..offset + w * h]
        .iter()
        .map(|&v| match (255.0 - v as f64) / 255.0 {
            p if p > 0.65 => 100,
            p if p < 0.196 => 0,
            _ => UNKNOWN,
        })
        .collect();
    let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
    let mut tiled = vec![UNKNOWN; SIDE * SIDE];
    for y in 0..SIDE {
        let sy = if (y / h) % 2 == 0 {
            y % h
        } else {
            h - 1 - y % h
        };
        for x in 0..SIDE {
            let sx = if (x / w) % 2 == 0 {
                x % w
            } else {
                w - 1 - x % w
            };
            tiled[y * SIDE + x] = g.cells()[sy * w + sx];
        }
    }
    OccupancyGrid::from_cells(SIDE, SIDE, 0.05, Pose2::default(), tiled).unwrap()
}

fn bench(c: &mut Criterion) {
    let grid = read_fixture();
    let mapping = IntensityMapping::default();
    let mut group = c.benchmark_group("scale_space_2048");
    group.sample_size(10);
    let rect = known_bounding_box(&grid, 64).unwrap();
    group.bench_function("intensity_image", |b| {
        b.iter(|| black_box(intensity_image_in(&grid, &mapping, rect)).width)
    });
    for delta_min in [1.0f32, 0.5] {
        let config = ScaleSpaceConfig {
            delta_min,
            ..ScaleSpaceConfig::default()
        };
        let image = intensity_image_in(&grid, &mapping, rect);
        let mut space = ScaleSpace::new();
        group.bench_function(format!("build_delta_{delta_min}"), |b| {
            b.iter(|| space.build(black_box(&image), &config).unwrap())
        });
        space.build(&image, &config).unwrap();
        let mut out = Vec::new();
        group.bench_function(format!("detect_delta_{delta_min}"), |b| {
            b.iter(|| {
                out.clear();
                space.detect((0.0, 0.0), &mut out);
                out.len()
            })
        });
        eprintln!("delta_min {delta_min}: {} keypoints", out.len());
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
