//! `mapmerge info` on the fixtures, through the real binary.
//!
//! Expected counts come from the value histograms in `fixtures/PROVENANCE.md` and
//! `python3 fixtures/histogram.py IMAGE`, bucketed with each map's YAML thresholds (the
//! reasoning per map is in `crates/grid-core/tests/fixtures.rs`), not from the loader.

use std::path::PathBuf;

use serde_json::{Value, json};

mod common;
use common::{mapmerge, sparse_walls_map, tiny_map};

fn fixture(name: &str, ext: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/maps")
        .join(name)
        .join(format!("{name}.{ext}"))
}

fn info_json(args: &[&str]) -> Value {
    let out = mapmerge(args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stderr.is_empty());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        text.lines().count(),
        1,
        "one JSON object on one line: {text}"
    );
    serde_json::from_str(&text).unwrap()
}

/// The wall thickness of the map `yaml`, as `mapmerge::ascent::wall_thickness` measures it.
fn thickness(yaml: &std::path::Path) -> f64 {
    mapmerge::ascent::wall_thickness(&load(yaml))
}

/// The frontier ratio of the map `yaml`, as `mapmerge::ascent::frontier_ratio` measures it.
fn frontier(yaml: &std::path::Path) -> f64 {
    mapmerge::ascent::frontier_ratio(&load(yaml))
}

/// The share of lone wall cells of the map `yaml`, as `mapmerge::ascent::lone_wall_share`
/// measures it.
fn lone_share(yaml: &std::path::Path) -> f64 {
    mapmerge::ascent::lone_wall_share(&load(yaml))
}

fn load(yaml: &std::path::Path) -> grid_core::OccupancyGrid {
    grid_core::io::load_map(yaml, &grid_core::io::LoadOptions::default()).unwrap()
}

/// (name, image extension, width, height, resolution, origin, free, occupied, unknown)
type Row = (
    &'static str,
    &'static str,
    u64,
    u64,
    f64,
    [f64; 3],
    u64,
    u64,
    u64,
);

#[test]
fn info_json_on_every_fixture() {
    let cases: &[Row] = &[
        (
            "wpi_ilab",
            "pgm",
            200,
            300,
            0.05,
            [0.0, 0.0, 0.0],
            34520,
            3711,
            21769,
        ),
        (
            "tb3_world",
            "pgm",
            384,
            384,
            0.05,
            [-10.0, -10.0, 0.0],
            7903,
            870,
            138683,
        ),
        (
            "tb_ctrl_room",
            "pgm",
            544,
            480,
            0.05,
            [-12.2, -12.2, 0.0],
            14672,
            1386,
            245062,
        ),
        (
            "aws_small_house",
            "pgm",
            500,
            500,
            0.05,
            [-12.5, -12.5, 0.0],
            63021,
            3442,
            183537,
        ),
        (
            "sunil_pair_a",
            "pgm",
            380,
            500,
            0.05,
            [-7.00141145, -16.95239031, 0.0],
            23099,
            1556,
            165345,
        ),
        (
            "sunil_pair_b",
            "pgm",
            500,
            440,
            0.05,
            [-7.0, -9.41086525, 0.0],
            28798,
            1964,
            189238,
        ),
        // free_thresh 0.25 in its YAML: the 205 cells are free.
        (
            "nav2_depot",
            "pgm",
            604,
            307,
            0.05,
            [0.0, 0.0, 0.0],
            170587 + 8894,
            5947,
            0,
        ),
        // free_thresh 0.1 in its YAML: 254 and 255 are free, 205 unknown.
        (
            "nav2_warehouse",
            "pgm",
            1006,
            1674,
            0.03,
            [-15.1, -25.0, 0.0],
            1318485 + 103807,
            30951,
            230801,
        ),
        (
            "uos_cic",
            "png",
            980,
            1477,
            0.05,
            [0.0, 0.0, 0.0],
            456730 + 71320,
            23346 + 276,
            895788,
        ),
        (
            "uos_avz",
            "pgm",
            975,
            477,
            0.05,
            [0.0, 0.0, 0.0],
            150467,
            10668,
            303940,
        ),
        // occ 0.2 / free 0.05: free v >= 243, unknown 204..=242, occupied v < 204.
        (
            "intel_lab",
            "pgm",
            579,
            581,
            0.1,
            [0.0, 0.0, 0.0],
            192948,
            29942,
            113509,
        ),
    ];
    for &(name, ext, width, height, resolution, origin, free, occupied, unknown) in cases {
        let yaml = fixture(name, "yaml");
        let yaml_s = yaml.to_str().unwrap();
        let got = info_json(&["info", "--json", yaml_s]);
        let thresholds = if name == "intel_lab" {
            (0.2, 0.05)
        } else if name == "nav2_depot" {
            (0.65, 0.25)
        } else if name == "nav2_warehouse" {
            (0.65, 0.1)
        } else {
            (0.65, 0.196)
        };
        let want = json!({
            "path": yaml_s,
            "image": fixture(name, ext).to_str().unwrap(),
            "mode": "trinary",
            "width": width,
            "height": height,
            "resolution": resolution,
            "origin": origin,
            "negate": false,
            "occupied_thresh": thresholds.0,
            "free_thresh": thresholds.1,
            "free": free,
            "occupied": occupied,
            "unknown": unknown,
        });
        // The library's measures (unit-tested on walls of known thickness and on speckle),
        // reported as they are (to the last bit but one: serde_json's parser may round the
        // last).
        let mut got = got;
        for (key, want) in [
            ("wall_thickness", thickness(&yaml)),
            ("frontier_ratio", frontier(&yaml)),
            ("lone_wall_share", lone_share(&yaml)),
        ] {
            let reported = got
                .as_object_mut()
                .unwrap()
                .remove(key)
                .and_then(|v| v.as_f64());
            assert!(
                reported.is_some_and(|t| (t - want).abs() <= 1e-12 * want),
                "{name}: {key} {reported:?} against {want}"
            );
        }
        assert_eq!(got, want, "{name}");
    }
}

