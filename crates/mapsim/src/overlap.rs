//! Overlap control: the robots share one exploration tour; robot `i` drives the segment
//! `[m_i - delta, m_{i+1} + delta)` of it (`m_i = i N / n`). The noise-free footprint of every
//! pose is precomputed (on a coarse raster for big worlds), so the overlap of any `delta`
//! is a cheap count, and `delta` is found by bisection.

use rayon::prelude::*;

use crate::RobotConfig;
use crate::planner::PathPose;
use crate::raycast::traverse;
use crate::sensor::{beam_offsets, failed};
use crate::world::World;
use glam::DVec2;

/// Per-pose sets of coarse cells a robot's noise-free sensor observes.
pub(crate) struct Footprints {
    /// First pose index covered.
    first: usize,
    offsets: Vec<usize>,
    cells: Vec<u32>,
}

/// Coarse raster for footprints: `f` world cells per coarse cell.
#[derive(Clone, Copy)]
pub(crate) struct CoarseRaster {
    pub f: usize,
    pub w: usize,
    pub h: usize,
}

impl CoarseRaster {
    pub fn new(world: &World) -> Self {
        // Keep the footprint raster at most ~512 a side: the control is then cheap at any size,
        // and exact (f = 1) for worlds up to 512 cells.
        let f = world.width().max(world.height()).div_ceil(512).max(1);
        Self {
            f,
            w: world.width().div_ceil(f),
            h: world.height().div_ceil(f),
        }
    }
}

/// Every `stride`-th pose of a tour is enough to estimate a segment's footprint: consecutive
/// poses see nearly the same cells, so footprints are computed for poses at most a tenth of
/// the sensor range apart (and the others count as empty).
pub(crate) fn footprint_stride(cfg: &RobotConfig, pose_step: f64) -> usize {
    ((0.1 * cfg.max_range / pose_step).floor() as usize).max(1)
}

/// Whether a robot driving the tour backwards (heading + pi) sees the same footprint as one
/// driving it forwards: true when its beams are symmetric under a half turn.
pub(crate) fn flip_invariant(cfg: &RobotConfig) -> bool {
    cfg.beams.is_multiple_of(2) && cfg.failed_beams.is_empty()
}

/// Footprints of poses `range` of `tour` (headings already in the robot's direction); only
/// poses whose index is a multiple of `stride` are cast, the others are empty.
pub(crate) fn footprints(
    world: &World,
    tour: &[PathPose],
    range: std::ops::Range<usize>,
    cfg: &RobotConfig,
    reversed: bool,
    raster: CoarseRaster,
    stride: usize,
) -> Footprints {
    let offsets = beam_offsets(cfg.beams);
    let flip = if reversed { std::f64::consts::PI } else { 0.0 };
    let per_pose: Vec<Vec<u32>> = tour[range.clone()]
        .par_iter()
        .enumerate()
        .map_init(
            || vec![false; raster.w * raster.h],
            |stamp, (k, p)| {
                let mut cells = Vec::new();
                if !(range.start + k).is_multiple_of(stride) {
                    return cells;
                }
                let heading = DVec2::from_angle(p.heading + flip);
                for (j, &o) in offsets.iter().enumerate() {
                    if failed(cfg, j) {
                        continue;
                    }
                    traverse(p.pos, heading.rotate(o), cfg.max_range, |x, y, _| {
                        if x < 0 || y < 0 {
                            return false;
                        }
                        let (cx, cy) = (x as usize / raster.f, y as usize / raster.f);
                        if cx >= raster.w || cy >= raster.h {
                            return false;
                        }
                        let c = cy * raster.w + cx;
                        if !stamp[c] {
                            stamp[c] = true;
                            cells.push(c as u32);
                        }
                        !world.is_occupied(x, y)
                    });
                }
                for &c in &cells {
                    stamp[c as usize] = false;
                }
                cells
            },
        )
        .collect();
    let mut offsets = Vec::with_capacity(per_pose.len() + 1);
    let mut cells = Vec::new();
    offsets.push(0);
    for v in per_pose {
        cells.extend_from_slice(&v);
        offsets.push(cells.len());
    }
    Footprints {
        first: range.start,
        offsets,
        cells,
    }
}

