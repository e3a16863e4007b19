//! Helpers of the tests that run the `mapmerge` binary (`cli_*.rs`), and the simulated pairs
//! on real floors that those and `simulated_pairs.rs` share: each test file uses some of them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use grid_core::{OccupancyGrid, Rigid2};
use mapsim::{Case, CaseConfig, RobotConfig, WorldConfig, WorldKind, generate_case};

/// `fixtures/maps/NAME/NAME.yaml`.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../fixtures/maps/{name}/{name}.yaml"))
}

/// The floor `name` of `fixtures/maps` (its `name/name.yaml`), loaded.
pub fn fixture_floor(name: &str) -> OccupancyGrid {
    grid_core::io::load_map(fixture(name), &Default::default()).unwrap()
}

/// Case `seed` of a row of `cargo xtask eval` on a real floor (`--suites real`, `floors` or
/// `large`): two lidar robots with 10 % range noise exploring `floor` at 30 % overlap.
pub fn floor_case(floor: OccupancyGrid, seed: u64) -> Case {
    let config = CaseConfig {
        world: WorldConfig {
            kind: WorldKind::Grid(floor),
            width: 0,
            height: 0,
            ..WorldConfig::default()
        },
        robots: vec![
            RobotConfig {
                noise_bound: 0.1,
                ..RobotConfig::default()
            };
            2
        ],
        overlap: 0.3,
        overlap_tolerance: f64::INFINITY,
        ..CaseConfig::default()
    };
    generate_case(&config, seed).unwrap()
}

/// Run `mapmerge args`.
pub fn mapmerge(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mapmerge"))
        .args(args)
        .output()
        .unwrap()
}

/// Run `mapmerge args`, assert exit code 2, no stdout, no panic and one line on stderr, and
/// return that line.
pub fn fails(args: &[&str]) -> String {
    let out = mapmerge(args);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    stderr.trim_end().to_string()
}

/// The transform of a report's `{"theta", "tx", "ty"}` object.
pub fn transform(v: &serde_json::Value) -> Rigid2 {
    Rigid2::new(
        v["theta"].as_f64().unwrap(),
        v["tx"].as_f64().unwrap(),
        v["ty"].as_f64().unwrap(),
    )
}

/// Write `tiny.pgm` into `dir`: a 30 x 30 bare PGM map, a wall along the top row and free
/// space below, 900 known cells (fewer than the 1 250 a registered pair must share).
pub fn tiny_map(dir: &Path) -> PathBuf {
    let pgm = dir.join("tiny.pgm");
    let mut bytes = b"P5\n30 30\n255\n".to_vec();
    bytes.extend((0..900).map(|i| if i < 30 { 0u8 } else { 254 }));
    std::fs::write(&pgm, bytes).unwrap();
    pgm
}

/// A 50 x 50 bare map in `dir/name`: 2,500 known cells, free but for `walls` occupied cells
/// along its first row.
pub fn sparse_walls_map(dir: &Path, name: &str, walls: usize) -> PathBuf {
    let pgm = dir.join(name);
    let mut bytes = b"P5\n50 50\n255\n".to_vec();
    bytes.extend((0..2500).map(|i| if i < walls { 0u8 } else { 254 }));
    std::fs::write(&pgm, bytes).unwrap();
    pgm
}

/// Run `mapmerge estimate A B --json` with `flags`.
pub fn estimate_json(a: &Path, b: &Path, flags: &[&str]) -> Output {
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    mapmerge(&[&["estimate", a, b, "--json"], flags].concat())
}
