//! Sub-pixel refinement of a hypothesis: symmetric point-to-line ICP of each map's walls onto
//! the other's.
//!
//! RANSAC's answer is fixed by a few keypoints whose positions carry the blur of the scale
//! space; the walls themselves pin the pose down much better. Each iteration pairs every
//! sampled wall cell of B with the nearest wall cell of A (looked up in A's nearest-occupied
//! transform, no search) and every sampled wall cell of A with the nearest of B, within a
//! shrinking gate. Distances are measured along the local wall normal (point-to-line), so
//! points may slide along walls instead of dragging the pose, and residuals are weighted
//! robustly (Cauchy), so smeared walls of a noisy sensor do not bias the fit. Each map's walls
//! may also sit a little behind the true obstacle faces (range bias), by an offset fitted with
//! the pose ([`RefineConfig::range_bias`]).

use grid_core::{DVec2, Rigid2};
use rayon::prelude::*;

use crate::verify::{PreparedMap, WallLookup, strided};

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
    /// The refinement has converged (once the gate has shrunk) when an iteration moves the
    /// paired walls by less than this, in pixels (translation plus rotation times the
    /// pairs' root-mean-square distance from their centroid), and each range-bias offset by
    /// less. Default 0.05. The test before it (a step under 0.001 px and 0.00001 rad) was
    /// almost never met: with the Cauchy weight at 0.15 px the fit creeps by about 0.03 px
    /// per iteration, and 101 of the 114 refinements of the 2048 x 2048 bench's hard pair
    /// ran all their iterations (a scratch count, 2026-12-03). With this and
    /// [`RefineConfig::coarse_points`] one refinement and scoring takes a third of the time
    /// (`cargo bench -p mapmerge --bench register`, `refine_and_score_one_placement`: 8.5
    /// -> 2.6-3.1 ms), and on the 30 % overlap rows and real floors of `cargo xtask eval`
    /// (seeds 7-9, both mappers; 640 pairs) 5 more pairs were registered and 4 fewer
    /// accepted off the truth, while of 281 zero-overlap pairs one more was accepted (5);
    /// see docs/EVALUATION.md, "ICP that stops once converged".
    pub tolerance_px: f64,
    /// Wall cells used per map while the gate shrinks (the first `max_iterations / 2`
    /// iterations, evenly strided from the `max_points`); the iterations after that, which
    /// settle the pose, use all `max_points`. `usize::MAX` uses all of them throughout.
    /// Default 1500: while the gate shrinks the refinement only brings the pose into the
    /// basin, which a quarter of the walls does as well (measured together with
    /// [`RefineConfig::tolerance_px`]).
    pub coarse_points: usize,
    /// Estimate each map's range bias jointly with the pose. A noisy range sensor mapped with
    /// an inverse sensor model pushes walls away from the side they were seen from: beams
    /// that read long clear the cells in front of the far end of the noise band (in the
    /// simulator, the wall cells of 10 % noise lidar maps lie on average 1-3 px inside the
    /// obstacles, about half of them more than 3 px: `cargo run --release -p mapsim
    /// --example wall_bias`). Two maps whose walls in the overlap were seen from different sides then
    /// disagree by the sum of their offsets. Each map gets one offset `>= 0` (pixels, at
    /// most 8), every wall point is moved by it towards its free side
    /// ([`PreparedMap::free_side`]) before it is compared, and the offsets are fitted with
    /// the pose (with a wider robust kernel, 1 px, since they are a smooth effect over many
    /// walls). The value is the weight of the Gaussian prior that pulls each offset towards
    /// 0; `None` fits no offset. Default `Some(10.0)`: on `cargo xtask eval --suites
    /// overlap --only "overlap 0.3" --cases 20 --seed 7 --range-bias W` the drift of
    /// refinement started at the truth fell from a median 1.78 / 1.52 px (disaster /
    /// indoor, no offsets) to 1.33 / 1.27 with W = 10 and 1.37 / 1.22 with W = 1, while
    /// W = 100 held the offsets back (1.47 / 1.15, and no more pairs registered).
    pub range_bias: Option<f64>,
    /// Keep the rotation fixed and refine the translation (and the offsets) only. Default
    /// false.
    pub lock_rotation: bool,
    /// Where the prior of [`Self::range_bias`] centres each offset, and where the offsets
    /// start, in pixels (clamped to the offsets' bounds; NaN counts as 0). Default 0: no bias
    /// expected. Equal offsets cancel where both maps saw a wall from the same side;
    /// elsewhere (one map saw it from one side and the other from both, or the two from
    /// opposite sides) they move the walls relative to each other, which the data cannot
    /// tell from a translation across those walls, so there the prior sets how far. Offsets held at
    /// 2.5 px (`cargo xtask eval --range-bias 1000000 --range-bias-mean 2.5`) registered more
    /// of the simulated 30 % overlap pairs but fewer pairs of the real floors, so it is not
    /// the default (docs/EVALUATION.md, "Answers that push the maps apart").
    pub range_bias_mean_px: f64,
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
            coarse_points: 1500,
            tolerance_px: 0.05,
            range_bias: Some(10.0),
            lock_rotation: false,
            range_bias_mean_px: 0.0,
        }
    }
}

