//! Sub-pixel refinement of a hypothesis: symmetric point-to-line ICP of each map's walls onto
//! the other's.
//!
//! RANSAC's answer is fixed by a few keypoints whose positions carry the blur of the scale
//! space; the walls themselves pin the pose down much better. Each iteration pairs every
//! sampled wall cell of B with the nearest wall cell of A (looked up in A's nearest-occupied
//! transform, no search) and every sampled wall cell of A with the nearest of B, within a
//! shrinking gate. Distances are measured along the local wall normal (point-to-line), so
//! points may slide along walls instead of dragging the pose, and residuals are weighted
//! robustly (Cauchy), so smeared walls of a noisy sensor do not bias the fit.

use grid_core::{CellState, DVec2, Rigid2};
use rayon::prelude::*;

use crate::verify::{PreparedMap, strided};

/// Parameters of the refinement, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineConfig {
    /// Pairing gate of the first iteration, in pixels. Default 6.
    pub initial_gate_px: f32,
    /// Gate the schedule shrinks to. Default 3.
    pub final_gate_px: f32,
    /// Iterations at most. Default 30.
    pub max_iterations: usize,
    /// Scale of the Cauchy weight, in pixels. Default 0.15: a small scale lets only pairs that
    /// land on a wall pull, so the smeared band of a noisy wall does not bias the pose. Chosen
    /// by the drift of refinement started at the truth (`cargo xtask eval --suites overlap`,
    /// field `truth_refined_drift_px`): median at 0.3 overlap, disaster world 4.8 px with 1.0,
    /// 3.5 with 0.5, 1.9 with 0.2, 1.6 with 0.15; annealing the scale from 1.65 down to 0.15
    /// made it worse (4.3).
    pub robust_scale_px: f64,
    /// The refinement may move the hypothesis at most this far (pixels, at B's centroid) before
    /// it is considered diverged and the input is kept. Default 8.
    pub max_shift_px: f64,
    /// Wall cells used per map (evenly strided from the verification's samples). Default
    /// 6000: on `cargo xtask eval --suites overlap,zero,paper,real --cases 20 --seed 7` every
    /// row registered the same pairs as with all 20 000 samples (medians moved by at most
    /// 0.06 px), while maps with more walls (the 2048 x 2048 bench pair has 20 000 samples per
    /// map) refine proportionally faster.
    pub max_points: usize,
}

impl Default for RefineConfig {
    fn default() -> Self {
        Self {
            initial_gate_px: 6.0,
            final_gate_px: 3.0,
            max_iterations: 30,
            robust_scale_px: 0.15,
            max_shift_px: 8.0,
            max_points: 6000,
        }
    }
}

/// One linearised constraint: B point `p`, target point `q` in A, unit normal `n` in A.
struct Pair {
    p: DVec2,
    q: DVec2,
    n: DVec2,
}

/// Collect pairs of `from`'s walls with the nearest walls of `onto`, `to_onto` mapping `from`'s
/// pixels to `onto`'s. With `swap`, the pair is expressed the other way round (A point as
/// target, B point as source) so both directions feed one system in A's frame.
fn collect(
    from: &[DVec2],
    onto: &PreparedMap,
    to_onto: &Rigid2,
    gate: f32,
    swap: Option<&Rigid2>,
    out: &mut Vec<Pair>,
) {
    // Chunks are looked up in parallel and appended in order, so the pairs (and the sums over
    // them) do not depend on the thread count.
    let chunks: Vec<Vec<Pair>> = from
        .par_chunks(2048)
        .map(|chunk| {
            let mut part = Vec::with_capacity(chunk.len());
            collect_chunk(chunk, onto, to_onto, gate, swap, &mut part);
            part
        })
        .collect();
    for part in chunks {
        out.extend(part);
    }
}

