//! Per-component statistics from one pass over a label image: raw moments up to order three
//! (accumulated in `f64` relative to each component's first pixel, so that large coordinates do
//! not cancel away the central moments), bounding box, boundary pixels and unknown contact.

use std::f64::consts::PI;

use grid_core::{CellState, DVec2, OccupancyGrid};

use crate::label::{WORD, is_zero_word};

/// Inclusive pixel bounding box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BoundingBox {
    /// Smallest column.
    pub min_x: usize,
    /// Smallest row.
    pub min_y: usize,
    /// Largest column.
    pub max_x: usize,
    /// Largest row.
    pub max_y: usize,
}

/// Shape statistics of one connected component.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// Number of pixels.
    pub area: usize,
    /// Mean pixel position (pixel convention, integer values at pixel centres).
    pub centroid: DVec2,
    /// Bounding box.
    pub bbox: BoundingBox,
    /// Eigenvalues `[major, minor]` (`major >= minor`) of the pixel covariance, px², each pixel
    /// counted as a unit square (so a single pixel has `1/12` along both axes).
    pub eigenvalues: [f64; 2],
    /// Angle of the major axis in `(-pi/2, pi/2]`, radians, pixel convention (y down, positive
    /// from +x towards +y): `0.5 * atan2(2 mu11, mu20 - mu02)`. Meaningless for round shapes;
    /// see [`Shape::roundness`].
    pub axis_angle: f64,
    /// Hu's seven moment invariants, log-scaled: `-sign(h) * log10(|h|)` (`0` when `h == 0`).
    pub hu: [f64; 7],
    /// Pixels of the component with a 4-neighbour outside it (or outside the image).
    pub perimeter: usize,
    /// Fraction of the boundary pixels that have an unknown cell among their 8 neighbours (the
    /// edge of the map counts as unknown): such a component may continue where nobody looked.
    pub unknown_contact: f64,
}

impl Shape {
    /// `minor / major` eigenvalue ratio in `[0, 1]`: 1 for a disc or a square, 0 for a line.
    pub fn roundness(&self) -> f64 {
        if self.eigenvalues[0] > 0.0 {
            self.eigenvalues[1] / self.eigenvalues[0]
        } else {
            1.0
        }
    }

    /// Eccentricity of the moment ellipse, `sqrt(1 - minor / major)`.
    pub fn eccentricity(&self) -> f64 {
        (1.0 - self.roundness()).max(0.0).sqrt()
    }
}

/// Raw moments of one component relative to its reference (first) pixel.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Accumulator {
    n: u64,
    x0: u32,
    y0: u32,
    s: [f64; 9], // x, y, xx, xy, yy, xxx, xxy, xyy, yyy
    min_x: u32,
    min_y: u32,
    max_x: u32,
    max_y: u32,
    boundary: u64,
    boundary_unknown: u64,
}

impl Accumulator {
    #[inline]
    fn add(&mut self, x: u32, y: u32) {
        if self.n == 0 {
            (self.x0, self.y0) = (x, y);
            (self.min_x, self.min_y, self.max_x, self.max_y) = (x, y, x, y);
        }
        self.n += 1;
        let dx = x as f64 - self.x0 as f64;
        let dy = y as f64 - self.y0 as f64;
        let (xx, xy, yy) = (dx * dx, dx * dy, dy * dy);
        let s = &mut self.s;
        s[0] += dx;
        s[1] += dy;
        s[2] += xx;
        s[3] += xy;
        s[4] += yy;
        s[5] += xx * dx;
        s[6] += xx * dy;
        s[7] += xy * dy;
        s[8] += yy * dy;
        self.min_x = self.min_x.min(x);
        self.max_x = self.max_x.max(x);
        self.min_y = self.min_y.min(y);
        self.max_y = self.max_y.max(y);
    }

    pub(crate) fn area(&self) -> usize {
        self.n as usize
    }

