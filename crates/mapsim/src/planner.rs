//! Collision-free exploration tour: waypoints on a jittered lattice, visited in snake order and
//! joined by breadth-first paths on a coarse clearance grid.

use std::collections::VecDeque;

use glam::DVec2;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::world::World;
use crate::{Error, Result};

/// A robot pose along a path: position in world pixels and heading (radians, pixel convention).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PathPose {
    pub pos: DVec2,
    pub heading: f64,
}

/// Coarse planning grid. Block `(bx, by)` covers fine cells `[bx*s, bx*s + s)`; it is passable
/// when it and its 8 neighbours hold no obstacle, so its centre keeps a clearance of at least
/// `1.5 s - 0.5` cells and the straight segment to any passable 8-neighbour stays collision-free
/// (every point of it is within `0.71 s` of one end).
pub(crate) struct Coarse {
    s: usize,
    bw: usize,
    bh: usize,
    passable: Vec<bool>,
    /// Connected component label per block (`u32::MAX` for blocked).
    label: Vec<u32>,
    main_label: u32,
}

impl Coarse {
    pub fn new(world: &World, clearance: f64) -> Result<Self> {
        let s = ((clearance + 0.5) / 1.5).ceil().max(1.0) as usize;
        let (w, h) = (world.width(), world.height());
        let (bw, bh) = (w.div_ceil(s), h.div_ceil(s));
        let mut dirty = vec![false; bw * bh];
        for y in 0..h {
            let row = &world.raster()[y * w..(y + 1) * w];
            let by = y / s;
            for (x, &o) in row.iter().enumerate() {
                if o {
                    dirty[by * bw + x / s] = true;
                }
            }
        }
        // Partial blocks at the right/bottom edge reach outside the world: treat as dirty.
        if w % s != 0 {
            for by in 0..bh {
                dirty[by * bw + bw - 1] = true;
            }
        }
        if h % s != 0 {
            for bx in 0..bw {
                dirty[(bh - 1) * bw + bx] = true;
            }
        }
        let mut passable = vec![false; bw * bh];
        for by in 1..bh.saturating_sub(1) {
            for bx in 1..bw.saturating_sub(1) {
                passable[by * bw + bx] =
                    (by - 1..=by + 1).all(|yy| (bx - 1..=bx + 1).all(|xx| !dirty[yy * bw + xx]));
            }
        }
        // Label components; keep the largest as the explorable space.
        let mut label = vec![u32::MAX; bw * bh];
        let mut sizes = Vec::new();
        let mut queue = VecDeque::new();
        for start in 0..bw * bh {
            if !passable[start] || label[start] != u32::MAX {
                continue;
            }
            let l = sizes.len() as u32;
            let mut n = 0usize;
            label[start] = l;
            queue.push_back(start);
            while let Some(i) = queue.pop_front() {
                n += 1;
                for j in neighbours(i, bw, bh) {
                    if passable[j] && label[j] == u32::MAX {
                        label[j] = l;
                        queue.push_back(j);
                    }
                }
            }
            sizes.push(n);
        }
        let main_label = sizes
            .iter()
            .enumerate()
            .max_by_key(|&(i, &n)| (n, usize::MAX - i))
            .map(|(i, _)| i as u32)
            .ok_or(Error::NoFreeSpace)?;
        if sizes[main_label as usize] < 4 {
            return Err(Error::NoFreeSpace);
        }
        Ok(Self {
            s,
            bw,
            bh,
            passable,
            label,
            main_label,
        })
    }

    fn centre(&self, i: usize) -> DVec2 {
        let half = (self.s as f64 - 1.0) * 0.5;
        DVec2::new(
            (i % self.bw * self.s) as f64 + half,
            (i / self.bw * self.s) as f64 + half,
        )
    }

    fn in_main(&self, i: usize) -> bool {
        self.passable[i] && self.label[i] == self.main_label
    }

