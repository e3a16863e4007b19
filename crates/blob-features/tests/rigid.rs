//! Blob correspondences between a map and a rigidly warped copy of it, against the known truth.

mod common;

use std::f64::consts::PI;

use blob_features::{BlobCorrespondences, BlobScratch, Blobs, match_blobs};
use common::{grid_with, scatter};
use grid_core::{Correspondence, CorrespondenceSource, EvidenceKind, OccupancyGrid, Rigid2};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A scattered-shape map `a`, a random rigid `truth` (B -> A) and `b = a` seen through it.
fn pair(seed: u64) -> (OccupancyGrid, OccupancyGrid, Rigid2) {
    let (w, h) = (400, 400);
    let a = grid_with(&scatter(w, h, 70, seed), w, h);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let theta = rng.random_range(-PI..PI);
    let shift = (rng.random_range(-15.0..15.0), rng.random_range(-15.0..15.0));
    // Rotation about the map centre plus a shift, so every shape stays on the canvas.
    let c = grid_core::DVec2::new(w as f64 / 2.0, h as f64 / 2.0);
    let rc = Rigid2::new(theta, 0.0, 0.0).apply(c);
    let truth = Rigid2::new(theta, c.x - rc.x + shift.0, c.y - rc.y + shift.1);
    // warp(S) gives out(p) = a(S^-1 p); we want b(p) = a(truth p).
    let b = a.warp(&truth.inverse(), w, h).unwrap();
    (a, b, truth)
}

/// Wrapped difference of two angles modulo `period`, in degrees.
fn mod_diff_deg(x: f64, period: f64) -> f64 {
    let d = x.rem_euclid(period);
    d.min(period - d).to_degrees()
}

struct Score {
    total: usize,
    within_2px: usize,
    with_orientation: usize,
    orientation_ok: usize,
}

fn score(cs: &[Correspondence], truth: &Rigid2) -> Score {
    let mut s = Score {
        total: cs.len(),
        within_2px: 0,
        with_orientation: 0,
        orientation_ok: 0,
    };
    for c in cs {
        assert_eq!(c.kind, EvidenceKind::Area);
        assert!(c.weight > 0.0 && c.weight <= 1.0, "weight {}", c.weight);
        if (truth.apply(c.b) - c.a).length() < 2.0 {
            s.within_2px += 1;
            if let Some(o) = c.orientation {
                assert_eq!(o.period, PI);
                s.with_orientation += 1;
                // theta = a - b modulo pi.
                if mod_diff_deg(o.a - o.b - truth.theta, PI) < 5.0 {
                    s.orientation_ok += 1;
                }
            }
        }
    }
    s
}

#[test]
fn warped_copy_yields_mostly_true_correspondences() {
    let source = BlobCorrespondences::default();
    let (mut total, mut good, mut with_o, mut o_ok) = (0, 0, 0, 0);
    for seed in 0..6 {
        let (a, b, truth) = pair(seed);
        let mut cs = Vec::new();
        source.correspondences(&a, &b, &mut cs);
        let s = score(&cs, &truth);
        println!(
            "seed {seed}: theta {:.1} deg, {} matches, {} within 2 px, {}/{} orientations within 5 deg",
            truth.theta.to_degrees(),
            s.total,
            s.within_2px,
            s.orientation_ok,
            s.with_orientation
        );
        // Each pair on its own must give a usable set: at least 10 true matches.
        assert!(
            s.within_2px >= 10,
            "seed {seed}: {} true matches",
            s.within_2px
        );
        total += s.total;
        good += s.within_2px;
        with_o += s.with_orientation;
        o_ok += s.orientation_ok;
    }
    let inlier = good as f64 / total as f64;
    let orient = o_ok as f64 / with_o as f64;
    println!(
        "overall {good}/{total} = {inlier:.3} within 2 px; orientation {o_ok}/{with_o} = {orient:.3}"
    );
    assert!(inlier >= 0.8, "inlier fraction {inlier}");
    assert!(orient >= 0.97, "orientation agreement {orient}");
}

#[test]
fn extract_once_match_many_equals_the_source() {
    let (a, b, _) = pair(42);
    let blobs = Blobs::default();
    let mut scratch = BlobScratch::default();
    let (mut ba, mut bb) = (Vec::new(), Vec::new());
    blobs.extract_with(&a, &mut scratch, &mut ba);
    blobs.extract_with(&b, &mut scratch, &mut bb);
    let source = BlobCorrespondences::default();
    let mut direct = Vec::new();
    source.correspondences(&a, &b, &mut direct);
    let mut reused = Vec::new();
    match_blobs(&ba, &bb, &source.matching, &mut reused);
    assert!(!direct.is_empty());
    assert_eq!(direct, reused);
}

#[test]
fn top_k_candidates_are_sorted_by_descriptor_distance() {
    let (a, b, _) = pair(7);
    let blobs = Blobs::default();
    let mut scratch = BlobScratch::default();
    let (mut ba, mut bb) = (Vec::new(), Vec::new());
    blobs.extract_with(&a, &mut scratch, &mut ba);
    blobs.extract_with(&b, &mut scratch, &mut bb);
    let m = blob_features::MatchConfig {
        candidates: 3,
        max_distance: f64::INFINITY,
        ..Default::default()
    };
    let mut cs = Vec::new();
    match_blobs(&ba, &bb[..1], &m, &mut cs);
    // One blob of B, three candidates of distinct A blobs with weights 1, 1/2, 1/3 (times the
    // reliabilities, 1 here: islands never touch unknown).
    assert_eq!(cs.len(), 3);
    let w: Vec<f64> = cs.iter().map(|c| c.weight).collect();
    assert_eq!(w, vec![1.0, 0.5, 1.0 / 3.0]);
    let d = |c: &Correspondence| {
        let ia = ba.iter().position(|x| x.shape.centroid == c.a).unwrap();
        ba[ia]
            .descriptor
            .iter()
            .zip(&bb[0].descriptor)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
    };
    assert!(d(&cs[0]) <= d(&cs[1]) && d(&cs[1]) <= d(&cs[2]));
    // The nearest equals what the k = 1 search would return without its filters.
    let nearest = ba
        .iter()
        .min_by(|x, y| {
            let dx: f64 = x
                .descriptor
                .iter()
                .zip(&bb[0].descriptor)
                .map(|(p, q)| (p - q).powi(2))
                .sum();
            let dy: f64 = y
                .descriptor
                .iter()
                .zip(&bb[0].descriptor)
                .map(|(p, q)| (p - q).powi(2))
                .sum();
            dx.total_cmp(&dy)
        })
        .unwrap();
    assert_eq!(cs[0].a, nearest.shape.centroid);
}
