//! Measures the design choices of ransac-rigid on synthetic correspondence sets with known
//! truth: MSAC versus inlier counting, and SIFT-orientation pruning of 2-point hypotheses.
//! Run: `cargo run --release -p ransac-rigid --example measure_ransac`

use std::f64::consts::PI;
use std::time::Instant;

use grid_core::{Correspondence, DVec2, EvidenceKind, Orientation, Rigid2};
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ransac_rigid::{RansacConfig, Scoring, estimate_rigid};

fn gauss<R: Rng>(rng: &mut R) -> f64 {
    let u: f64 = rng.random_range(f64::EPSILON..1.0);
    let v: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (2.0 * PI * v).cos()
}

/// SIFT-like correspondences over a 2048² map: inliers with 1 px noise and a directed
/// orientation that is right (10° noise) 85 % of the time, outliers anywhere.
fn scene(seed: u64, n: usize, inliers: usize) -> (Rigid2, Vec<Correspondence>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let truth = Rigid2::new(
        rng.random_range(-PI..PI),
        rng.random_range(-500.0..500.0),
        rng.random_range(-500.0..500.0),
    );
    let data = (0..n)
        .map(|i| {
            let b = DVec2::new(rng.random_range(0.0..2048.0), rng.random_range(0.0..2048.0));
            let inlier = i < inliers;
            let a = if inlier {
                truth.apply(b) + DVec2::new(gauss(&mut rng), gauss(&mut rng))
            } else {
                truth.apply(DVec2::new(
                    rng.random_range(0.0..2048.0),
                    rng.random_range(0.0..2048.0),
                ))
            };
            let ob = rng.random_range(-PI..PI);
            let oa = if inlier && rng.random::<f64>() < 0.85 {
                ob + truth.theta + 10f64.to_radians() * gauss(&mut rng)
            } else {
                rng.random_range(-PI..PI)
            };
            Correspondence {
                a,
                b,
                orientation: Some(Orientation {
                    a: oa,
                    b: ob,
                    period: 2.0 * PI,
                }),
                weight: if inlier {
                    rng.random_range(0.3..1.0)
                } else {
                    rng.random_range(0.1..0.9)
                },
                kind: EvidenceKind::Intensity,
            }
        })
        .collect();
    (truth, data)
}

/// CPU time of this thread in seconds (Linux), so the numbers hold on a loaded machine; falls
/// back to wall time elsewhere.
fn cpu_seconds(wall: &Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or_else(|| wall.elapsed().as_secs_f64(), |ns| ns * 1e-9)
}

fn displacement(est: &Rigid2, truth: &Rigid2) -> f64 {
    let mut sum = 0.0;
    for i in 0..=8 {
        for j in 0..=8 {
            let p = DVec2::new(i as f64, j as f64) * 256.0;
            sum += (est.apply(p) - truth.apply(p)).length();
        }
    }
    sum / 81.0
}

fn run(label: &str, cfg: &RansacConfig, n: usize, inliers: usize, trials: u64) {
    let (mut ok, mut err_sum, mut iters, mut secs) = (0, 0.0, 0usize, 0.0);
    for t in 0..trials {
        let (truth, data) = scene(t, n, inliers);
        let wall = Instant::now();
        let start = cpu_seconds(&wall);
        let r = estimate_rigid(&data, &RansacConfig { seed: t, ..*cfg });
        secs += cpu_seconds(&wall) - start;
        if let Ok(r) = r {
            iters += r.iterations;
            let d = displacement(&r.model, &truth);
            if d <= 3.0 {
                ok += 1;
                err_sum += d;
            }
        }
    }
    println!(
        "{label:<34} n={n:<5} inliers={inliers:<4} success {ok:>3}/{trials}  mean disp (successes) {:.3} px  mean iterations {:>5}  mean CPU time {:.2} ms",
        err_sum / ok.max(1) as f64,
        iters / trials as usize,
        1e3 * secs / trials as f64
    );
}