/// One linearised constraint: B point `p`, target point `q` in A, unit normal `n` in A, and
/// each point's free side (B's `sb` in B's frame, A's `sa`; unit vectors or zero, see
/// [`PreparedMap::free_side`]) along which its wall is moved by its map's range-bias offset.
struct Pair {
    p: DVec2,
    sb: DVec2,
    q: DVec2,
    sa: DVec2,
    n: DVec2,
}

/// Collect pairs of `from`'s walls with the nearest walls of `onto`, `to_onto` mapping `from`'s
/// pixels to `onto`'s. With `swap`, the pair is expressed the other way round (A point as
/// target, B point as source) so both directions feed one system in A's frame. `looked` holds
/// one lookup per sample of `from`, kept from the previous iteration: a sample that lands in
/// the same cell of `onto` again reuses it instead of reading `onto`'s arrays (a cache miss
/// each on a large map; between iterations most samples stay in their cell).
fn collect(
    from: (&[(DVec2, DVec2)], f64),
    onto: &PreparedMap,
    to_onto: &Rigid2,
    gate: f32,
    swap: Option<&Rigid2>,
    looked: &mut [WallLookup],
    out: &mut Vec<Pair>,
) {
    let (from, off_from) = from;
    // Chunks are looked up in parallel and appended in order, so the pairs (and the sums over
    // them) do not depend on the thread count.
    let chunks: Vec<Vec<Pair>> = from
        .par_chunks(2048)
        .zip(looked.par_chunks_mut(2048))
        .map(|(chunk, looked)| {
            let mut part = Vec::with_capacity(chunk.len());
            collect_chunk(
                (chunk, off_from),
                onto,
                to_onto,
                gate,
                swap,
                looked,
                &mut part,
            );
            part
        })
        .collect();
    for part in chunks {
        out.extend(part);
    }
}

/// [`collect`] for some of `from`'s wall samples.
fn collect_chunk(
    from: (&[(DVec2, DVec2)], f64),
    onto: &PreparedMap,
    to_onto: &Rigid2,
    gate: f32,
    swap: Option<&Rigid2>,
    looked: &mut [WallLookup],
    out: &mut Vec<Pair>,
) {
    let (samples, off_from) = from;
    let turn = swap.map(|b_to_a| DVec2::from_angle(b_to_a.theta));
    for (&(p, sp), looked) in samples.iter().zip(looked) {
        let m = to_onto.apply(p + off_from * sp);
        let Some(i) = onto.window_index(m) else {
            continue;
        };
        if looked.index != i as u32 {
            *looked = onto.wall_lookup(i);
        }
        if !looked.has_wall() || looked.distance > gate {
            continue;
        }
        let target = DVec2::new(looked.wall[0] as f64, looked.wall[1] as f64);
        let (normal, st) = match looked.normal_and_side() {
            Some((n, side)) => (n, n * side),
            None => match (m - target).try_normalize() {
                Some(n) => (n, DVec2::ZERO),
                None => continue,
            },
        };
        match turn {
            // from = B, onto = A: source p (B), target in A.
            None => out.push(Pair {
                p,
                sb: sp,
                q: target,
                sa: st,
                n: normal,
            }),
            // from = A, onto = B: the B point is the target, the A point p the goal; in A's
            // frame the B point maps through `b_to_a` and the normal turns with it.
            Some(turn) => out.push(Pair {
                p: target,
                sb: st,
                q: p,
                sa: sp,
                n: turn.rotate(normal),
            }),
        }
    }
}

