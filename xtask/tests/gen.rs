//! `xtask gen` through the binary: the same seed gives byte-identical files, the written maps
//! read back as the simulator's maps, the truth file matches the simulator's truth, and a real
//! map can be the world.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use grid_core::io::{LoadOptions, load_map};
use mapsim::{CaseConfig, generate_case};

fn xtask(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .output()
        .expect("xtask runs")
}

fn gen_into(dir: &Path, extra: &[&str]) {
    let out = dir.to_str().unwrap();
    let mut args = vec!["gen", "--out", out];
    args.extend_from_slice(extra);
    let o = xtask(&args);
    assert!(
        o.status.success(),
        "xtask {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Every file under `dir`, by relative path, with its bytes.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

#[test]
fn same_seed_gives_byte_identical_files() {
    let (a, b, c) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    let args = ["--preset", "paper", "--seed", "7", "--count", "2"];
    gen_into(a.path(), &args);
    gen_into(b.path(), &args);
    let (ta, tb) = (tree(a.path()), tree(b.path()));
    let names: Vec<_> = ta
        .keys()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "case_0/preview.png",
            "case_0/robot_0.pgm",
            "case_0/robot_0.yaml",
            "case_0/robot_1.pgm",
            "case_0/robot_1.yaml",
            "case_0/truth.json",
            "case_1/preview.png",
            "case_1/robot_0.pgm",
            "case_1/robot_0.yaml",
            "case_1/robot_1.pgm",
            "case_1/robot_1.yaml",
            "case_1/truth.json",
        ]
    );
    assert!(ta == tb, "two runs with seed 7 differ");
    // Another seed is another case.
    gen_into(
        c.path(),
        &["--preset", "paper", "--seed", "8", "--count", "1"],
    );
    let tc = tree(c.path());
    assert_ne!(
        ta[Path::new("case_0/robot_0.pgm")],
        tc[Path::new("case_0/robot_0.pgm")]
    );
}

#[test]
fn written_maps_and_truth_are_the_simulators() {
    let dir = tempfile::tempdir().unwrap();
    gen_into(dir.path(), &["--preset", "paper", "--seed", "3"]);
    let case = generate_case(&CaseConfig::paper(), 3).unwrap();
    let case_dir = dir.path().join("case_0");
    for (i, r) in case.robots.iter().enumerate() {
        let yaml = case_dir.join(format!("robot_{i}.yaml"));
        let read = load_map(&yaml, &LoadOptions::default()).unwrap();
        assert_eq!(
            (read.width(), read.height()),
            (r.map.width(), r.map.height())
        );
        assert_eq!(read.resolution(), r.map.resolution());
        for y in 0..read.height() {
            for x in 0..read.width() {
                assert_eq!(
                    read.state(x, y),
                    r.map.state(x, y),
                    "robot {i} cell ({x}, {y})"
                );
            }
        }
    }
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(case_dir.join("truth.json")).unwrap()).unwrap();
    assert_eq!(truth["seed"], 3);
    let pair = truth["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["a"] == 0 && p["b"] == 1)
        .expect("pair (0, 1) in truth.json");
    let t: grid_core::Rigid2 = serde_json::from_value(pair["transform"].clone()).unwrap();
    assert_eq!(t, case.truth(0, 1));
    assert_eq!(truth["achieved_overlap"], case.achieved_overlap);
}

#[test]
fn a_real_map_is_the_world() {
    let world =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/maps/tb3_world/tb3_world.yaml");
    let dir = tempfile::tempdir().unwrap();
    gen_into(
        dir.path(),
        &[
            "--preset",
            "paper",
            "--world",
            world.to_str().unwrap(),
            "--overlap",
            "0.5",
        ],
    );
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("case_0/truth.json")).unwrap())
            .unwrap();
    let source = load_map(&world, &LoadOptions::default()).unwrap();
    assert_eq!(truth["world"]["kind"], "grid");
    assert_eq!(truth["world"]["width"], source.width());
    assert_eq!(truth["world"]["height"], source.height());
    assert_eq!(truth["world"]["resolution"], source.resolution());
}

#[test]
fn the_mapper_is_recorded_in_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    gen_into(
        dir.path(),
        &["--preset", "paper", "--mapper", "slam-toolbox"],
    );
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("case_0/truth.json")).unwrap())
            .unwrap();
    assert_eq!(
        truth["config"]["mapper"],
        serde_json::json!({"hit_ratio": {"occupied_above": 0.1, "min_passes": 2}})
    );
    let dir = tempfile::tempdir().unwrap();
    gen_into(dir.path(), &["--preset", "paper"]);
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("case_0/truth.json")).unwrap())
            .unwrap();
    assert_eq!(
        truth["config"]["mapper"],
        serde_json::json!({"log_odds": {"free": -1.4, "occupied": 2.2, "clamp": 5.0}})
    );
}

#[test]
fn a_missing_world_map_is_named_in_the_error() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere.yaml");
    let o = xtask(&[
        "gen",
        "--out",
        dir.path().join("out").to_str().unwrap(),
        "--world",
        missing.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("nowhere.yaml"),
        "the error should name the file: {err}"
    );
    assert!(!dir.path().join("out/case_0").exists(), "no partial output");
}