    /// The main-component block nearest to world point `p` within `radius` blocks.
    fn snap(&self, p: DVec2, radius: i64) -> Option<usize> {
        let (bx, by) = ((p.x / self.s as f64) as i64, (p.y / self.s as f64) as i64);
        let mut best: Option<(i64, usize)> = None;
        for dy in -radius..=radius {
            for dx in -radius..=radius {
                let (x, y) = (bx + dx, by + dy);
                if x < 0 || y < 0 || x >= self.bw as i64 || y >= self.bh as i64 {
                    continue;
                }
                let i = y as usize * self.bw + x as usize;
                let d = dx * dx + dy * dy;
                if self.in_main(i) && best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, i));
                }
            }
        }
        best.map(|(_, i)| i)
    }

    /// Breadth-first path from block `a` to block `b` (both in the main component), appended to
    /// `out` without `a`. `parent` is a caller-owned scratch buffer.
    fn path(&self, a: usize, b: usize, parent: &mut Vec<u32>, out: &mut Vec<usize>) {
        parent.clear();
        parent.resize(self.bw * self.bh, u32::MAX);
        let mut queue = VecDeque::new();
        parent[a] = a as u32;
        queue.push_back(a);
        while let Some(i) = queue.pop_front() {
            if i == b {
                break;
            }
            for j in neighbours(i, self.bw, self.bh) {
                if self.passable[j] && parent[j] == u32::MAX {
                    parent[j] = i as u32;
                    queue.push_back(j);
                }
            }
        }
        let start = out.len();
        let mut i = b;
        while i != a {
            out.push(i);
            i = parent[i] as usize;
        }
        out[start..].reverse();
    }
}

/// 8-neighbours of block `i`; diagonal moves only when both side blocks are in range (the
/// passability test already guarantees clearance).
fn neighbours(i: usize, bw: usize, bh: usize) -> impl Iterator<Item = usize> {
    let (x, y) = ((i % bw) as i64, (i / bw) as i64);
    const D: [(i64, i64); 8] = [
        (1, 0),
        (-1, 0),
        (0, 1),
        (0, -1),
        (1, 1),
        (-1, 1),
        (1, -1),
        (-1, -1),
    ];
    D.iter().filter_map(move |&(dx, dy)| {
        let (nx, ny) = (x + dx, y + dy);
        (nx >= 0 && ny >= 0 && nx < bw as i64 && ny < bh as i64)
            .then(|| ny as usize * bw + nx as usize)
    })
}

/// An exploration tour through the main free component, sampled every `step` cells.
pub(crate) fn tour(
    world: &World,
    clearance: f64,
    spacing: f64,
    step: f64,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<PathPose>> {
    let coarse = Coarse::new(world, clearance)?;
    let (w, h) = (world.width() as f64, world.height() as f64);
    let spacing = spacing.max(2.0 * coarse.s as f64);
    let nx = ((w / spacing).round() as usize).max(1);
    let ny = ((h / spacing).round() as usize).max(1);
    let (cw, ch) = (w / nx as f64, h / ny as f64);
    // Snake order over a jittered lattice: the tour sweeps the world row by row, so a prefix
    // and a suffix of it cover different parts (this is what makes the overlap controllable).
    let vertical = rng.random_bool(0.5);
    let flip_major = rng.random_bool(0.5);
    let flip_minor = rng.random_bool(0.5);
    let (major, minor) = if vertical { (nx, ny) } else { (ny, nx) };
    let mut blocks = Vec::new();
    for a in 0..major {
        let a = if flip_major { major - 1 - a } else { a };
        for b in 0..minor {
            let b = if (a % 2 == 1) ^ flip_minor {
                minor - 1 - b
            } else {
                b
            };
            let (ix, iy) = if vertical { (a, b) } else { (b, a) };
            let p = DVec2::new(
                (ix as f64 + 0.5 + rng.random_range(-0.3..0.3)) * cw,
                (iy as f64 + 0.5 + rng.random_range(-0.3..0.3)) * ch,
            );
            let radius = (spacing * 0.5 / coarse.s as f64).ceil() as i64;
            if let Some(i) = coarse.snap(p, radius)
                && blocks.last() != Some(&i)
            {
                blocks.push(i);
            }
        }
    }
    if blocks.len() < 2 {
        return Err(Error::NoFreeSpace);
    }
    let mut parent = Vec::new();
    let mut chain = vec![blocks[0]];
    for pair in blocks.windows(2) {
        coarse.path(pair[0], pair[1], &mut parent, &mut chain);
    }
    let pts: Vec<DVec2> = chain.iter().map(|&i| coarse.centre(i)).collect();
    Ok(resample(&pts, step))
}

/// Poses every `step` cells along a polyline, heading along the current segment.
fn resample(pts: &[DVec2], step: f64) -> Vec<PathPose> {
    let mut out = Vec::new();
    let mut carry = 0.0;
    for seg in pts.windows(2) {
        let d = seg[1] - seg[0];
        let len = d.length();
        if len == 0.0 {
            continue;
        }
        let heading = d.y.atan2(d.x);
        let mut t = carry;
        while t < len {
            out.push(PathPose {
                pos: seg[0] + d * (t / len),
                heading,
            });
            t += step;
        }
        carry = t - len;
    }
    out
}
