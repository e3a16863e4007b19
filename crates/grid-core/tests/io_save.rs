//! Writing maps the way map_saver does, and reading them back.

use grid_core::io::{LoadOptions, image_path_for, load_map, save_map};
use grid_core::{OccupancyGrid, Pose2, UNKNOWN};
use proptest::prelude::*;
use tempfile::TempDir;

#[test]
fn writes_map_saver_files_byte_for_byte() {
    let dir = TempDir::new().unwrap();
    // Percent cells: 0 and 25 are free, 65 and 100 occupied, 30 and unknown are unknown.
    let g = OccupancyGrid::from_cells(
        3,
        2,
        0.05,
        Pose2::new(-12.5, 3.0, 0.0),
        vec![0, 25, 30, 65, 100, UNKNOWN],
    )
    .unwrap();
    let yaml = dir.path().join("out.yaml");
    save_map(&g, &yaml).unwrap();
    let pgm = std::fs::read(dir.path().join("out.pgm")).unwrap();
    assert_eq!(pgm, b"P5\n3 2\n255\n\xfe\xfe\xcd\x00\x00\xcd");
    assert_eq!(
        std::fs::read_to_string(&yaml).unwrap(),
        "image: out.pgm\nmode: trinary\nresolution: 0.05\norigin: [-12.5, 3.0, 0.0]\n\
         negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    );
    // Only the two files: no temporary file is left behind.
    let mut names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["out.pgm", "out.yaml"]);
}

#[test]
fn overwrites_an_existing_output() {
    let dir = TempDir::new().unwrap();
    let yaml = dir.path().join("m.yml");
    let a = OccupancyGrid::from_cells(2, 1, 0.1, Pose2::default(), vec![0, 100]).unwrap();
    let b = OccupancyGrid::from_cells(1, 1, 0.2, Pose2::default(), vec![UNKNOWN]).unwrap();
    save_map(&a, &yaml).unwrap();
    save_map(&b, &yaml).unwrap();
    assert_eq!(image_path_for(&yaml), dir.path().join("m.pgm"));
    assert_eq!(load_map(&yaml, &LoadOptions::default()).unwrap(), b);
}

#[test]
fn refuses_outputs_it_could_not_read_back() {
    let dir = TempDir::new().unwrap();
    let g = OccupancyGrid::from_cells(1, 1, 0.1, Pose2::new(f64::NAN, 0.0, 0.0), vec![0]).unwrap();
    let yaml = dir.path().join("nan.yaml");
    assert_eq!(
        save_map(&g, &yaml).unwrap_err().to_string(),
        format!(
            "{}: origin must be 3 finite numbers [x, y, yaw], found [NaN, 0, 0]",
            yaml.display()
        )
    );
    let pgm = dir.path().join("m.pgm");
    let ok = OccupancyGrid::from_cells(1, 1, 0.1, Pose2::default(), vec![0]).unwrap();
    assert_eq!(
        save_map(&ok, &pgm).unwrap_err().to_string(),
        format!(
            "{}: the output map must be a .yaml or .yml file (its PGM is written beside it)",
            pgm.display()
        )
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    let missing = dir.path().join("no/such/dir/m.yaml");
    let e = save_map(&ok, &missing).unwrap_err();
    assert!(
        e.to_string()
            .starts_with(&dir.path().join("no/such/dir/m.pgm").display().to_string()),
        "{e}"
    );
}

fn trinary_grid() -> impl Strategy<Value = OccupancyGrid> {
    (1usize..40, 1usize..40)
        .prop_flat_map(|(w, h)| {
            (
                Just(w),
                Just(h),
                prop::collection::vec(prop::sample::select(vec![0u8, 100, UNKNOWN]), w * h),
                // Any positive resolution and any origin, including awkward binary fractions.
                1e-4f64..50.0,
                (
                    -1e6f64..1e6,
                    -1e6f64..1e6,
                    -std::f64::consts::PI..std::f64::consts::PI,
                ),
            )
        })
        .prop_map(|(w, h, cells, r, (x, y, yaw))| {
            OccupancyGrid::from_cells(w, h, r, Pose2::new(x, y, yaw), cells).unwrap()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn trinary_grids_survive_save_and_load_exactly(g in trinary_grid()) {
        let dir = TempDir::new().unwrap();
        let yaml = dir.path().join("map.yaml");
        save_map(&g, &yaml).unwrap();
        let back = load_map(&yaml, &LoadOptions::default()).unwrap();
        // PartialEq on the grid compares cells, size, resolution and origin bit for bit.
        prop_assert_eq!(back, g);
    }
}