    pub(crate) fn shape(&self) -> Shape {
        let n = self.n as f64;
        let s = &self.s;
        let (mx, my) = (s[0] / n, s[1] / n);
        // Central moments (about the centroid) from the raw ones; the pixel-as-square term
        // n/12 makes tiny blobs isotropic instead of degenerate.
        let mu20 = s[2] - s[0] * mx + n / 12.0;
        let mu02 = s[4] - s[1] * my + n / 12.0;
        let mu11 = s[3] - s[0] * my;
        let mu30 = s[5] - 3.0 * mx * s[2] + 2.0 * mx * mx * s[0];
        let mu03 = s[8] - 3.0 * my * s[4] + 2.0 * my * my * s[1];
        let mu21 = s[6] - 2.0 * mx * s[3] - my * s[2] + 2.0 * mx * mx * s[1];
        let mu12 = s[7] - 2.0 * my * s[3] - mx * s[4] + 2.0 * my * my * s[0];

        let (a, b, c) = (mu20 / n, mu11 / n, mu02 / n);
        let half = 0.5 * (a - c);
        let root = (half * half + b * b).sqrt();
        let mid = 0.5 * (a + c);
        let eigenvalues = [mid + root, (mid - root).max(0.0)];
        let mut axis_angle = 0.5 * (2.0 * mu11).atan2(mu20 - mu02);
        if axis_angle <= -PI / 2.0 {
            axis_angle += PI;
        }

        // Scale-normalised moments eta_pq = mu_pq / n^(1 + (p+q)/2).
        let n2 = n * n;
        let n25 = n2 * n.sqrt();
        let (e20, e02, e11) = (mu20 / n2, mu02 / n2, mu11 / n2);
        let (e30, e03, e21, e12) = (mu30 / n25, mu03 / n25, mu21 / n25, mu12 / n25);
        let hu = hu_invariants(e20, e02, e11, e30, e03, e21, e12).map(log_scale);

        Shape {
            area: self.n as usize,
            centroid: DVec2::new(self.x0 as f64 + mx, self.y0 as f64 + my),
            bbox: BoundingBox {
                min_x: self.min_x as usize,
                min_y: self.min_y as usize,
                max_x: self.max_x as usize,
                max_y: self.max_y as usize,
            },
            eigenvalues,
            axis_angle,
            hu,
            perimeter: self.boundary as usize,
            unknown_contact: if self.boundary > 0 {
                self.boundary_unknown as f64 / self.boundary as f64
            } else {
                0.0
            },
        }
    }
}

fn hu_invariants(e20: f64, e02: f64, e11: f64, e30: f64, e03: f64, e21: f64, e12: f64) -> [f64; 7] {
    let (p, q) = (e30 + e12, e21 + e03);
    let (r, t) = (e30 - 3.0 * e12, 3.0 * e21 - e03);
    [
        e20 + e02,
        (e20 - e02).powi(2) + 4.0 * e11 * e11,
        r * r + t * t,
        p * p + q * q,
        r * p * (p * p - 3.0 * q * q) + t * q * (3.0 * p * p - q * q),
        (e20 - e02) * (p * p - q * q) + 4.0 * e11 * p * q,
        t * p * (p * p - 3.0 * q * q) - r * q * (3.0 * p * p - q * q),
    ]
}

fn log_scale(h: f64) -> f64 {
    if h == 0.0 || !h.is_finite() {
        0.0
    } else {
        -h.signum() * h.abs().log10()
    }
}

/// Accumulate the statistics of every component of `labels` (`1..=n`, `0` background, non-zero
/// exactly where `mask` is) into `acc` (resized to `n`). `grid` supplies the unknown cells for
/// the contact measure; it must have the labels' size. `origin` is added to every pixel's
/// coordinates (the labels may cover a window of a larger grid), so positions come out in the
/// larger grid's frame, computed exactly as if it had been labelled whole. Components `l` with
/// `skip[l]` (`skip` has `n + 1` entries, `skip[0]` for the background, which must be set) are
/// not accumulated and keep an empty accumulator.
pub(crate) fn accumulate(
    labels: &[u32],
    mask: &[u8],
    n: usize,
    skip: &[bool],
    grid: &OccupancyGrid,
    origin: (usize, usize),
    acc: &mut Vec<Accumulator>,
) {
    debug_assert_eq!(skip.len(), n + 1);
    let (w, h) = (grid.width(), grid.height());
    acc.clear();
    acc.resize(n, Accumulator::default());
    let cells = grid.cells();
    // A neighbour counts when it is unknown in the grid and not part of the component itself
    // (closing may have filled unknown gap cells into the component).
    let unknown = |x: usize, y: usize, l: u32| {
        labels[y * w + x] != l && OccupancyGrid::classify(cells[y * w + x]) == CellState::Unknown
    };
    for y in 0..h {
        let row = &labels[y * w..(y + 1) * w];
        let mrow = &mask[y * w..(y + 1) * w];
        let mut x = 0;
        while x < w {
            // Skip background a word at a time: most of a map is not an obstacle.
            if x + WORD <= w && is_zero_word(&mrow[x..x + WORD]) {
                x += WORD;
                continue;
            }
            let l = row[x];
            x += 1;
            if skip[l as usize] {
                continue;
            }
            let x = x - 1;
            let a = &mut acc[l as usize - 1];
            a.add((x + origin.0) as u32, (y + origin.1) as u32);
            let edge = x == 0 || y == 0 || x + 1 == w || y + 1 == h;
            let boundary = edge
                || row[x - 1] != l
                || row[x + 1] != l
                || labels[(y - 1) * w + x] != l
                || labels[(y + 1) * w + x] != l;
            if boundary {
                a.boundary += 1;
                let touches = edge || {
                    let mut t = false;
                    for yy in y - 1..=y + 1 {
                        for xx in x - 1..=x + 1 {
                            t |= unknown(xx, yy, l);
                        }
                    }
                    t
                };
                if touches {
                    a.boundary_unknown += 1;
                }
            }
        }
    }
}