/// Solve the `N x N` system `m x = v` (symmetric positive semi-definite) by Gaussian
/// elimination with partial pivoting; `None` if (numerically) singular.
fn solve<const N: usize>(mut m: [[f64; N]; N], mut v: [f64; N]) -> Option<[f64; N]> {
    let scale = (0..N)
        .map(|i| m[i][i].abs())
        .fold(0.0, f64::max)
        .max(1e-300);
    for col in 0..N {
        let piv = (col..N).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() < 1e-12 * scale {
            return None;
        }
        m.swap(col, piv);
        v.swap(col, piv);
        let (pivot_row, pivot_v) = (m[col], v[col]);
        for (row, vr) in m.iter_mut().zip(v.iter_mut()).skip(col + 1) {
            let f = row[col] / pivot_row[col];
            for (x, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                *x -= f * p;
            }
            *vr -= f * pivot_v;
        }
    }
    let mut x = [0.0; N];
    for r in (0..N).rev() {
        let tail: f64 = (r + 1..N).map(|k| m[r][k] * x[k]).sum();
        x[r] = (v[r] - tail) / m[r][r];
    }
    Some(x)
}

/// Refine `b_to_a` by symmetric point-to-line ICP. Returns the input when too few pairs are
/// found or the refinement wanders off.
pub fn refine(a: &PreparedMap, b: &PreparedMap, b_to_a: &Rigid2, config: &RefineConfig) -> Rigid2 {
    refine_with_bias(a, b, b_to_a, config).0
}

