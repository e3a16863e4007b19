//! Sub-pixel refinement of a hypothesis: iterative closest point of B's walls onto A's walls.
//!
//! RANSAC's answer is fixed by a few keypoints whose positions carry the blur of the scale
//! space; the walls themselves pin the pose down much better. Each iteration pairs every
//! sampled wall cell of B with the nearest wall cell of A (looked up in A's nearest-occupied
//! transform, no search) within a shrinking gate, and solves the closed-form rigid fit.

use grid_core::{CellState, DVec2, Rigid2};

use crate::verify::PreparedMap;

/// Parameters of the refinement, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineConfig {
    /// Pairing gate of the first iteration, in pixels. Default 6.
    pub initial_gate_px: f32,
    /// Gate the schedule shrinks to. Default 2.
    pub final_gate_px: f32,
    /// Iterations at most. Default 15.
    pub max_iterations: usize,
    /// The refinement may move the hypothesis at most this far (pixels, at B's centroid) before
    /// it is considered diverged and the input is kept. Default 8.
    pub max_shift_px: f64,
}

impl Default for RefineConfig {
    fn default() -> Self {
        Self {
            initial_gate_px: 6.0,
            final_gate_px: 2.0,
            max_iterations: 15,
            max_shift_px: 8.0,
        }
    }
}

/// Refine `b_to_a` by ICP of `b`'s walls onto `a`'s walls. Returns the input when too few pairs
/// are found or the refinement wanders off.
pub fn refine(a: &PreparedMap, b: &PreparedMap, b_to_a: &Rigid2, config: &RefineConfig) -> Rigid2 {
    let mut t = *b_to_a;
    let mut pairs: Vec<(DVec2, DVec2)> = Vec::with_capacity(b.wall_samples.len());
    for it in 0..config.max_iterations {
        let f = it as f32 / (config.max_iterations.max(2) - 1) as f32;
        let gate = config.initial_gate_px + (config.final_gate_px - config.initial_gate_px) * f;
        pairs.clear();
        for &p in &b.wall_samples {
            let q = t.apply(p);
            let (x, y) = (q.x.round(), q.y.round());
            if x < 0.0 || y < 0.0 {
                continue;
            }
            let (x, y) = (x as usize, y as usize);
            if a.grid.state(x, y) == CellState::Unknown {
                continue;
            }
            if let Some(((nx, ny), d)) = a.walls.nearest(x, y) {
                if d <= gate {
                    pairs.push((DVec2::new(nx as f64, ny as f64), p));
                }
            }
        }
        if pairs.len() < 10 {
            break;
        }
        let Some(next) = ransac_rigid::fit_rigid_weighted(pairs.iter().map(|&(a, b)| (a, b, 1.0)))
        else {
            break;
        };
        let moved = (next.apply(DVec2::ZERO) - t.apply(DVec2::ZERO)).length()
            + (next.theta - t.theta).abs();
        t = next;
        if moved < 1e-3 {
            break;
        }
    }
    // Guard against a refinement that slid along a corridor to somewhere else.
    let centre = b.wall_samples.iter().copied().sum::<DVec2>() / b.wall_samples.len().max(1) as f64;
    if (t.apply(centre) - b_to_a.apply(centre)).length() > config.max_shift_px {
        return *b_to_a;
    }
    t
}
