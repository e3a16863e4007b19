//! Measurements behind the defaults of `BlobConfig` and `MatchConfig`, on synthetic pairs (a
//! scattered-shape map and a rigidly warped copy).
//!
//! `cargo run --release -p blob-features --example measure_blobs`

#[path = "../tests/common/mod.rs"]
mod common;

use std::f64::consts::PI;

use blob_features::{
    Blob, BlobConfig, BlobScratch, Blobs, DescriptorKind, MatchConfig, UnknownPolicy, match_blobs,
};
use grid_core::{DVec2, OccupancyGrid, Rigid2};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn pair(seed: u64) -> (OccupancyGrid, OccupancyGrid, Rigid2) {
    let (w, h) = (400, 400);
    let a = common::grid_with(&common::scatter(w, h, 70, seed), w, h);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let theta = rng.random_range(-PI..PI);
    let c = DVec2::new(w as f64 / 2.0, h as f64 / 2.0);
    let rc = Rigid2::new(theta, 0.0, 0.0).apply(c);
    let truth = Rigid2::new(
        theta,
        c.x - rc.x + rng.random_range(-15.0..15.0),
        c.y - rc.y + rng.random_range(-15.0..15.0),
    );
    let b = a.warp(&truth.inverse(), w, h).unwrap();
    (a, b, truth)
}

fn axis_err_deg(x: f64) -> f64 {
    let d = x.rem_euclid(PI);
    d.min(PI - d).to_degrees()
}

fn extract(cfg: BlobConfig, g: &OccupancyGrid) -> Vec<Blob> {
    let mut out = Vec::new();
    Blobs::new(cfg).extract_with(g, &mut BlobScratch::default(), &mut out);
    out
}