/// [`refine`], also returning the range-bias offsets `[a, b]` (pixels) it estimated for the
/// two maps (zero when [`RefineConfig::range_bias`] is off, or the input is returned).
pub fn refine_with_bias(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    config: &RefineConfig,
) -> (Rigid2, [f64; 2]) {
    let mut t = *b_to_a;
    let mean = match config.range_bias {
        Some(_) if config.range_bias_mean_px.is_finite() => {
            config.range_bias_mean_px.clamp(0.0, MAX_OFFSET_PX)
        }
        _ => 0.0,
    };
    let (mut off_a, mut off_b) = (mean, mean);
    // Each sample with its free side (zero without the range-bias model: nothing moves).
    let sided = |m: &PreparedMap| -> Vec<(DVec2, DVec2)> {
        // Striding both lists of equal length picks the same entries of each.
        let samples = strided(&m.wall_samples, config.max_points);
        match config.range_bias {
            Some(_) => samples
                .into_iter()
                .zip(strided(&m.wall_sides, config.max_points))
                .collect(),
            None => samples.into_iter().map(|p| (p, DVec2::ZERO)).collect(),
        }
    };
    // The samples of both maps, all of them (`fine`) and the subset used while the gate
    // shrinks (`coarse`), each with one lookup per sample kept between iterations: B's
    // samples in A, A's in B.
    let levels = |wa: Vec<(DVec2, DVec2)>, wb: Vec<(DVec2, DVec2)>| Samples {
        looked_a: vec![WallLookup::NONE; wb.len()],
        looked_b: vec![WallLookup::NONE; wa.len()],
        wa,
        wb,
    };
    let (wa, wb) = (sided(a), sided(b));
    let mut coarse = levels(
        strided(&wa, config.coarse_points),
        strided(&wb, config.coarse_points),
    );
    let mut fine = levels(wa, wb);
    let all = (fine.wa.len() + fine.wb.len()).max(1) as f64;
    let mut pairs = Vec::with_capacity(fine.wa.len() + fine.wb.len());
    for it in 0..config.max_iterations {
        let f = (it as f32 / (config.max_iterations.max(2) / 2) as f32).min(1.0);
        let gate = config.initial_gate_px + (config.final_gate_px - config.initial_gate_px) * f;
        let scale = config.robust_scale_px;
        let level = if f < 1.0 { &mut coarse } else { &mut fine };
        // The prior on the offsets weighs as much against the data as with all samples.
        let share = (level.wa.len() + level.wb.len()) as f64 / all;
        pairs.clear();
        collect(
            (&level.wb, off_b),
            a,
            &t,
            gate,
            None,
            &mut level.looked_a,
            &mut pairs,
        );
        let to_b = t.inverse();
        collect(
            (&level.wa, off_a),
            b,
            &to_b,
            gate,
            Some(&t),
            &mut level.looked_b,
            &mut pairs,
        );
        if pairs.len() < 10 {
            break;
        }
        let rot = DVec2::from_angle(t.theta);
        // Linearise about the centroid of the mapped source points: x' = x + dθ perp(x - c) + d.
        let c = pairs.iter().map(|pr| t.apply(pr.p)).sum::<DVec2>() / pairs.len() as f64;
        let (mut m, mut v) = ([[0.0; 3]; 3], [0.0; 3]);
        let (mut mb, mut vb) = ([[0.0; 2]; 2], [0.0; 2]);
        for pr in &pairs {
            let x = t.apply(pr.p) + off_b * rot.rotate(pr.sb);
            let q = pr.q + off_a * pr.sa;
            let r = pr.n.dot(x - q);
            let w = 1.0 / (1.0 + (r / scale).powi(2));
            let j = [pr.n.dot((x - c).perp()), pr.n.x, pr.n.y];
            for i in 0..3 {
                for k in 0..3 {
                    m[i][k] += w * j[i] * j[k];
                }
                v[i] -= w * j[i] * r;
            }
            if config.range_bias.is_none() {
                continue;
            }
            // The bias is a smooth effect over many walls: fit it with a wider kernel.
            let wb = 1.0 / (1.0 + (r / BIAS_SCALE_PX).powi(2));
            let jb = [pr.n.dot(rot.rotate(pr.sb)), -pr.n.dot(pr.sa)];
            for i in 0..2 {
                for k in 0..2 {
                    mb[i][k] += wb * jb[i] * jb[k];
                }
                vb[i] -= wb * jb[i] * r;
            }
        }
        let bias_step = config.range_bias.and_then(|prior| {
            let prior = prior * share;
            // A Gaussian prior pulls each offset towards the mean (0: no bias).
            mb[0][0] += prior;
            mb[1][1] += prior;
            vb[0] -= prior * (off_b - mean);
            vb[1] -= prior * (off_a - mean);
            let [mut db, mut da] = solve(mb, vb)?;
            // Offsets are never negative (a wall is not pulled towards its observer): where
            // one would be, hold it at 0 and fit the other alone.
            if off_a + da < 0.0 {
                da = -off_a;
                db = (vb[0] - mb[0][1] * da) / mb[0][0];
            } else if off_b + db < 0.0 {
                db = -off_b;
                da = (vb[1] - mb[1][0] * db) / mb[1][1];
            }
            Some([db, da])
        });
        let step = if config.lock_rotation {
            solve([[m[1][1], m[1][2]], [m[2][1], m[2][2]]], [v[1], v[2]])
                .map(|[dx, dy]| [0.0, dx, dy])
        } else {
            solve(m, v)
        };
        let Some([dt, dx, dy]) = step else {
            break;
        };
        let [db, da] = bias_step.unwrap_or([0.0, 0.0]);
        // The offsets as moved, within their bounds: a step that would push an offset held
        // at a bound (both below 0, say) moves nothing, and must not keep the loop going.
        let (new_b, new_a) = (
            (off_b + db).clamp(0.0, MAX_OFFSET_PX),
            (off_a + da).clamp(0.0, MAX_OFFSET_PX),
        );
        let moved = (new_b - off_b).abs().max((new_a - off_a).abs());
        (off_b, off_a) = (new_b, new_a);
        // Apply the increment: rotate about c by dθ, then shift by d.
        let step = Rigid2::new(dt, 0.0, 0.0);
        let about_c = Rigid2 {
            theta: dt,
            tx: c.x - step.apply(c).x + dx,
            ty: c.y - step.apply(c).y + dy,
        };
        t = about_c.compose(&t);
        // Converged once the gate has shrunk and the step moved the paired walls (root mean
        // square about `c`) and the offsets by less than the tolerance. The spread is only
        // computed where the test can pass.
        let spread = || {
            (pairs
                .iter()
                .map(|pr| (t.apply(pr.p) - c).length_squared())
                .sum::<f64>()
                / pairs.len() as f64)
                .sqrt()
        };
        if f >= 1.0
            && moved < config.tolerance_px
            && dx.hypot(dy) + dt.abs() * spread() < config.tolerance_px
        {
            break;
        }
    }
    // Guard against a refinement that slid along a corridor to somewhere else.
    let centre = b.wall_centre();
    if !(t.theta.is_finite() && t.tx.is_finite() && t.ty.is_finite())
        || (t.apply(centre) - b_to_a.apply(centre)).length() > config.max_shift_px
    {
        return (*b_to_a, [0.0, 0.0]);
    }
    (t, [off_a, off_b])
}