#[test]
fn info_human_form() {
    let yaml = fixture("wpi_ilab", "yaml");
    let out = mapmerge(&["info", yaml.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    let want = format!(
        "map:        {}\n\
         image:      {} (mode trinary, negate 0, occupied_thresh 0.65, free_thresh 0.196)\n\
         size:       200 x 300 cells (10.00 x 15.00 m)\n\
         resolution: 0.05 m/cell\n\
         origin:     x 0 m, y 0 m, yaw 0 rad\n\
         free:       34520 (57.5%)\n\
         occupied:   3711 (6.2%)\n\
         unknown:    21769 (36.3%)\n\
         walls:      1.13 cells thick (occupied cells per side facing free space)\n\
         frontier:   0.53 free cells beside unknown per free cell beside a wall (high for a short-range sensor)\n\
         speckle:    0.8% of occupied cells lone (no occupied neighbour; grows with range noise)\n",
        yaml.display(),
        fixture("wpi_ilab", "pgm").display()
    );
    assert_eq!(format!("{:.2}", thickness(&yaml)), "1.13");
    assert_eq!(format!("{:.2}", frontier(&yaml)), "0.53");
    assert_eq!(format!("{:.1}", 100.0 * lone_share(&yaml)), "0.8");
    assert_eq!(text, want);
}

#[test]
fn a_map_no_pair_can_be_accepted_with_is_noted() {
    // 900 known cells, under the 1 250 a registered pair must share
    // (`VerifyConfig::min_overlap_cells`).
    let dir = tempfile::TempDir::new().unwrap();
    let pgm = tiny_map(dir.path());
    let out = mapmerge(&["info", pgm.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.ends_with(
            "note:       only 900 known cells, fewer than the 1250 a registered pair must share (estimate|merge --min-overlap-cells): with the default settings no pair with this map is accepted\n"
        ),
        "{text}"
    );
    // A map with known cells enough but no wall gets its own note.
    let free = sparse_walls_map(dir.path(), "free.pgm", 0);
    let out = mapmerge(&["info", free.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.ends_with(
            "note:       no occupied cell: walls are what a placement is judged by, so no pair with this map is accepted\n"
        ),
        "{text}"
    );
    // A fixture floor gets no note (`info_human_form` compares its whole text).
    let yaml = fixture("wpi_ilab", "yaml");
    let out = mapmerge(&["info", yaml.to_str().unwrap()]);
    assert!(!String::from_utf8(out.stdout).unwrap().contains("note:"));
}

#[test]
fn bare_image_defaults_and_flags() {
    let pgm = fixture("wpi_ilab", "pgm");
    let pgm = pgm.to_str().unwrap();
    let counts = |v: &Value| {
        (
            v["free"].clone(),
            v["occupied"].clone(),
            v["unknown"].clone(),
        )
    };

    let plain = info_json(&["info", "--json", pgm]);
    assert_eq!(plain["resolution"], json!(0.05));
    assert_eq!(plain["origin"], json!([0.0, 0.0, 0.0]));
    assert_eq!(counts(&plain), (json!(34520), json!(3711), json!(21769)));

    // Flags may come before or after the subcommand.
    let coarse = info_json(&["--resolution", "0.1", "info", "--json", pgm]);
    assert_eq!(coarse["resolution"], json!(0.1));
    assert_eq!(counts(&coarse), counts(&plain));

    // negate: 0 (p = 0) free; 254 and 205 (p = 0.996, 0.804) occupied.
    let neg = info_json(&["info", "--json", pgm, "--negate"]);
    assert_eq!(neg["negate"], json!(true));
    assert_eq!(counts(&neg), (json!(3711), json!(34520 + 21769), json!(0)));

    // free_thresh 0.25: 205 (p = 0.196) becomes free.
    let loose = info_json(&["info", "--json", pgm, "--free-thresh", "0.25"]);
    assert_eq!(
        counts(&loose),
        (json!(34520 + 21769), json!(3711), json!(0))
    );

    // occupied_thresh 0.1: 205 (p = 0.196) becomes occupied, given free_thresh below it.
    let strict = info_json(&[
        "info",
        "--json",
        pgm,
        "--occupied-thresh",
        "0.1",
        "--free-thresh",
        "0.05",
    ]);
    assert_eq!(
        counts(&strict),
        (json!(34520), json!(3711 + 21769), json!(0))
    );

    // The flags do not change a map given by YAML.
    let yaml = fixture("wpi_ilab", "yaml");
    let y = info_json(&[
        "info",
        "--json",
        yaml.to_str().unwrap(),
        "--negate",
        "--resolution",
        "1",
    ]);
    assert_eq!(y["resolution"], json!(0.05));
    assert_eq!(counts(&y), counts(&plain));
}

#[test]
fn help_teaches() {
    let out = mapmerge(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "Examples:",
        "mapmerge info --json",
        "Exit codes:",
        "--resolution",
        "--negate",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in:\n{text}");
    }
    let out = mapmerge(&["info", "--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    for key in [
        "path",
        "mode",
        "width, height",
        "resolution",
        "origin",
        "free, occupied, unknown",
    ] {
        assert!(
            text.contains(&format!("  {key} ")),
            "key {key:?} undocumented in:\n{text}"
        );
    }
}
