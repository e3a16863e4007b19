//! SIFT on fixture maps and their turned copies: keypoints and matches.
//!
//! For each map: the keypoints of the map at (300, 200) on one 2048 x 2048 canvas and of the
//! map turned by 30 degrees at (900, 150) on another (the nav2 warehouse loses its bottom
//! corner to that canvas's edge), and the matches between the two. Then the matches of the
//! map against copies of itself turned about the centre of a square canvas, and how many
//! agree with the truth within 3 px. docs/EVALUATION.md ("An edge test that does not depend
//! on the edge's direction") quotes its output.
//!
//! Run: `cargo run --release -p sift-desc --example turned_copies`

use grid_core::io::{LoadOptions, load_map};
use grid_core::{CorrespondenceSource, DVec2, OccupancyGrid, Rigid2};
use sift_desc::{ScaleSpace, Sift, SiftConfig, SiftCorrespondences};

fn fixture(name: &str) -> OccupancyGrid {
    let path = format!(
        "{}/../../fixtures/maps/{name}/{name}.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    load_map(&path, &LoadOptions::default()).expect("fixture loads")
}

fn main() {
    let config = SiftConfig::default();
    let sift = Sift::new(config.clone()).expect("valid config");
    let matcher = SiftCorrespondences::new(config).expect("valid config");
    println!("map: keypoints unturned / turned by 30 degrees, matches");
    for name in ["nav2_warehouse", "uos_cic", "intel_lab"] {
        let map = fixture(name);
        let canvas = |pose: Rigid2| map.warp(&pose, 2048, 2048).expect("canvas");
        let a = canvas(Rigid2::new(0.0, 300.0, 200.0));
        let b = canvas(Rigid2::new(30f64.to_radians(), 900.0, 150.0));
        let keypoints = |g: &OccupancyGrid| {
            let mut out = Vec::new();
            let c = sift.config();
            scale_space::detect_grid(
                g,
                &c.mapping,
                &c.scale_space,
                &mut ScaleSpace::new(),
                &mut out,
            )
            .expect("valid config");
            out.len()
        };
        let mut matches = Vec::new();
        matcher.correspondences(&a, &b, &mut matches);
        println!(
            "{name}: {} / {}, {} matches",
            keypoints(&a),
            keypoints(&b),
            matches.len()
        );
    }
    println!("map, turn: matches against the turned copy, within 3 px of the truth");
    for name in ["intel_lab", "uos_cic"] {
        let map = fixture(name);
        let (w, h) = (map.width() as f64, map.height() as f64);
        let side = w.hypot(h).ceil() as usize + 8;
        let centre = DVec2::splat(side as f64 / 2.0);
        let a = map
            .warp(
                &Rigid2::new(0.0, (side as f64 - w) / 2.0, (side as f64 - h) / 2.0),
                side,
                side,
            )
            .expect("canvas");
        for deg in [0.0f64, 5.0, 15.0, 30.0, 45.0, 60.0, 90.0, 120.0, 135.0] {
            let t = centre - DVec2::from_angle(deg.to_radians()).rotate(centre);
            let a_to_b = Rigid2::new(deg.to_radians(), t.x, t.y);
            let b = a.warp(&a_to_b, side, side).expect("canvas");
            let mut out = Vec::new();
            matcher.correspondences(&a, &b, &mut out);
            let good = out
                .iter()
                .filter(|m| (a_to_b.apply(m.a) - m.b).length() < 3.0)
                .count();
            println!(
                "{name}, {deg} degrees: {} matches, {good} within 3 px",
                out.len()
            );
        }
    }
}
