//! Measures the design choices of ransac-rigid on synthetic correspondence sets with known
//! truth: MSAC versus inlier counting, and SIFT-orientation pruning of 2-point hypotheses.
//! Run: `cargo run --release -p ransac-rigid --example measure`

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

fn main() {
    let base = RansacConfig::default();
    let count = RansacConfig {
        scoring: Scoring::InlierCount,
        ..base
    };
    let prune = RansacConfig {
        orientation_prune_deg: Some(30.0),
        ..base
    };
    for &(n, k) in &[(300, 60), (1000, 40), (2000, 400), (2000, 60), (2000, 30)] {
        run("msac (default)", &base, n, k, 100);
        run("inlier count", &count, n, k, 100);
        run("msac + orientation prune 30 deg", &prune, n, k, 100);
    }
}