/// The tour segment of robot `i` of `n` for a tour of `len` poses and extension `delta`.
pub(crate) fn segment(i: usize, n: usize, len: usize, delta: i64) -> std::ops::Range<usize> {
    let m = |k: usize| (k * len / n) as i64;
    let lo = if i == 0 { 0 } else { (m(i) - delta).max(0) };
    let hi = if i + 1 == n {
        len as i64
    } else {
        (m(i + 1) + delta).min(len as i64)
    };
    lo as usize..(hi.max(lo)) as usize
}

/// Pairwise overlap matrix `|E_i & E_j| / min(|E_i|, |E_j|)` from a per-cell robot bitmask.
pub(crate) fn overlap_matrix(masks: &[u32], n: usize) -> Vec<Vec<f64>> {
    let mut size = vec![0usize; n];
    let mut both = vec![vec![0usize; n]; n];
    for &m in masks.iter().filter(|&&m| m != 0) {
        for i in 0..n {
            if m & (1 << i) != 0 {
                size[i] += 1;
                for (j, count) in both[i].iter_mut().enumerate().skip(i + 1) {
                    if m & (1 << j) != 0 {
                        *count += 1;
                    }
                }
            }
        }
    }
    let mut out = vec![vec![1.0; n]; n];
    for i in 0..n {
        for j in i + 1..n {
            let small = size[i].min(size[j]);
            let v = if small == 0 {
                0.0
            } else {
                both[i][j] as f64 / small as f64
            };
            out[i][j] = v;
            out[j][i] = v;
        }
    }
    out
}

/// Mean overlap of consecutive robots `(i, i + 1)`: the quantity the control targets.
pub(crate) fn mean_consecutive(m: &[Vec<f64>]) -> f64 {
    let n = m.len();
    (0..n - 1).map(|i| m[i][i + 1]).sum::<f64>() / (n - 1) as f64
}

/// Reference overlap (noise-free, coarse) for extension `delta`.
pub(crate) fn reference_overlap(
    fps: &[&Footprints],
    len: usize,
    delta: i64,
    masks: &mut Vec<u32>,
    raster: CoarseRaster,
) -> f64 {
    let n = fps.len();
    masks.clear();
    masks.resize(raster.w * raster.h, 0);
    for (i, fp) in fps.iter().enumerate() {
        let seg = segment(i, n, len, delta);
        for p in seg {
            let k = p - fp.first;
            for &c in &fp.cells[fp.offsets[k]..fp.offsets[k + 1]] {
                masks[c as usize] |= 1 << i;
            }
        }
    }
    mean_consecutive(&overlap_matrix(masks, n))
}

/// The extension `delta` whose reference overlap is closest to `target`, searched in
/// `[lo, hi]` assuming the overlap grows with `delta`. For `target == 0` the largest `delta`
/// with zero overlap is returned minus `safety` poses, so that noise cannot bridge the gap.
pub(crate) fn choose_delta(
    eval: &mut impl FnMut(i64) -> f64,
    target: f64,
    lo: i64,
    hi: i64,
    safety: i64,
) -> i64 {
    if eval(lo) > target {
        return lo;
    }
    // Invariant: eval(a) <= target; b is either hi or has eval(b) > target.
    let (mut a, mut b) = (lo, hi);
    if eval(hi) <= target {
        return hi;
    }
    while b - a > 1 {
        let mid = a + (b - a) / 2;
        if eval(mid) <= target {
            a = mid;
        } else {
            b = mid;
        }
    }
    if target <= 0.0 {
        return a - safety;
    }
    if (eval(b) - target).abs() < (target - eval(a)).abs() {
        b
    } else {
        a
    }
}