/// A P5 PGM map_server image read as trinary (tests only: 0 occupied, >= 250 free, else
/// unknown), `None` when absent or not P5.
fn read_pgm(path: &str) -> Option<OccupancyGrid> {
    let bytes = std::fs::read(path).ok()?;
    let mut fields = Vec::new();
    let mut i = 0;
    while fields.len() < 4 {
        while bytes.get(i)?.is_ascii_whitespace() {
            i += 1;
        }
        if bytes[i] == b'#' {
            while bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        let start = i;
        while !bytes.get(i)?.is_ascii_whitespace() {
            i += 1;
        }
        fields.push(String::from_utf8_lossy(&bytes[start..i]).to_string());
    }
    let (w, h): (usize, usize) = (fields[1].parse().ok()?, fields[2].parse().ok()?);
    if fields[0] != "P5" || fields[3] != "255" {
        return None;
    }
    let px = bytes.get(i + 1..i + 1 + w * h)?;
    let cells = px
        .iter()
        .map(|&v| match v {
            0 => 100,
            v if v >= 250 => 0,
            _ => grid_core::UNKNOWN,
        })
        .collect();
    OccupancyGrid::from_cells(w, h, 0.05, Default::default(), cells).ok()
}

/// Real maps: each placed on a canvas large enough to turn it, then warped by 5 random rigid
/// transforms; matches within 2 px of the truth. Skipped when /work/shared/maps is absent.
fn real_maps() {
    println!(
        "\n== real maps (/work/shared/maps), map vs. its rigidly warped copy, 5 transforms each"
    );
    for name in [
        "wpi_ilab",
        "tb3_world",
        "aws_small_house",
        "nav2_depot",
        "sunil_pair_a",
    ] {
        let Some(map) = read_pgm(&format!("/work/shared/maps/{name}/{name}.pgm")) else {
            println!("{name}: not available");
            continue;
        };
        let side = (map.width() as f64).hypot(map.height() as f64).ceil() as usize + 40;
        let off = Rigid2::new(
            0.0,
            ((side - map.width()) / 2) as f64,
            ((side - map.height()) / 2) as f64,
        );
        let a = map.warp(&off, side, side).unwrap();
        for mask in [
            blob_features::MaskKind::Occupied,
            blob_features::MaskKind::NotFreeIslands,
        ] {
            let cfg = BlobConfig {
                mask,
                ..BlobConfig::default()
            };
            let ba = extract(cfg, &a);
            let (mut good, mut total, mut o_ok, mut with_o) = (0, 0, 0, 0);
            for seed in 0..5u64 {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let theta = rng.random_range(-PI..PI);
                let c = DVec2::splat(side as f64 / 2.0);
                let rc = Rigid2::new(theta, 0.0, 0.0).apply(c);
                let truth = Rigid2::new(
                    theta,
                    c.x - rc.x + rng.random_range(-10.0..10.0),
                    c.y - rc.y + rng.random_range(-10.0..10.0),
                );
                let b = a.warp(&truth.inverse(), side, side).unwrap();
                let bb = extract(cfg, &b);
                let mut cs = Vec::new();
                match_blobs(&ba, &bb, &MatchConfig::default(), &mut cs);
                total += cs.len();
                for c in &cs {
                    if (truth.apply(c.b) - c.a).length() < 2.0 {
                        good += 1;
                        if let Some(o) = c.orientation {
                            with_o += 1;
                            if axis_err_deg(o.a - o.b - truth.theta) < 5.0 {
                                o_ok += 1;
                            }
                        }
                    }
                }
            }
            println!(
                "{name:16} {mask:?}{:w$} blobs {:4}  matches {total:4}  within 2 px {good:4} ({:.3})  orientation within 5 deg {o_ok}/{with_o}",
                "",
                ba.len(),
                good as f64 / total.max(1) as f64,
                w = 15 - format!("{mask:?}").len()
            );
        }
    }
}

/// A 2 px thick, 200 px long wall at a random angle with each cell lost with probability
/// `drop`: how many components of at least `min_area` cells it falls into, per closing radius.
fn gappy_walls() {
    println!("\n== gappy walls: components per wall (mean over 50 walls), by closing radius");
    for drop in [0.1, 0.2, 0.3] {
        let mut line = format!("cells lost {drop:.1}:");
        for r in 0..3 {
            let mut comps = 0;
            for seed in 0..50u64 {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let angle = rng.random_range(-PI..PI);
                let wall = common::Analytic::Rect {
                    cx: 150.0,
                    cy: 150.0,
                    a: 100.0,
                    b: 1.0,
                    angle,
                };
                let (w, h) = (300, 300);
                let mut cells = vec![0u8; w * h];
                wall.paint(&mut cells, w, h, 100);
                for c in cells.iter_mut() {
                    if *c == 100 && rng.random::<f64>() < drop {
                        *c = 0;
                    }
                }
                let g = OccupancyGrid::from_cells(w, h, 0.05, Default::default(), cells).unwrap();
                let cfg = BlobConfig {
                    mask: blob_features::MaskKind::Occupied,
                    close_radius: r,
                    ..BlobConfig::default()
                };
                comps += extract(cfg, &g).len();
            }
            line += &format!("  r={r}: {:.2}", comps as f64 / 50.0);
        }
        println!("{line}");
    }
}

fn main() {
    gappy_walls();
    real_maps();
    let seeds = 0..20u64;
    let pairs: Vec<_> = seeds.map(pair).collect();

    // 1. Orientation error between true partners, binned by roundness (minor/major).
    println!("== orientation error of true partners vs roundness (20 synthetic pairs)");
    let all = BlobConfig {
        round_ratio: 1.0,
        unknown: UnknownPolicy::Keep,
        ..BlobConfig::default()
    };
    let edges = [0.0, 0.3, 0.5, 0.6, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0];
    let mut bins = vec![Vec::new(); edges.len() - 1];
    for (a, b, truth) in &pairs {
        let (ba, bb) = (extract(all, a), extract(all, b));
        for x in &bb {
            let pa = truth.apply(x.shape.centroid);
            if let Some(y) = ba.iter().find(|y| (y.shape.centroid - pa).length() < 2.0) {
                let r = y.shape.roundness();
                let k = edges
                    .windows(2)
                    .position(|e| r >= e[0] && r < e[1])
                    .unwrap_or(bins.len() - 1);
                let e = axis_err_deg(y.orientation.unwrap() - x.orientation.unwrap() - truth.theta);
                bins[k].push(e);
            }
        }
    }
    for (k, v) in bins.iter_mut().enumerate() {
        v.sort_by(f64::total_cmp);
        if v.is_empty() {
            continue;
        }
        let q = |f: f64| v[((v.len() - 1) as f64 * f) as usize];
        let over3 = v.iter().filter(|&&e| e > 3.0).count() as f64 / v.len() as f64;
        println!(
            "roundness [{:.2}, {:.2}): n {:4}  median {:6.2}  p90 {:6.2}  max {:6.2} deg  >3deg {:.3}",
            edges[k],
            edges[k + 1],
            v.len(),
            q(0.5),
            q(0.9),
            q(1.0),
            over3
        );
    }

    // 2. Descriptor kind x ratio x mutual: inlier fraction of the matches.
    println!("\n== descriptor / ratio / mutual: true matches (within 2 px) / all matches");
    for kind in [
        DescriptorKind::Axes,
        DescriptorKind::AxesPerimeter,
        DescriptorKind::AxesHu,
        DescriptorKind::Hu,
    ] {
        let cfg = BlobConfig {
            descriptor: kind,
            ..BlobConfig::default()
        };
        let ex: Vec<_> = pairs
            .iter()
            .map(|(a, b, t)| (extract(cfg, a), extract(cfg, b), *t))
            .collect();
        for (ratio, mutual, max_distance, candidates) in [
            (0.7, true, f64::INFINITY, 1),
            (0.8, true, f64::INFINITY, 1),
            (0.9, true, f64::INFINITY, 1),
            (1.0, true, f64::INFINITY, 1),
            (0.8, false, f64::INFINITY, 1),
            (0.8, true, 0.3, 1),
            (0.9, true, 0.3, 1),
            (0.8, true, 0.3, 3),
        ] {
            let m = MatchConfig {
                ratio,
                mutual,
                max_distance,
                candidates,
            };
            let (mut good, mut total) = (0, 0);
            for (ba, bb, t) in &ex {
                let mut cs = Vec::new();
                match_blobs(ba, bb, &m, &mut cs);
                total += cs.len();
                good += cs
                    .iter()
                    .filter(|c| (t.apply(c.b) - c.a).length() < 2.0)
                    .count();
            }
            println!(
                "{kind:?}{:w$} ratio {ratio:.1} mutual {mutual:5} max_d {max_distance:4.1} k {candidates}: {good:4}/{total:4} = {:.3}  ({:.1} true per pair)",
                "",
                good as f64 / total.max(1) as f64,
                good as f64 / ex.len() as f64,
                w = 14 - format!("{kind:?}").len()
            );
        }
    }
}
