//! The bench pairs of `register.rs` (see its documentation), shared with the example
//! `bench_pair`, which registers one of them in a process of its own for a profiler.

use grid_core::io::{LoadOptions, load_map};
use grid_core::{OccupancyGrid, Rigid2, UNKNOWN};
use mapsim::{CaseConfig, generate_case};

/// Fixture map `name` moved by `a_pose` onto one 2048 x 2048 canvas and by `b_pose` onto
/// another.
fn fixture_on_canvases(
    name: &str,
    a_pose: Rigid2,
    b_pose: Rigid2,
) -> (OccupancyGrid, OccupancyGrid) {
    let path = format!(
        "{}/../../fixtures/maps/{name}/{name}.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let map = load_map(path, &LoadOptions::default()).expect("fixture loads");
    let canvas = |pose: &Rigid2| map.warp(pose, 2048, 2048).expect("canvas");
    (canvas(&a_pose), canvas(&b_pose))
}

/// The CIC floor on a 2048 x 2048 canvas, and the same floor turned by 30 degrees on another.
pub fn pair() -> (OccupancyGrid, OccupancyGrid) {
    fixture_on_canvases(
        "uos_cic",
        Rigid2::new(0.0, 500.0, 280.0),
        Rigid2::new(30f64.to_radians(), 900.0, 150.0),
    )
}

/// The nav2 warehouse on a 2048 x 2048 canvas, and the same map turned by 30 degrees (its
/// corners within the canvas) on another.
pub fn warehouse_pair() -> (OccupancyGrid, OccupancyGrid) {
    fixture_on_canvases(
        "nav2_warehouse",
        Rigid2::new(0.0, 500.0, 180.0),
        Rigid2::new(30f64.to_radians(), 900.0, 40.0),
    )
}

/// The western and the eastern three quarters of the uos_cic floor (see the module
/// documentation), the eastern turned by 30 degrees, each on a 2048 x 2048 canvas.
pub fn overlapping_crops() -> (OccupancyGrid, OccupancyGrid) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/maps/uos_cic/uos_cic.yaml"
    );
    let floor = load_map(path, &LoadOptions::default()).expect("fixture loads");
    let w = floor.width();
    let crop = |keep: std::ops::Range<usize>| {
        let mut c = floor.clone();
        for (i, cell) in c.cells_mut().iter_mut().enumerate() {
            if !keep.contains(&(i % w)) {
                *cell = UNKNOWN;
            }
        }
        c
    };
    let a = crop(0..w * 3 / 4)
        .warp(&Rigid2::new(0.0, 300.0, 200.0), 2048, 2048)
        .expect("canvas");
    let b = crop(w / 4..w)
        .warp(&Rigid2::new(30f64.to_radians(), 900.0, 150.0), 2048, 2048)
        .expect("canvas");
    (a, b)
}

/// Two robots' partial maps of the uos_cic floor sharing `overlap` of their known cells (see
/// the module documentation), each moved onto a 2048 x 2048 canvas.
pub fn partial_pair(overlap: f64) -> (OccupancyGrid, OccupancyGrid) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/maps/uos_cic/uos_cic.yaml"
    );
    let floor = load_map(path, &LoadOptions::default()).expect("fixture loads");
    let config = CaseConfig {
        overlap,
        overlap_tolerance: f64::INFINITY,
        ..CaseConfig::floor(floor, &[0.1, 0.2])
    };
    let case = generate_case(&config, 7_014_000).expect("case generates");
    let canvas = |m: &OccupancyGrid| {
        m.warp(&Rigid2::new(0.0, 300.0, 200.0), 2048, 2048)
            .expect("canvas")
    };
    (canvas(&case.robots[0].map), canvas(&case.robots[1].map))
}