/// Wall samples of both maps with their free sides, and the lookups kept for them (see
/// [`collect`]).
struct Samples {
    wa: Vec<(DVec2, DVec2)>,
    wb: Vec<(DVec2, DVec2)>,
    looked_a: Vec<WallLookup>,
    looked_b: Vec<WallLookup>,
}

/// Scale (pixels) of the Cauchy weight of the bias fit.
const BIAS_SCALE_PX: f64 = 1.0;

/// Largest range-bias offset, in pixels (the walls of a 10 % noise sensor at 80 cells).
const MAX_OFFSET_PX: f64 = 8.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testmaps::{grown_room, room};
    use crate::verify::VerifyConfig;
    use grid_core::metrics::displacement_error;

    #[test]
    fn solve_needs_pivoting_and_refuses_singular_systems() {
        // A zero in the first pivot position: elimination must swap rows.
        let x = solve(
            [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [2.0, 0.0, 3.0]],
            [7.0, 3.0, 11.0],
        );
        let x = x.unwrap();
        for (got, want) in x.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-12, "{x:?}");
        }
        assert_eq!(solve([[1.0, 2.0], [2.0, 4.0]], [1.0, 2.0]), None);
    }

    #[test]
    fn a_converged_refinement_stops_even_with_an_offset_held_at_zero() {
        // B is the room turned by 30 degrees and resampled cell by cell: the turned walls
        // come out thicker on one side, so the bias fit would move both maps' walls towards
        // their observers, below 0, where the offsets are held. Once the pose has settled,
        // allowing one more iteration (the gate schedule, which shrinks over
        // `max_iterations / 2`, is the same) must change nothing, bit for bit: the loop has
        // stopped. (Before, the held offsets' steps kept it running to `max_iterations`.)
        let a = room();
        let a_to_b = Rigid2::new(30f64.to_radians(), 60.0, 10.0);
        let b = a.warp(&a_to_b, 200, 200).unwrap();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let truth = a_to_b.inverse();
        let start = Rigid2::new(truth.theta + 0.01, truth.tx + 1.0, truth.ty - 1.0);
        let run = |max_iterations| {
            let config = RefineConfig {
                max_iterations,
                ..RefineConfig::default()
            };
            refine_with_bias(&pa, &pb, &start, &config)
        };
        let (t, offsets) = run(30);
        assert_eq!(offsets, [0.0, 0.0]);
        let err = displacement_error(&b, &t, &truth).unwrap();
        assert!(err < 0.5, "{err} px off");
        assert_eq!(run(31), (t, offsets));
    }

    #[test]
    fn the_refinement_stops_once_its_steps_fall_below_the_tolerance() {
        // B is the room with its outer walls 1 cell further out: the robust fit of walls that
        // do not quite agree keeps creeping by small steps.
        let (a, b) = (room(), grown_room(1));
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let start = Rigid2::new(0.01, 1.5, -1.0);
        let run = |max_iterations, tolerance_px| {
            let config = RefineConfig {
                max_iterations,
                tolerance_px,
                ..RefineConfig::default()
            };
            refine_with_bias(&pa, &pb, &start, &config).0
        };
        // Without a tolerance every iteration still moves the pose: one more changes it.
        let (crept, further) = (run(30, 0.0), run(31, 0.0));
        assert_ne!(crept, further);
        // With it the loop has stopped before the last iteration, bit for bit, within the
        // tolerance of where the creeping run ended.
        let stopped = run(30, 0.05);
        assert_eq!(run(31, 0.05), stopped);
        let apart = displacement_error(&b, &stopped, &crept).unwrap();
        assert!(apart < 0.1, "{apart} px from the run without a tolerance");
        assert!(displacement_error(&b, &stopped, &Rigid2::default()).unwrap() < 1.5);
    }

    #[test]
    fn a_map_whose_walls_sit_behind_the_faces_gets_its_offset() {
        // B is the room with its outer walls 2 cells further out; the truth is the identity.
        let (a, b) = (room(), grown_room(2));
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let truth = Rigid2::new(0.0, 0.0, 0.0);
        let start = Rigid2::new(0.01, 1.0, -1.0);
        let (t, [off_a, off_b]) = refine_with_bias(&pa, &pb, &start, &RefineConfig::default());
        // Only the difference of the offsets shows in walls seen from the same side.
        assert!(
            (off_b - off_a - 2.0).abs() < 0.3,
            "offsets {off_a} (A), {off_b} (B)"
        );
        let err = displacement_error(&b, &t, &truth).unwrap();
        assert!(err < 0.3, "{err} px off");
        // Without the model the grown walls pull nothing out of place here (the room grew
        // evenly), but no offset is reported either.
        let off = RefineConfig {
            range_bias: None,
            ..RefineConfig::default()
        };
        let (_, offsets) = refine_with_bias(&pa, &pb, &start, &off);
        assert_eq!(offsets, [0.0, 0.0]);
    }

    #[test]
    fn equal_offsets_held_by_the_prior_leave_walls_seen_from_one_side_in_place() {
        // A copy of the room: every wall is seen from the same side in both maps, so moving
        // both maps' walls 1.5 px towards their free sides moves nothing relative to the
        // other, and the pose comes back to the truth.
        let a = room();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&a, &vc));
        let truth = Rigid2::new(0.0, 0.0, 0.0);
        let start = Rigid2::new(0.01, 1.0, -1.0);
        let held = RefineConfig {
            range_bias: Some(1e6),
            range_bias_mean_px: 1.5,
            ..RefineConfig::default()
        };
        let (t, offsets) = refine_with_bias(&pa, &pb, &start, &held);
        for o in offsets {
            assert!((o - 1.5).abs() < 1e-3, "offsets {offsets:?}");
        }
        let err = displacement_error(&a, &t, &truth).unwrap();
        assert!(err < 0.3, "{err} px off");
        // Past the bounds or NaN, the mean is clamped, or 0.
        for (mean, want) in [(f64::NAN, 0.0), (-1.0, 0.0), (20.0, MAX_OFFSET_PX)] {
            let config = RefineConfig {
                range_bias_mean_px: mean,
                ..held
            };
            let (_, offsets) = refine_with_bias(&pa, &pb, &start, &config);
            assert!((offsets[0] - want).abs() < 1e-3, "mean {mean}: {offsets:?}");
        }
    }
}