/// Points along a few axis-aligned walls of an 800² map, 0.5 px noise.
fn wall_points(rng: &mut ChaCha8Rng, n: usize) -> Vec<DVec2> {
    let walls: Vec<(DVec2, DVec2)> = (0..rng.random_range(3..7))
        .map(|_| {
            let p = DVec2::new(rng.random_range(0.0..800.0), rng.random_range(0.0..800.0));
            let d = if rng.random::<bool>() {
                DVec2::X
            } else {
                DVec2::Y
            };
            (p, p + d * rng.random_range(100.0..500.0))
        })
        .collect();
    (0..n)
        .map(|_| {
            let (p, q) = walls[rng.random_range(0..walls.len())];
            p.lerp(q, rng.random_range(0.0..1.0)) + 0.5 * DVec2::new(gauss(rng), gauss(rng))
        })
        .collect()
}

fn plain(a: DVec2, b: DVec2) -> Correspondence {
    Correspondence {
        a,
        b,
        orientation: None,
        weight: 1.0,
        kind: EvidenceKind::Intensity,
    }
}

/// Confidence calibration: `k` true matches among `outliers` random ones, points uniform in
/// 1000² or along walls (true matches on B's walls, outliers pair wall points at random).
fn calibration(walls: bool, k: usize, outliers: usize, trials: u64) -> (usize, f64, f64) {
    let (mut high, mut min_l, mut max_l) = (0, f64::INFINITY, f64::NEG_INFINITY);
    for t in 0..trials {
        let mut rng = ChaCha8Rng::seed_from_u64(10_000 * k as u64 + t);
        let truth = Rigid2::new(
            rng.random_range(-PI..PI),
            rng.random_range(-300.0..300.0),
            50.0,
        );
        let pts_b = if walls {
            wall_points(&mut rng, k + outliers)
        } else {
            (0..k + outliers)
                .map(|_| DVec2::new(rng.random_range(0.0..1000.0), rng.random_range(0.0..1000.0)))
                .collect()
        };
        let pts_a = if walls {
            wall_points(&mut rng, outliers)
        } else {
            (0..outliers)
                .map(|_| DVec2::new(rng.random_range(0.0..1000.0), rng.random_range(0.0..1000.0)))
                .collect()
        };
        let mut data: Vec<_> = pts_b[..k]
            .iter()
            .map(|&b| {
                plain(
                    truth.apply(b) + DVec2::new(gauss(&mut rng), gauss(&mut rng)),
                    b,
                )
            })
            .collect();
        // In the walls case A's outlier points come from A's own walls: the truth maps B's
        // walls elsewhere, so outliers are structured but unrelated.
        data.extend(pts_a.iter().zip(&pts_b[k..]).map(|(&a, &b)| plain(a, b)));
        let (conf, l) = match estimate_rigid(
            &data,
            &RansacConfig {
                seed: t,
                ..Default::default()
            },
        ) {
            Ok(r) if displacement(&r.model, &truth) <= 3.0 => (r.confidence, r.log10_nfa),
            Ok(r) => (0.0, r.log10_nfa.max(0.0)),
            Err(_) => (0.0, f64::INFINITY),
        };
        high += usize::from(conf > 0.9);
        min_l = min_l.min(l);
        max_l = max_l.max(l);
    }
    (high, min_l, max_l)
}

fn main() {
    println!(
        "confidence calibration: share of runs right (<= 3 px) with confidence > 0.9, log10 NFA range"
    );
    for walls in [false, true] {
        for &outliers in &[20, 100, 300, 1000] {
            let row: Vec<String> = [0usize, 3, 4, 5, 6, 8, 10]
                .iter()
                .map(|&k| {
                    let (h, lo, hi) = calibration(walls, k, outliers, 50);
                    format!("k={k}: {h:>2}/50 [{lo:.1}, {hi:.1}]")
                })
                .collect();
            println!(
                "{} outliers={outliers:<5} {}",
                if walls { "walls  " } else { "uniform" },
                row.join("  ")
            );
        }
    }

    let base = RansacConfig::default();
    let count = RansacConfig {
        scoring: Scoring::InlierCount,
        ..base
    };
    let prune = RansacConfig {
        orientation_prune_deg: Some(30.0),
        ..base
    };
    for &(n, k) in &[
        (300, 60),
        (1000, 40),
        (2000, 400),
        (2000, 60),
        (2000, 30),
        (2000, 15),
        (2000, 10),
    ] {
        run("msac (default)", &base, n, k, 100);
        run("inlier count", &count, n, k, 100);
        run("msac + orientation prune 30 deg", &prune, n, k, 100);
    }
}
