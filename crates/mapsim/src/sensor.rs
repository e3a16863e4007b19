//! Range sensing in the world and log-odds mapping in the robot's own frame.

use std::f64::consts::TAU;

use glam::DVec2;
use grid_core::{OccupancyGrid, Pose2, Rigid2, UNKNOWN};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::planner::PathPose;
use crate::raycast::{cast, traverse};
use crate::world::World;
use crate::{CaseConfig, MapperModel, Result, RobotConfig};

/// One measured beam, in world pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ray {
    pub origin: DVec2,
    pub dir: DVec2,
    /// Measured length (cells); `max_range` when nothing was returned.
    pub len: f64,
    /// Whether the beam returned an obstacle at `len`.
    pub hit: bool,
}

/// The beams' directions relative to the heading (beam `j` of `n` at `TAU j / n`), computed
/// once: a beam's world direction is the heading's unit vector rotated by its entry.
pub(crate) fn beam_offsets(n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|j| DVec2::from_angle(TAU * j as f64 / n as f64))
        .collect()
}

/// Whether beam `j` is listed as failed.
#[inline]
pub(crate) fn failed(cfg: &RobotConfig, j: usize) -> bool {
    cfg.failed_beams.contains(&j)
}

/// Cast every beam at every pose; noise and dropout are drawn from `rng` in pose-beam order so
/// the result does not depend on the thread count.
pub(crate) fn measure(
    world: &World,
    poses: &[PathPose],
    cfg: &RobotConfig,
    rng: &mut ChaCha8Rng,
) -> Vec<Ray> {
    let n = cfg.beams;
    let offsets = beam_offsets(n);
    let headings: Vec<DVec2> = poses.iter().map(|p| DVec2::from_angle(p.heading)).collect();
    // Exact distances are the expensive part and need no randomness: do them in parallel.
    let truth: Vec<Option<f64>> = poses
        .par_iter()
        .zip(&headings)
        .flat_map_iter(|(p, &h)| {
            offsets.iter().enumerate().map(move |(j, &o)| {
                if failed(cfg, j) {
                    None
                } else {
                    cast(world, p.pos, h.rotate(o), cfg.max_range)
                }
            })
        })
        .collect();
    let mut rays = Vec::with_capacity(truth.len());
    for (k, t) in truth.iter().enumerate() {
        let (p, h, j) = (&poses[k / n], headings[k / n], k % n);
        if failed(cfg, j) {
            continue;
        }
        // Always draw both numbers so the stream stays aligned whatever the parameters.
        let drop = rng.random::<f64>() < cfg.dropout;
        let u: f64 = rng.random_range(-1.0..1.0);
        if drop {
            continue;
        }
        let (len, hit) = match t {
            Some(t) => {
                let m = t * (1.0 + u * cfg.noise_bound);
                if m <= cfg.max_range {
                    (m, true)
                } else {
                    (cfg.max_range, false)
                }
            }
            None => (cfg.max_range, false),
        };
        rays.push(Ray {
            origin: p.pos,
            dir: h.rotate(offsets[j]),
            len,
            hit,
        });
    }
    rays
}

/// The robot's map in its own frame: a random rotation, a canvas cropped to the explored area
/// plus a margin. Returns the map and the transform mapping a map pixel to a world pixel.
pub(crate) fn build_map(
    rays: &[Ray],
    poses: &[PathPose],
    case: &CaseConfig,
    resolution: f64,
    rng: &mut ChaCha8Rng,
) -> Result<(OccupancyGrid, Rigid2)> {
    let theta = if case.max_rotation > 0.0 {
        rng.random_range(-case.max_rotation..=case.max_rotation)
    } else {
        0.0
    };
    let rot = DVec2::from_angle(theta);
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    let mut grow = |p: DVec2| {
        let q = rot.rotate(p);
        lo = lo.min(q);
        hi = hi.max(q);
    };
    for p in poses {
        grow(p.pos);
    }
    for r in rays {
        grow(r.origin + r.dir * (r.len + 1.0));
    }
    if lo.x > hi.x {
        // No pose at all: an empty 1-cell canvas around the origin.
        lo = DVec2::ZERO;
        hi = DVec2::ZERO;
    }
    let m = case.margin as f64;
    let extra = case.extra_margin as f64;
    let mut pad = || {
        m + if extra > 0.0 {
            rng.random_range(0.0..extra)
        } else {
            0.0
        }
    };
    let (pad_lo, pad_hi) = (DVec2::new(pad(), pad()), DVec2::new(pad(), pad()));
    let t = pad_lo - lo;
    let size = (hi - lo + pad_lo + pad_hi).ceil();
    let (w, h) = (size.x as usize + 1, size.y as usize + 1);
    let world_to_map = Rigid2::new(theta, t.x, t.y);

    let cells = match case.mapper {
        MapperModel::LogOdds(model) => {
            let mut logodds = vec![0f32; w * h];
            let mut seen = vec![false; w * h];
            fold_beams(rays, (&world_to_map, rot), (w, h), |i, hit| {
                logodds[i] = if hit {
                    (logodds[i] + model.occupied).min(model.clamp)
                } else {
                    (logodds[i] + model.free).max(-model.clamp)
                };
                seen[i] = true;
            });
            logodds
                .iter()
                .zip(&seen)
                .map(|(&l, &s)| {
                    if s {
                        (100.0 / (1.0 + (-l).exp())).round() as u8
                    } else {
                        UNKNOWN
                    }
                })
                .collect()
        }
        MapperModel::HitRatio(model) => {
            // (hits, passes), a hit counting as a pass.
            let mut counts = vec![(0u32, 0u32); w * h];
            fold_beams(rays, (&world_to_map, rot), (w, h), |i, hit| {
                let c = &mut counts[i];
                c.0 += u32::from(hit);
                c.1 += 1;
            });
            counts
                .iter()
                .map(|&(hits, passes)| {
                    if passes <= model.min_passes {
                        UNKNOWN
                    } else if hits as f32 > model.occupied_above * passes as f32 {
                        100
                    } else {
                        0
                    }
                })
                .collect()
        }
    };
    let map = OccupancyGrid::from_cells(w, h, resolution, Pose2::default(), cells)?;
    Ok((map, world_to_map.inverse()))
}

/// Every beam of `rays` rasterised in the map (`world_to_map`, whose rotation is `rot`, onto a
/// `w x h` canvas): `update(i, false)` for each cell `i` it passes through, then `update(i,
/// true)` for the cell it ends in when it returned an obstacle. A cell is passed when its centre projects before the
/// measured end, and the first cell whose centre projects beyond it is the hit: walls come out
/// one cell thick, on the obstacle boundary, independent of the map's rotation.
fn fold_beams(
    rays: &[Ray],
    (world_to_map, rot): (&Rigid2, DVec2),
    (w, h): (usize, usize),
    mut update: impl FnMut(usize, bool),
) {
    let idx = |x: i64, y: i64| {
        (x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h)
            .then(|| y as usize * w + x as usize)
    };
    for r in rays {
        let o = world_to_map.apply(r.origin);
        let d = rot.rotate(r.dir);
        let mut occ_done = !r.hit;
        let reach = if r.hit { r.len + 1.5 } else { r.len };
        traverse(o, d, reach, |x, y, _| {
            let s = (DVec2::new(x as f64, y as f64) - o).dot(d);
            let Some(i) = idx(x, y) else {
                return true;
            };
            if s < r.len {
                update(i, false);
                true
            } else if !occ_done {
                update(i, true);
                occ_done = true;
                false
            } else {
                false
            }
        });
    }
}