/// [`collect`] for some of `from`'s wall samples.
fn collect_chunk(
    samples: &[DVec2],
    onto: &PreparedMap,
    to_onto: &Rigid2,
    gate: f32,
    swap: Option<&Rigid2>,
    out: &mut Vec<Pair>,
) {
    for &p in samples {
        let m = to_onto.apply(p);
        let (x, y) = (m.x.round(), m.y.round());
        if x < 0.0 || y < 0.0 {
            continue;
        }
        let (x, y) = (x as usize, y as usize);
        if onto.grid.state(x, y) == CellState::Unknown {
            continue;
        }
        let Some(((nx, ny), d)) = onto.walls.nearest(x, y) else {
            continue;
        };
        if d > gate {
            continue;
        }
        let target = DVec2::new(nx as f64, ny as f64);
        let normal = onto.normal(nx, ny).or_else(|| (m - target).try_normalize());
        let Some(normal) = normal else { continue };
        match swap {
            // from = B, onto = A: source p (B), target in A.
            None => out.push(Pair {
                p,
                q: target,
                n: normal,
            }),
            // from = A, onto = B: the B point is the target, the A point p the goal; in A's
            // frame the B point maps through `b_to_a` and the normal turns with it.
            Some(b_to_a) => out.push(Pair {
                p: target,
                q: p,
                n: DVec2::from_angle(b_to_a.theta).rotate(normal),
            }),
        }
    }
}

/// Solve the 3 x 3 system `m x = v` (symmetric positive semi-definite); `None` if singular.
fn solve3(m: [[f64; 3]; 3], v: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d.abs() < 1e-9 {
        return None;
    }
    let mut x = [0.0; 3];
    for (i, xi) in x.iter_mut().enumerate() {
        let mut mi = m;
        for r in 0..3 {
            mi[r][i] = v[r];
        }
        *xi = det(&mi) / d;
    }
    Some(x)
}

/// Refine `b_to_a` by symmetric point-to-line ICP. Returns the input when too few pairs are
/// found or the refinement wanders off.
pub fn refine(a: &PreparedMap, b: &PreparedMap, b_to_a: &Rigid2, config: &RefineConfig) -> Rigid2 {
    let mut t = *b_to_a;
    let (wa, wb) = (
        strided(&a.wall_samples, config.max_points),
        strided(&b.wall_samples, config.max_points),
    );
    let mut pairs = Vec::with_capacity(wa.len() + wb.len());
    for it in 0..config.max_iterations {
        let f = (it as f32 / (config.max_iterations.max(2) / 2) as f32).min(1.0);
        let gate = config.initial_gate_px + (config.final_gate_px - config.initial_gate_px) * f;
        let scale = config.robust_scale_px;
        pairs.clear();
        collect(&wb, a, &t, gate, None, &mut pairs);
        collect(&wa, b, &t.inverse(), gate, Some(&t), &mut pairs);
        if pairs.len() < 10 {
            break;
        }
        // Linearise about the centroid of the mapped source points: x' = x + dθ perp(x - c) + d.
        let c = pairs.iter().map(|pr| t.apply(pr.p)).sum::<DVec2>() / pairs.len() as f64;
        let (mut m, mut v) = ([[0.0; 3]; 3], [0.0; 3]);
        for pr in &pairs {
            let x = t.apply(pr.p);
            let r = pr.n.dot(x - pr.q);
            let w = 1.0 / (1.0 + (r / scale).powi(2));
            let j = [pr.n.dot((x - c).perp()), pr.n.x, pr.n.y];
            for i in 0..3 {
                for k in 0..3 {
                    m[i][k] += w * j[i] * j[k];
                }
                v[i] -= w * j[i] * r;
            }
        }
        let Some([dt, dx, dy]) = solve3(m, v) else {
            break;
        };
        // Apply the increment: rotate about c by dθ, then shift by d.
        let step = Rigid2::new(dt, 0.0, 0.0);
        let about_c = Rigid2 {
            theta: dt,
            tx: c.x - step.apply(c).x + dx,
            ty: c.y - step.apply(c).y + dy,
        };
        t = about_c.compose(&t);
        if dt.abs() < 1e-5 && dx.hypot(dy) < 1e-3 && f >= 1.0 {
            break;
        }
    }
    // Guard against a refinement that slid along a corridor to somewhere else.
    let centre = b.wall_samples.iter().copied().sum::<DVec2>() / b.wall_samples.len().max(1) as f64;
    if !(t.theta.is_finite() && t.tx.is_finite() && t.ty.is_finite())
        || (t.apply(centre) - b_to_a.apply(centre)).length() > config.max_shift_px
    {
        return *b_to_a;
    }
    t
}
