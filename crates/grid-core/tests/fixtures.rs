//! Every map in `fixtures/maps` loads with its known size and cell counts.
//!
//! The expected counts do not come from this loader: they are the value histograms of
//! `fixtures/PROVENANCE.md` (computed with PIL when the maps were collected) and of
//! `python3 fixtures/histogram.py IMAGE`, bucketed by hand with each map's own YAML thresholds.

use std::path::PathBuf;

use grid_core::io::{LoadOptions, load_map};
use grid_core::{CellCounts, Pose2};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/maps")
        .join(name)
        .join(format!("{name}.yaml"))
}

struct Expected {
    name: &'static str,
    width: usize,
    height: usize,
    resolution: f64,
    origin: [f64; 3],
    free: usize,
    occupied: usize,
    unknown: usize,
}

/// For the map_saver maps (values 0, 205, 254 only; thresholds 0.65 / 0.196):
/// 0 → p = 1 occupied, 254 → p = 0.004 free, 205 → p = 0.19608, not below 0.196, unknown.
const EXPECTED: &[Expected] = &[
    // PROVENANCE.md: 254:34520, 205:21769, 0:3711.
    Expected {
        name: "wpi_ilab",
        width: 200,
        height: 300,
        resolution: 0.05,
        origin: [0.0, 0.0, 0.0],
        free: 34520,
        occupied: 3711,
        unknown: 21769,
    },
    // 205:138683, 254:7903, 0:870.
    Expected {
        name: "tb3_world",
        width: 384,
        height: 384,
        resolution: 0.05,
        origin: [-10.0, -10.0, 0.0],
        free: 7903,
        occupied: 870,
        unknown: 138683,
    },
    // 205:245062, 254:14672, 0:1386.
    Expected {
        name: "tb_ctrl_room",
        width: 544,
        height: 480,
        resolution: 0.05,
        origin: [-12.2, -12.2, 0.0],
        free: 14672,
        occupied: 1386,
        unknown: 245062,
    },
    // 205:183537, 254:63021, 0:3442.
    Expected {
        name: "aws_small_house",
        width: 500,
        height: 500,
        resolution: 0.05,
        origin: [-12.5, -12.5, 0.0],
        free: 63021,
        occupied: 3442,
        unknown: 183537,
    },
    // 205:165345, 254:23099, 0:1556.
    Expected {
        name: "sunil_pair_a",
        width: 380,
        height: 500,
        resolution: 0.05,
        origin: [-7.00141145, -16.95239031, 0.0],
        free: 23099,
        occupied: 1556,
        unknown: 165345,
    },
    // 205:189238, 254:28798, 0:1964.
    Expected {
        name: "sunil_pair_b",
        width: 500,
        height: 440,
        resolution: 0.05,
        origin: [-7.0, -9.41086525, 0.0],
        free: 28798,
        occupied: 1964,
        unknown: 189238,
    },
    // 254:170587, 205:8894, 0:5947. Its YAML has free_thresh 0.25, so 205 (p = 0.196 < 0.25)
    // is FREE, exactly as map_server reads it: this map has no unknown cell.
    Expected {
        name: "nav2_depot",
        width: 604,
        height: 307,
        resolution: 0.05,
        origin: [0.0, 0.0, 0.0],
        free: 170587 + 8894,
        occupied: 5947,
        unknown: 0,
    },
    // 254:1318485, 205:230801, 255:103807, 0:30951. Its YAML has free_thresh 0.1: 254 (p =
    // 0.004) and 255 (p = 0) are free, 205 (p = 0.196) unknown.
    Expected {
        name: "nav2_warehouse",
        width: 1006,
        height: 1674,
        resolution: 0.03,
        origin: [-15.1, -25.0, 0.0],
        free: 1318485 + 103807,
        occupied: 30951,
        unknown: 230801,
    },
    // RGBA PNG, alpha 255 everywhere. `histogram.py` gives channel sums (mean = sum / 3):
    // 615/3 = 205 → unknown: 895788; 758/3 = 252.7 and 765/3 = 255 → free: 456730 + 71320;
    // 10/3 = 3.3 and 0/3 = 0 → occupied: 23346 + 276. Same as PROVENANCE.md's buckets.
    Expected {
        name: "uos_cic",
        width: 980,
        height: 1477,
        resolution: 0.05,
        origin: [0.0, 0.0, 0.0],
        free: 456730 + 71320,
        occupied: 23346 + 276,
        unknown: 895788,
    },
    // 205:303940, 254:150467, 0:10668.
    Expected {
        name: "uos_avz",
        width: 975,
        height: 477,
        resolution: 0.05,
        origin: [0.0, 0.0, 0.0],
        free: 150467,
        occupied: 10668,
        unknown: 303940,
    },
    // Non-standard encoding, thresholds occ 0.2 / free 0.05 from its YAML:
    // free: p = (255 - v) / 255 < 0.05 ⟺ v > 242.25 ⟺ v >= 243;
    // occupied: p > 0.2 ⟺ 255 - v > 51 ⟺ v < 204 (v = 204 is p = 0.2 exactly: unknown);
    // unknown: 204 <= v <= 242.
    // So 255:190847 is free, 230:107483 unknown, 64:11755 and 128:1351 occupied. All buckets,
    // summed over the full histogram:
    //   python3 fixtures/histogram.py fixtures/maps/intel_lab/intel_lab.pgm | tail -n +2 |
    //     awk '{v=$1;n=$2; if (v>=243) f+=n; else if (v>=204) u+=n; else o+=n}
    //          END {print f, u, o}'
    // → 192948 113509 29942 (sum 336399 = 579 x 581).
    Expected {
        name: "intel_lab",
        width: 579,
        height: 581,
        resolution: 0.1,
        origin: [0.0, 0.0, 0.0],
        free: 192948,
        occupied: 29942,
        unknown: 113509,
    },
];

