//! `mapmerge merge` through the real binary: three turned crops of a real floor merged back into
//! the floor, unrelated maps left out or refused, bad input refused with exit code 2, and
//! nothing written but what a finished merge writes.

use std::path::{Path, PathBuf};
use std::process::Output;

use grid_core::io::{LoadOptions, load_map, save_map};
use grid_core::metrics::{agreement, displacement_error, rotation_error_deg};
use grid_core::{CellState, DVec2, OccupancyGrid, Rigid2, UNKNOWN};
use tempfile::TempDir;

mod common;
use common::{fixture, transform};

/// Run `mapmerge merge args`.
fn merge(args: &[&str]) -> Output {
    common::mapmerge(&[&["merge"], args].concat())
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The cells of `floor` that `keep(x, y)` selects (the rest unknown), placed by `floor_to_map`
/// on a square canvas that holds any turn of the floor, saved as `name.yaml` in `dir`.
fn crop(
    dir: &TempDir,
    name: &str,
    floor: &OccupancyGrid,
    keep: impl Fn(usize, usize) -> bool,
    floor_to_map: Rigid2,
) -> (PathBuf, OccupancyGrid) {
    let mut c = floor.clone();
    let w = floor.width();
    for (i, cell) in c.cells_mut().iter_mut().enumerate() {
        if !keep(i % w, i / w) {
            *cell = UNKNOWN;
        }
    }
    let (w, h) = (floor.width() as f64, floor.height() as f64);
    let side = (w * w + h * h).sqrt() as usize + 20;
    let map = c.warp(&floor_to_map, side, side).unwrap();
    let path = dir.path().join(format!("{name}.yaml"));
    save_map(&map, &path).unwrap();
    (path, map)
}

/// A transform that turns the floor by `degrees` about its middle cell and puts that cell in
/// the middle of the crop's canvas. Whole-cell shifts: unturned, the crop is the floor's cells
/// moved, not resampled half a cell off.
fn turned(floor: &OccupancyGrid, degrees: f64) -> Rigid2 {
    let (w, h) = (floor.width() as f64, floor.height() as f64);
    let side = (w * w + h * h).sqrt() as usize + 20;
    let middle = DVec2::new((floor.width() / 2) as f64, (floor.height() / 2) as f64);
    let to_origin = Rigid2::new(0.0, -middle.x, -middle.y);
    let half = (side / 2) as f64;
    Rigid2::new(degrees.to_radians(), half, half).compose(&to_origin)
}

#[test]
fn three_turned_crops_of_a_real_floor_merge_back_into_the_floor() {
    let dir = TempDir::new().unwrap();
    let floor = load_map(fixture("intel_lab"), &LoadOptions::default()).unwrap();
    let (w, h) = (floor.width(), floor.height());
    // West 60 %, east 60 % turned by 30 degrees, north 60 % turned by -100 degrees: every
    // cell of the floor is in at least one crop, and each pair shares a third of the floor.
    let to = [
        turned(&floor, 0.0),
        turned(&floor, 30.0),
        turned(&floor, -100.0),
    ];
    let (a, ga) = crop(&dir, "west", &floor, |x, _| x < w * 6 / 10, to[0]);
    let (b, gb) = crop(&dir, "east", &floor, |x, _| x >= w * 4 / 10, to[1]);
    let (c, gc) = crop(&dir, "north", &floor, |_, y| y < h * 6 / 10, to[2]);
    let out = dir.path().join("team.yaml");
    let png = dir.path().join("team.png");
    let o = merge(&[
        s(&a),
        s(&b),
        s(&c),
        "-o",
        s(&out),
        "--json",
        "--debug-png",
        s(&png),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stderr.is_empty(), "no warning: {stderr}");
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // The report on disk is the one printed.
    let on_disk: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.with_extension("json")).unwrap()).unwrap();
    assert_eq!(report, on_disk);
    let maps = report["maps"].as_array().unwrap();
    assert!(maps.iter().all(|m| m["merged"] == true), "{report}");
    let pairs = report["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), 3);
    assert!(pairs.iter().all(|p| p["accepted"] == true), "{report}");

    // Each map's pose, against the truth: map k's pixel -> floor -> west crop -> merged map,
    // the last step being the reference's own pose in the report.
    let pose = |k: usize| transform(&maps[k]["transform"]);
    let reference = pose(0);
    assert_eq!(reference.theta, 0.0, "the reference is only shifted");
    for (k, g) in [(1, &gb), (2, &gc)] {
        let truth = reference.compose(&to[0]).compose(&to[k].inverse());
        let disp = displacement_error(g, &pose(k), &truth).unwrap();
        let rot = rotation_error_deg(&pose(k), &truth);
        assert!(disp < 0.5, "map {k}: {disp} px off ({rot} degrees)");
        assert!(rot < 0.1, "map {k}: {rot} degrees off");
    }

    // The merged map, read back, is the floor: its cells agree with the floor's, it covers
    // nearly all of them, and a point has the same world coordinates in it as in the west crop.
    let merged = load_map(&out, &LoadOptions::default()).unwrap();
    let floor_to_merged = reference.compose(&to[0]);
    let ag = agreement(&merged, &floor, &floor_to_merged);
    let ai = ag.acceptance_index().unwrap();
    assert!(ai > 0.97, "acceptance index {ai}");
    let known = floor.counts().free + floor.counts().occupied;
    assert!(
        ag.overlap() as f64 > 0.97 * known as f64,
        "{} of {known} floor cells covered",
        ag.overlap()
    );
    let p = DVec2::new(200.0, 300.0);
    let q = merged.world_to_pixel(ga.pixel_to_world(p));
    assert!((q - reference.apply(p)).length() < 1e-6, "{q}");
    assert_eq!(report["output"]["width"], merged.width());
    let ai_report = report["acceptance_index"].as_f64().unwrap();
    assert!(ai_report > 0.9, "{ai_report}");
    let img = image::open(&png).unwrap();
    assert_eq!(
        (img.width() as usize, img.height() as usize),
        (merged.width(), merged.height())
    );
}

/// Map pixel `p` of a map of `height` rows at `own` m/cell to its pixel once resampled to
/// `to` m/cell with `resampled_height` rows (the lower-left corner kept).
fn resampled_pixel(p: DVec2, own: f64, height: usize, to: f64, resampled_height: usize) -> DVec2 {
    let s = own / to;
    DVec2::new(
        (p.x + 0.5) * s - 0.5,
        resampled_height as f64 - 0.5 - (height as f64 - 0.5 - p.y) * s,
    )
}

/// The Intel lab's west 60 % and east 60 % (turned by 30 degrees), saved as `west.yaml` and
/// `east.yaml` in `dir`: the two crops, each as (path, grid), the floor's resolution and the
/// truth (the east crop's pixels onto the west crop's).
struct WestEast {
    west: (PathBuf, OccupancyGrid),
    east: (PathBuf, OccupancyGrid),
    resolution: f64,
    truth: Rigid2,
}

fn west_east(dir: &TempDir) -> WestEast {
    let floor = load_map(fixture("intel_lab"), &LoadOptions::default()).unwrap();
    let w = floor.width();
    let to = [turned(&floor, 0.0), turned(&floor, 30.0)];
    WestEast {
        west: crop(dir, "west", &floor, |x, _| x < w * 6 / 10, to[0]),
        east: crop(dir, "east", &floor, |x, _| x >= w * 4 / 10, to[1]),
        resolution: floor.resolution(),
        truth: to[0].compose(&to[1].inverse()),
    }
}

#[test]
fn maps_of_other_resolutions_are_resampled_to_the_first_ones() {
    let dir = TempDir::new().unwrap();
    let crops = west_east(&dir);
    let (a, gb) = (&crops.west.0, &crops.east.1);
    // The east crop as a finer robot would map it (0.05 m/cell, each cell four), and as a
    // coarser one would (0.2 m/cell, the highest occupancy of each four cells). Measured:
    // 0.12 and 0.31 px off (in the merged map's cells), the frame 0.011 and 0.051 m.
    let r = crops.resolution;
    for (name, res, bound_px) in [("east_fine", r / 2.0, 0.5), ("east_coarse", r * 2.0, 1.5)] {
        let gk = gb.resample(res).unwrap();
        let path = dir.path().join(format!("{name}.yaml"));
        save_map(&gk, &path).unwrap();
        let out = dir.path().join(format!("{name}_team.yaml"));
        let o = merge(&[s(a), s(&path), "-o", s(&out), "--json"]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{stderr}");
        assert_eq!(
            stderr.trim_end(),
            format!(
                "mapmerge: note: {}: resampled from {res} to {r} m/cell, the resolution of {}",
                path.display(),
                a.display()
            )
        );
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let merged = load_map(&out, &LoadOptions::default()).unwrap();
        assert_eq!(merged.resolution(), r);
        let maps = report["maps"].as_array().unwrap();
        assert_eq!(maps[1]["resolution"], res);
        let t = &maps[1]["transform"];
        let scale = t["scale"].as_f64().unwrap();
        assert_eq!(
            (maps[0]["transform"]["scale"].as_f64(), scale),
            (Some(1.0), res / r)
        );
        // The report's transform takes the map's own pixels to the merged map's:
        // `scale R x + t`. Against the truth, at the map's known cells: own pixel -> the crop
        // at 0.1 m/cell -> floor -> west crop -> merged map.
        let pose = transform(t);
        let reference = transform(&maps[0]["transform"]);
        let truth = reference.compose(&crops.truth);
        let (mut sum, mut n) = (0.0, 0usize);
        for y in (0..gk.height()).step_by(3) {
            for x in (0..gk.width()).step_by(3) {
                if gk.state(x, y) == CellState::Unknown {
                    continue;
                }
                let p = DVec2::new(x as f64, y as f64);
                let got =
                    DVec2::new(pose.tx, pose.ty) + scale * DVec2::from_angle(pose.theta).rotate(p);
                let in_crop = resampled_pixel(p, res, gk.height(), r, gb.height());
                sum += (got - truth.apply(in_crop)).length();
                n += 1;
            }
        }
        let disp = sum / n as f64;
        assert!(disp < bound_px, "{name}: {disp} px off");
        // The map's frame in the merged frame: where its world origin lands, and its yaw.
        let world = &maps[1]["world"];
        let own = resampled_pixel(
            gk.world_to_pixel(DVec2::ZERO),
            res,
            gk.height(),
            r,
            gb.height(),
        );
        let in_merged = merged.pixel_to_world(truth.apply(own));
        let origin = DVec2::new(world["x"].as_f64().unwrap(), world["y"].as_f64().unwrap());
        assert!(
            (origin - in_merged).length() < bound_px * r,
            "{name}: frame at {origin}, truth {in_merged}"
        );
        // The text report shows the scale too.
        let text_out = dir.path().join(format!("{name}_text.yaml"));
        let o = merge(&[s(a), s(&path), "-o", s(&text_out)]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            text.contains(&format!(", scale {scale}), weight")),
            "{text}"
        );
        let yaw_err = grid_core::wrap_angle(world["yaw"].as_f64().unwrap() + truth.theta);
        assert!(
            yaw_err.abs().to_degrees() < 0.2,
            "{name}: yaw {yaw_err} off"
        );
    }
}

/// A map's pixel `p` taken to the merged map's pixels by its report entry's transform
/// (`scale R(theta) p + t`).
fn to_merged(entry: &serde_json::Value, p: DVec2) -> DVec2 {
    let t = &entry["transform"];
    let scale = t["scale"].as_f64().unwrap();
    let pose = transform(t);
    DVec2::new(pose.tx, pose.ty) + scale * DVec2::from_angle(pose.theta).rotate(p)
}

#[test]
fn the_merged_map_can_have_another_resolution_than_the_first_one() {
    let dir = TempDir::new().unwrap();
    let crops = west_east(&dir);
    let ((a, ga), gb, r) = (&crops.west, &crops.east.1, crops.resolution);
    // The east crop mapped at 0.05 m/cell; the merged map at that resolution, so the first
    // map is the one resampled.
    let fine = gb.resample(r / 2.0).unwrap();
    let path = dir.path().join("east_fine.yaml");
    save_map(&fine, &path).unwrap();
    let out = dir.path().join("fine_team.yaml");
    let o = merge(&[
        s(a),
        s(&path),
        "-o",
        s(&out),
        "--json",
        "--output-resolution",
        "0.05",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "mapmerge: note: {}: resampled from {r} to 0.05 m/cell, the --output-resolution",
            a.display()
        )
    );
    let merged = load_map(&out, &LoadOptions::default()).unwrap();
    assert_eq!(merged.resolution(), 0.05);
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let maps = report["maps"].as_array().unwrap();
    assert_eq!(maps[0]["transform"]["scale"].as_f64(), Some(2.0));
    assert_eq!(maps[1]["transform"]["scale"].as_f64(), Some(1.0));
    // The first map's cells keep their world coordinates.
    let p = DVec2::new(200.0, 300.0);
    let q = merged.world_to_pixel(ga.pixel_to_world(p));
    assert!((q - to_merged(&maps[0], p)).length() < 1e-6, "{q}");
    // The east map's known cells land where the truth puts them: its own pixel -> the crop at
    // 0.1 m/cell -> floor -> west crop -> merged map.
    let truth = crops.truth;
    let (mut sum, mut n) = (0.0, 0usize);
    for y in (0..fine.height()).step_by(3) {
        for x in (0..fine.width()).step_by(3) {
            if fine.state(x, y) == CellState::Unknown {
                continue;
            }
            let p = DVec2::new(x as f64, y as f64);
            let in_crop = resampled_pixel(p, r / 2.0, fine.height(), r, gb.height());
            let want = to_merged(&maps[0], truth.apply(in_crop));
            sum += (to_merged(&maps[1], p) - want).length();
            n += 1;
        }
    }
    // In the merged map's cells of 0.05 m (measured: 0.17).
    let disp = sum / n as f64;
    assert!(disp < 0.5, "{disp} px off");
}

#[test]
fn the_reference_can_be_any_of_the_maps() {
    let dir = TempDir::new().unwrap();
    let crops = west_east(&dir);
    let ((a, ga), b) = (&crops.west, &crops.east.0);
    let out = dir.path().join("east_frame.yaml");
    // The east crop by another path to the same file.
    let east_too = format!("{}/./east.yaml", dir.path().display());
    let o = merge(&[
        s(a),
        s(b),
        "-o",
        s(&out),
        "--json",
        "--reference",
        &east_too,
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["reference"], s(b));
    let maps = report["maps"].as_array().unwrap();
    // The east crop is only shifted, and its frame is the merged map's.
    let reference = transform(&maps[1]["transform"]);
    assert_eq!(reference.theta, 0.0);
    for key in ["x", "y", "yaw"] {
        let v = maps[1]["world"][key].as_f64().unwrap();
        assert!(v.abs() < 1e-9, "{key} {v}");
    }
    let truth = reference.compose(&crops.truth.inverse());
    let pose = transform(&maps[0]["transform"]);
    let disp = displacement_error(ga, &pose, &truth).unwrap();
    assert!(disp < 0.5, "west crop {disp} px off");
    // The text report marks it.
    let o = merge(&[
        s(a),
        s(b),
        "-o",
        s(&dir.path().join("text.yaml")),
        "--reference",
        s(b),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains(&format!("  {} (reference): ", s(b))),
        "{text}"
    );
    // A reference that is not one of the maps.
    let o = merge(&[s(a), s(b), "-o", s(&out), "--reference", "nope.yaml"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim_end(),
        "mapmerge: error: nope.yaml: --reference must be one of the maps given"
    );
}

/// Each pair's status in a merge report, in the report's order.
fn statuses(report: &serde_json::Value) -> Vec<&str> {
    report["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["status"].as_str().unwrap())
        .collect()
}

/// Whether each map of a merge report was merged, in the report's order.
fn merged_flags(report: &serde_json::Value) -> Vec<bool> {
    report["maps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["merged"].as_bool().unwrap())
        .collect()
}

#[test]
fn a_map_that_shares_nothing_with_the_first_is_placed_through_another() {
    let dir = TempDir::new().unwrap();
    let floor = load_map(fixture("intel_lab"), &LoadOptions::default()).unwrap();
    let w = floor.width();
    // West 45 %, middle 30-75 %, east 60-100 %: the west and east crops share no cell.
    let to = [
        turned(&floor, 0.0),
        turned(&floor, 75.0),
        turned(&floor, 160.0),
    ];
    let (a, _) = crop(&dir, "west", &floor, |x, _| x < w * 45 / 100, to[0]);
    let (b, _) = crop(
        &dir,
        "middle",
        &floor,
        |x, _| (w * 30 / 100..w * 75 / 100).contains(&x),
        to[1],
    );
    let (c, gc) = crop(&dir, "east", &floor, |x, _| x >= w * 60 / 100, to[2]);
    // Pairs in order (west, middle), (west, east), (middle, east). The west and east crops
    // share nothing, and their pair is declined: the best placement found (90 degrees and 352
    // px off, lift 0.66, on the lab's repeated offices) has each crop put 10.6 % or more of
    // its walls in the other's free space, where walls this clean allow 3.9 %
    // (`mapmerge::verify::CleanWalls`).
    // The east crop is placed through the middle one.
    let out = dir.path().join("chain.yaml");
    let o = merge(&[s(&a), s(&b), s(&c), "-o", s(&out), "--json"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(statuses(&report), ["tree", "declined", "tree"], "{report}");
    let why = report["pairs"][1]["reason"].as_str().unwrap();
    assert!(why.starts_with("contradicted: "), "{why}");
    assert!(why.contains("where maps with walls this clean"), "{why}");
    // `--no-clean-walls` lifts that bar; the placement shares under a quarter of the smaller
    // crop's known cells at a loose fit, and the rule for small overlaps declines it too
    // (`mapmerge::verify::SmallOverlap`). `--min-overlap 0.15` holds every placement to 15 %
    // and no more, and then the pair is answered: wrongly, a quarter turn off, which is what
    // the bars are for.
    let o = common::mapmerge(&["estimate", s(&a), s(&c), "--json", "--no-clean-walls"]);
    assert_eq!(o.status.code(), Some(3));
    let declined: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let why = declined["reason"].as_str().unwrap();
    assert!(why.starts_with("sliver: "), "{why}");
    let o = common::mapmerge(&[
        "estimate",
        s(&a),
        s(&c),
        "--json",
        "--no-clean-walls",
        "--min-overlap",
        "0.15",
    ]);
    assert_eq!(o.status.code(), Some(0));
    let answer: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let truth = to[0].compose(&to[2].inverse());
    let off = rotation_error_deg(&transform(&answer["transform"]), &truth);
    assert!((85.0..95.0).contains(&off), "{off} degrees off");
    let maps = &report["maps"];
    let reference = transform(&maps[0]["transform"]);
    let truth = reference.compose(&to[0]).compose(&to[2].inverse());
    let pose = transform(&maps[2]["transform"]);
    let disp = displacement_error(&gc, &pose, &truth).unwrap();
    assert!(disp < 0.5, "east crop {disp} px off");

    // With the lift bar at 1, the two accepted pairs are set aside as weak: no map is linked
    // to the first, so nothing is written (exit 3).
    let with_bar = |out: &Path, bar: &str| {
        merge(&[
            s(&a),
            s(&b),
            s(&c),
            "-o",
            s(out),
            "--json",
            "--min-lift",
            bar,
        ])
    };
    let out = dir.path().join("weak.yaml");
    let o = with_bar(&out, "1");
    assert_eq!(o.status.code(), Some(3));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(statuses(&report), ["weak", "declined", "weak"], "{report}");
    assert!(!out.exists() && !out.with_extension("json").exists());
    // The middle crop's reason names its weak pair with the first and the bar that uses it;
    // the east crop's weak pair is with the middle one, so its reason names the chain through
    // the middle crop and the bar that places it: the chain's lower lift. The report's reason
    // gives the bar that places both.
    let lift = report["pairs"][0]["confidence"].as_f64().unwrap();
    let chain = lift.min(report["pairs"][2]["confidence"].as_f64().unwrap());
    let bar = |l: f64| (l * 100.0).floor() / 100.0;
    let unlinked = format!(
        "no pair accepted at wall lift 1 or more links it to {}",
        a.display()
    );
    assert_eq!(
        report["maps"][1]["reason"],
        format!(
            "{unlinked}; its pair with {} was accepted at wall lift {lift:.3}, below --min-lift \
             1: --min-lift {} uses it",
            a.display(),
            bar(lift)
        )
    );
    assert_eq!(
        report["maps"][2]["reason"],
        format!(
            "{unlinked}; pairs accepted at wall lift {chain:.3} or more link it to {} through \
             {}: --min-lift {} places it",
            a.display(),
            b.display(),
            bar(chain)
        )
    );
    assert_eq!(
        report["reason"],
        format!(
            "no map could be placed in {}'s frame: no pair with it was accepted at wall lift 1 \
             or more; --min-lift {} places the 2 maps that accepted pairs link to it",
            a.display(),
            bar(chain)
        )
    );
    // That bar does place both.
    let o = with_bar(&dir.path().join("chain.yaml"), &bar(chain).to_string());
    assert_eq!(o.status.code(), Some(0));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(merged_flags(&report), [true, true, true], "{report}");
}

#[test]
fn a_map_that_overlaps_no_other_is_left_out_or_nothing_is_written() {
    let dir = TempDir::new().unwrap();
    let floor = load_map(fixture("wpi_ilab"), &LoadOptions::default()).unwrap();
    let other = load_map(fixture("aws_small_house"), &LoadOptions::default()).unwrap();
    let w = floor.width();
    let (a, _) = crop(&dir, "a", &floor, |x, _| x < w * 3 / 4, turned(&floor, 0.0));
    let (b, _) = crop(&dir, "b", &floor, |x, _| x >= w / 4, turned(&floor, 30.0));
    let (c, _) = crop(&dir, "c", &other, |_, _| true, turned(&other, 0.0));

    // Two of three: merged, with a warning naming the third.
    let out = dir.path().join("ab.yaml");
    let o = merge(&[s(&a), s(&b), s(&c), "-o", s(&out), "--json"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "mapmerge: warning: {}: not merged: no pair accepted at wall lift 0.75 or more links it to {}",
            c.display(),
            a.display()
        )
    );
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(merged_flags(&report), [true, true, false]);
    assert!(report["maps"][2]["transform"].is_null());
    assert!(out.exists() && out.with_extension("pgm").exists());

    // The first map overlaps none: exit 3, and nothing is written. The two that link to each
    // other are named, with the flag that merges them.
    let out = dir.path().join("none.yaml");
    let o = merge(&[s(&c), s(&a), s(&b), "-o", s(&out), "--json"]);
    assert_eq!(o.status.code(), Some(3));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(report["output"].is_null());
    let linked = format!(
        "{} and {} link to each other: --reference {} merges them",
        a.display(),
        b.display(),
        a.display()
    );
    assert_eq!(
        report["reason"],
        format!(
            "no map could be placed in {}'s frame: every pair with it was declined; {linked}",
            c.display()
        )
    );
    let reasons: Vec<&str> = report["maps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["reason"].as_str().unwrap())
        .collect();
    let unlinked = format!(
        "no pair accepted at wall lift 0.75 or more links it to {}; {linked}",
        c.display()
    );
    assert_eq!(
        reasons,
        [
            "the reference map: no other map could be placed in its frame",
            &unlinked,
            &unlinked
        ]
    );
    // The pairs of the floor with the house: declined with no placement passing, each with
    // the hint that names the deeper search; the floor's own pair, accepted, without it.
    let pairs = report["pairs"].as_array().unwrap();
    let hinted: Vec<bool> = pairs
        .iter()
        .map(|p| {
            p["hint"]
                .as_str()
                .is_some_and(|h| h.contains("--deep-screen"))
        })
        .collect();
    assert_eq!(hinted, [true, true, false], "{report}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with("none") || n.starts_with(".none"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// `mapmerge merge args` refused ([`common::fails`]): its one stderr line.
fn fails(args: &[&str]) -> String {
    common::fails(&[&["merge"], args].concat())
}

#[test]
fn bad_input_is_refused_with_exit_2_and_inputs_are_never_overwritten() {
    let dir = TempDir::new().unwrap();
    // Copies, so that a failure cannot spoil the fixtures.
    let a = dir.path().join("wpi_ilab.yaml");
    let image = dir.path().join("wpi_ilab.pgm");
    std::fs::copy(fixture("wpi_ilab"), &a).unwrap();
    std::fs::copy(fixture("wpi_ilab").with_extension("pgm"), &image).unwrap();
    let before = (std::fs::read(&a).unwrap(), std::fs::read(&image).unwrap());
    let a_s = s(&a);
    let out = dir.path().join("out.yaml");
    let out_s = s(&out);

    let err = fails(&[a_s, "-o", out_s]);
    assert!(err.contains("MAP"), "{err}");
    let err = fails(&[a_s, a_s, "-o", a_s]);
    assert_eq!(
        err,
        format!(
            "mapmerge: error: {a_s}: --output would overwrite an input map; choose another file"
        )
    );
    // The output's PGM would be the image an input YAML names.
    let err = fails(&[a_s, a_s, "-o", s(&dir.path().join("wpi_ilab.yml"))]);
    assert_eq!(
        err,
        format!(
            "mapmerge: error: {}: --output's PGM would overwrite an input map; choose another file",
            image.display()
        )
    );
    let err = fails(&[a_s, a_s, "-o", s(&dir.path().join("out.pgm"))]);
    assert!(err.contains("must be a .yaml or .yml file"), "{err}");
    let nowhere = dir.path().join("no_such_dir").join("out.yaml");
    let err = fails(&[a_s, a_s, "-o", s(&nowhere)]);
    assert!(err.contains("does not exist"), "{err}");
    let err = fails(&[a_s, a_s, "-o", out_s, "--weights", "1,NaN"]);
    assert!(
        err.contains("must be a finite number greater than 0"),
        "{err}"
    );
    let err = fails(&[a_s, a_s, "-o", out_s, "--weights", "1,2,3"]);
    assert!(err.contains("--weights gives 3 values for 2 maps"), "{err}");
    let err = fails(&[a_s, a_s, "-o", out_s, "--min-lift", "NaN"]);
    assert!(err.contains("must be a number between 0 and 1"), "{err}");
    let err = fails(&[a_s, a_s, "-o", out_s, "--rule", "max"]);
    assert!(err.contains("unknown fusion rule `max`"), "{err}");
    let err = fails(&[a_s, a_s, "-o", out_s, "--debug-png", out_s]);
    assert!(
        err.contains("--debug-png names one of the merged map's own files"),
        "{err}"
    );
    // The same file by another name.
    let pgm_too = format!("{}/./out.pgm", dir.path().display());
    let err = fails(&[a_s, a_s, "-o", out_s, "--debug-png", &pgm_too]);
    assert!(
        err.contains("--debug-png names one of the merged map's own files"),
        "{err}"
    );
    // A map so coarse that resampling it to the first one's cells would make a huge grid.
    let coarse =
        OccupancyGrid::from_cells(20, 10, 100.0, Default::default(), vec![0; 200]).unwrap();
    let coarse_path = dir.path().join("coarse.yaml");
    save_map(&coarse, &coarse_path).unwrap();
    let err = fails(&[a_s, s(&coarse_path), "-o", out_s]);
    assert_eq!(
        err,
        format!(
            "mapmerge: error: {}: cannot resample it to 0.05 m/cell: the map would be 40000 x \
             20000 cells at 0.05 m/cell, more than 2^28 (268435456)",
            coarse_path.display()
        )
    );
    let missing = dir.path().join("nope.yaml");
    let err = fails(&[a_s, s(&missing), "-o", out_s]);
    assert!(
        err.starts_with(&format!("mapmerge: error: {}: ", missing.display())),
        "{err}"
    );
    let blank = OccupancyGrid::new(20, 10, 0.05, Default::default()).unwrap();
    let blank_path = dir.path().join("blank.yaml");
    save_map(&blank, &blank_path).unwrap();
    let err = fails(&[a_s, s(&blank_path), "-o", out_s]);
    assert!(err.contains("every cell is unknown"), "{err}");

    assert_eq!(
        (std::fs::read(&a).unwrap(), std::fs::read(&image).unwrap()),
        before
    );
    assert!(!out.exists());
}

#[test]
fn a_map_merged_with_itself_is_itself() {
    let dir = TempDir::new().unwrap();
    let floor = load_map(fixture("wpi_ilab"), &LoadOptions::default()).unwrap();
    let out = dir.path().join("twice.yaml");
    let f = s(&fixture("wpi_ilab")).to_string();
    let o = merge(&[&f, &f, "-o", s(&out), "--json"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let merged = load_map(&out, &LoadOptions::default()).unwrap();
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (x0, y0) = (
        -report["maps"][0]["transform"]["tx"].as_f64().unwrap(),
        -report["maps"][0]["transform"]["ty"].as_f64().unwrap(),
    );
    // Every known cell of the floor, exactly, at its place (the two copies agree everywhere).
    for y in 0..floor.height() {
        for x in 0..floor.width() {
            let (u, v) = (x as f64 - x0, y as f64 - y0);
            let got = merged.state(u as usize, v as usize);
            if floor.state(x, y) != CellState::Unknown {
                assert_eq!(got, floor.state(x, y), "({x}, {y})");
            }
        }
    }
    assert_eq!(report["acceptance_index"], 1.0);
}
