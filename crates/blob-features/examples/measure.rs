//! Measurements behind the defaults of `BlobConfig` and `MatchConfig`, on synthetic pairs (a
//! scattered-shape map and a rigidly warped copy).
//!
//! `cargo run --release -p blob-features --example measure`

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

fn main() {
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