#[test]
fn every_fixture_loads_with_its_known_counts() {
    for e in EXPECTED {
        let g = load_map(fixture(e.name), &LoadOptions::default())
            .unwrap_or_else(|err| panic!("{}: {err}", e.name));
        assert_eq!((g.width(), g.height()), (e.width, e.height), "{}", e.name);
        assert_eq!(g.resolution(), e.resolution, "{}", e.name);
        assert_eq!(
            g.origin(),
            Pose2::new(e.origin[0], e.origin[1], e.origin[2]),
            "{}",
            e.name
        );
        assert_eq!(
            g.counts(),
            CellCounts {
                free: e.free,
                occupied: e.occupied,
                unknown: e.unknown
            },
            "{}",
            e.name
        );
    }
}

#[test]
fn every_fixture_folder_is_tested() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/maps");
    let mut on_disk: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    on_disk.sort();
    let mut tested: Vec<String> = EXPECTED.iter().map(|e| e.name.to_string()).collect();
    tested.sort();
    assert_eq!(on_disk, tested);
}

#[test]
fn rows_are_read_top_down() {
    // wpi_ilab: the PGM's first pixel byte is the top-left cell. Read the byte right after the
    // header ("P5\n200 300\n255\n" or with a comment) independently and compare.
    let pgm = std::fs::read(fixture("wpi_ilab").with_extension("pgm")).unwrap();
    let raster = &pgm[pgm.len() - 200 * 300..];
    let g = load_map(fixture("wpi_ilab"), &LoadOptions::default()).unwrap();
    for (i, (&v, &c)) in raster.iter().zip(g.cells()).enumerate() {
        let want = match v {
            0 => 100,
            254 => 0,
            205 => grid_core::UNKNOWN,
            other => panic!("unexpected value {other}"),
        };
        assert_eq!(c, want, "cell {i}");
    }
}
