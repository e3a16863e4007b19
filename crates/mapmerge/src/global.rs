//! Global search: transform hypotheses without any feature match.
//!
//! When the keypoints of two maps disagree (strong sensor noise, walls seen only in part), their
//! RANSAC hypotheses fail verification, yet the walls may still line up. Following Carpin's
//! Hough-spectrum merger: the rotation is where the Hough spectra of the two maps' walls
//! correlate best (the spectrum is invariant to translation), and for each candidate rotation
//! the translation is where B's rotated walls best hit A's wall likelihood field (an FFT
//! cross-correlation at a coarse scale). The hypotheses go through the same refinement and
//! verification as the feature-based ones, so a wrong one costs time, not trust.
//!
//! That Hough-spectrum search ([`global_hypotheses`]) runs only when `PairConfig::global` is
//! on (off by default: the rotation sweep proposes what it does). The same FFT correlation
//! serves the rotation sweep ([`sweep_placements`]: every 2 degrees of a full turn) and the
//! symmetry probes ([`twins`]), which the default pipeline runs.

use std::f64::consts::PI;

use grid_core::{CellState, DVec2, OccupancyGrid, Rigid2};
use rayon::prelude::*;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex32;

use crate::verify::{PreparedMap, strided};

/// Parameters of the global search, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalConfig {
    /// Bins of the Hough spectrum over `[0, pi)`. Default 360 (0.5 degree).
    pub angle_bins: usize,
    /// Rotation peaks of the spectrum correlation kept; each gives two angles (`+ pi`).
    /// Default 3.
    pub rotation_peaks: usize,
    /// Wall points used for the spectrum and the correlation at most. Default 6000.
    pub max_points: usize,
    /// Cells of the coarse correlation images across the longest of the side of A's known
    /// cells' bounding box and the diagonal of B's (not the grids' sizes: a map's unknown
    /// border does not coarsen them). Default 192.
    pub coarse_size: usize,
    /// Translation peaks kept per angle. Default 2.
    pub translation_peaks: usize,
    /// What a wall of B landing on a free coarse cell of A costs, against 1 for landing on a
    /// wall (see [`SweepConfig::free_penalty`]). Default 0.5.
    pub free_penalty: f32,
    /// How far apart the translation peaks of one angle are at least, in coarse cells (see
    /// [`SweepConfig::peak_radius`]). Default 1 (local maxima among the eight neighbours). The
    /// symmetry probes take this configuration; with 5 for them as well as for the sweep, every
    /// outcome on the eval sets was that of the sweep's 5 alone (a local build,
    /// `docs/EVALUATION.md`, "Sweep peaks apart").
    pub peak_radius: usize,
}

impl Default for GlobalConfig {
    fn default() -> Self {
        Self {
            angle_bins: 360,
            rotation_peaks: 3,
            max_points: 6000,
            coarse_size: 192,
            translation_peaks: 2,
            free_penalty: 0.5,
            peak_radius: 1,
        }
    }
}

/// Hough spectrum of a point set: for each line-normal angle, the sum of squared accumulator
/// counts over the distance bins, normalised to unit length.
fn hough_spectrum(points: &[DVec2], bins: usize) -> Vec<f64> {
    let c = points.iter().copied().sum::<DVec2>() / points.len().max(1) as f64;
    let rmax = points
        .iter()
        .map(|p| (*p - c).length())
        .fold(0.0, f64::max)
        .ceil() as usize
        + 1;
    let mut acc = vec![0u32; 2 * rmax + 1];
    let mut hs = vec![0.0; bins];
    for (t, h) in hs.iter_mut().enumerate() {
        let (s, co) = (t as f64 * PI / bins as f64).sin_cos();
        acc.fill(0);
        for p in points {
            let d = *p - c;
            let rho = (d.x * co + d.y * s).round() as isize + rmax as isize;
            acc[rho as usize] += 1;
        }
        *h = acc.iter().map(|&v| (v as f64) * (v as f64)).sum();
    }
    let norm = hs.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
    hs.iter_mut().for_each(|v| *v /= norm);
    hs
}

/// Angles (radians, in `[0, pi)`) at which the spectra correlate best: `A(phi + k) ~ B(phi)`.
fn rotation_candidates(sa: &[f64], sb: &[f64], peaks: usize) -> Vec<f64> {
    let n = sa.len();
    let cc: Vec<f64> = (0..n)
        .map(|k| (0..n).map(|t| sa[(t + k) % n] * sb[t]).sum())
        .collect();
    let mut maxima: Vec<(f64, f64)> = (0..n)
        .filter(|&k| cc[k] >= cc[(k + n - 1) % n] && cc[k] > cc[(k + 1) % n])
        .map(|k| {
            // Parabolic interpolation of the peak for a sub-bin angle.
            let (l, m, r) = (cc[(k + n - 1) % n], cc[k], cc[(k + 1) % n]);
            let den = l - 2.0 * m + r;
            let off = if den.abs() > 1e-15 {
                0.5 * (l - r) / den
            } else {
                0.0
            };
            (m, (k as f64 + off.clamp(-0.5, 0.5)) * PI / n as f64)
        })
        .collect();
    maxima.sort_by(|x, y| y.0.total_cmp(&x.0));
    maxima.into_iter().take(peaks).map(|(_, a)| a).collect()
}

/// Coarse likelihood field of A: 1 on walls (0.5 next to them), `-free_penalty` on free space,
/// zero where unknown; and A's coarse known mask: cells holding a wall or free pixel, or next
/// to a wall. The mask comes from the pixel counts, not from the field's value, so that it is
/// right whatever `free_penalty` is (at 0 free space would otherwise look unknown).
fn coarse_field(
    a: &PreparedMap,
    scale: f64,
    w: usize,
    h: usize,
    free_penalty: f32,
) -> (Vec<f32>, Vec<bool>) {
    let mut occ = vec![0u32; w * h];
    let mut free = vec![0u32; w * h];
    let g = a.grid;
    // Each pixel's coarse cell is `(x / scale, y / scale)` truncated: the column's part is
    // worked out once per column, the row's once per row.
    let columns: Vec<usize> = (0..g.width())
        .map(|x| (x as f64 / scale) as usize)
        .collect();
    for (y, row) in g.cells().chunks_exact(g.width().max(1)).enumerate() {
        let cy = (y as f64 / scale) as usize;
        if cy >= h {
            continue;
        }
        let (occ_row, free_row) = (&mut occ[cy * w..][..w], &mut free[cy * w..][..w]);
        for (&cell, &cx) in row.iter().zip(&columns) {
            if cx >= w {
                continue;
            }
            match OccupancyGrid::classify(cell) {
                CellState::Occupied => occ_row[cx] += 1,
                CellState::Free => free_row[cx] += 1,
                CellState::Unknown => {}
            }
        }
    }
    let mut field = vec![0f32; w * h];
    for i in 0..w * h {
        field[i] = if occ[i] > 0 {
            1.0
        } else if free[i] > 0 {
            -free_penalty
        } else {
            0.0
        };
    }
    let mut known: Vec<bool> = (0..w * h).map(|i| occ[i] > 0 || free[i] > 0).collect();
    // Spread walls by one coarse cell so a wall off by a fraction of a cell still scores.
    let mut spread = field.clone();
    for y in 0..h {
        for x in 0..w {
            if occ[y * w + x] > 0 {
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                        let i = ny as usize * w + nx as usize;
                        spread[i] = spread[i].max(0.5);
                        known[i] = true;
                    }
                }
            }
        }
    }
    (spread, known)
}

/// Two-dimensional FFT of the row-major `w x h` image `data`, in place: every row, then
/// every column. Rows at and beyond `rows` must be zero (their transforms are zero and are
/// skipped). Columns are gathered into a contiguous block a batch at a time, so that each
/// transform reads contiguous memory, and all transforms share one scratch buffer; each
/// transform is the same as one done alone, so the result does not depend on the batching.
fn fft2(
    data: &mut [Complex32],
    (w, h): (usize, usize),
    rows: usize,
    planner: &mut FftPlanner<f32>,
    inverse: bool,
) {
    let mut plan = |n| {
        if inverse {
            planner.plan_fft_inverse(n)
        } else {
            planner.plan_fft_forward(n)
        }
    };
    let (row, col) = (plan(w), plan(h));
    let mut scratch = vec![
        Complex32::default();
        row.get_inplace_scratch_len()
            .max(col.get_inplace_scratch_len())
    ];
    let rows = rows.min(h);
    if rows > 0 {
        row.process_with_scratch(&mut data[..rows * w], &mut scratch);
    }
    const BATCH: usize = 16;
    let mut block = vec![Complex32::default(); BATCH * h];
    for x0 in (0..w).step_by(BATCH) {
        let k = BATCH.min(w - x0);
        // A whole batch copies a fixed number of cells per row (a loop the compiler unrolls;
        // the rotation sweep's bench 4-7 % faster than with the copy of any width alone).
        if k == BATCH {
            for y in 0..h {
                let row: &[Complex32; BATCH] = data[y * w + x0..][..BATCH].try_into().unwrap();
                for (j, &z) in row.iter().enumerate() {
                    block[j * h + y] = z;
                }
            }
        } else {
            for y in 0..h {
                for j in 0..k {
                    block[j * h + y] = data[y * w + x0 + j];
                }
            }
        }
        col.process_with_scratch(&mut block[..k * h], &mut scratch);
        if k == BATCH {
            for y in 0..h {
                let row: &mut [Complex32; BATCH] =
                    (&mut data[y * w + x0..][..BATCH]).try_into().unwrap();
                for (j, z) in row.iter_mut().enumerate() {
                    *z = block[j * h + y];
                }
            }
        } else {
            for y in 0..h {
                for j in 0..k {
                    data[y * w + x0 + j] = block[j * h + y];
                }
            }
        }
    }
}

/// The smallest length at least `n` whose only prime factors are 2, 3 and 5: transforms of
/// such lengths are about as fast per sample as those of powers of two, and the next power of
/// two can be nearly twice as long (the correlation images' area up to four times as large).
fn fft_len(n: usize) -> usize {
    (n.max(1)..)
        .find(|&m| {
            let mut m = m;
            for p in [2, 3, 5] {
                while m % p == 0 {
                    m /= p;
                }
            }
            m == 1
        })
        .expect("a 5-smooth number follows every n")
}

/// A placement with its correlation.
type Scored = (f32, Rigid2);

/// A's coarse likelihood field, transformed, with the geometry of the correlation images.
struct CoarseField {
    /// Coarse cell size in pixels.
    scale: f64,
    /// Side lengths of the (zero-padded) correlation images.
    nw: usize,
    nh: usize,
    /// Fourier transform of A's coarse field; for a normalised correlation, plus `i` times
    /// that of A's coarse known mask (see [`CoarseField::correlate`]).
    spectrum: Vec<Complex32>,
    /// For a normalised correlation: the mean and standard deviation of A's field over its
    /// known coarse cells (what a wall of B landing on a random known cell of A scores).
    normalization: Option<(f32, f32)>,
    /// How far apart, in coarse cells, the translations of one angle are at least (see
    /// [`SweepConfig::peak_radius`]).
    peak_radius: usize,
}

impl CoarseField {
    /// A's plain field with the global search's settings (its Hough placements and the
    /// symmetry probes' twins).
    fn of_global(a: &PreparedMap, b: &PreparedMap, config: &GlobalConfig) -> Self {
        Self::new(
            a,
            b,
            (config.coarse_size, f64::INFINITY),
            config.free_penalty,
            false,
            config.peak_radius,
            &mut FftPlanner::new(),
        )
    }

    /// A's field at a scale where the larger of the sides of A's known cells' bounding box
    /// and the diagonal of B's spans `coarse_size` cells, or more where a cell would then be
    /// larger than `max_cell_px` pixels (up to twice as many: [`SweepConfig::max_cell_px`]),
    /// padded so that every shift of B stays unambiguous.
    fn new(
        a: &PreparedMap,
        b: &PreparedMap,
        (coarse_size, max_cell_px): (usize, f64),
        free_penalty: f32,
        normalized: bool,
        peak_radius: usize,
        planner: &mut FftPlanner<f32>,
    ) -> Self {
        let (wa, ha) = (a.grid.width() as f64, a.grid.height() as f64);
        let diag_b = ((b.grid.width() as f64).powi(2) + (b.grid.height() as f64).powi(2)).sqrt();
        // The scale follows the known cells' extents, not the grids' sizes, so that a map's
        // unknown border (its frame's margin, `PairConfig::frame_margin`) does not coarsen it.
        let extent = |m: &PreparedMap| {
            m.grid
                .known_bounds(0)
                .map_or((m.grid.width(), m.grid.height()), |(_, _, w, h)| (w, h))
        };
        let ((ka_w, ka_h), (kb_w, kb_h)) = (extent(a), extent(b));
        let known_diag_b = (kb_w as f64).hypot(kb_h as f64);
        // At most `max_cell_px` pixels a cell, but no more than twice `coarse_size` cells.
        let span = (ka_w.max(ka_h) as f64).max(known_diag_b);
        let scale = (span / coarse_size as f64)
            .min(max_cell_px)
            .max(span / (2 * coarse_size) as f64)
            .max(1.0);
        let (cw, ch) = (
            (wa / scale).ceil() as usize + 1,
            (ha / scale).ceil() as usize + 1,
        );
        let bside = (diag_b / scale).ceil() as usize + 2;
        let (nw, nh) = (fft_len(cw + bside), fft_len(ch + bside));
        let (field, known) = coarse_field(a, scale, cw, ch, free_penalty);
        let mut spectrum = vec![Complex32::default(); nw * nh];
        for y in 0..ch {
            for x in 0..cw {
                let i = y * cw + x;
                let k = if normalized && known[i] { 1.0 } else { 0.0 };
                spectrum[y * nw + x] = Complex32::new(field[i], k);
            }
        }
        // Both transforms at once: F_A + i K_A, two real images.
        fft2(&mut spectrum, (nw, nh), ch, planner, false);
        let normalization = normalized.then(|| {
            let vals: Vec<f64> = field
                .iter()
                .zip(&known)
                .filter(|(_, k)| **k)
                .map(|(&v, _)| v as f64)
                .collect();
            let n = vals.len().max(1) as f64;
            let mean = vals.iter().sum::<f64>() / n;
            let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
            (mean as f32, var.sqrt().max(1e-6) as f32)
        });
        Self {
            scale,
            nw,
            nh,
            spectrum,
            normalization,
            peak_radius,
        }
    }

    /// The best `peaks` translations for B's wall points `pb` turned by `theta`: local maxima
    /// of `C(t) = sum_u F_A(u + t) P_B(u)`, as B→A transforms with their correlation, best
    /// first; and, for a normalised field, the best `peaks` of the normalised correlation
    /// (empty otherwise), from the same transforms.
    fn correlate(
        &self,
        pb: &[DVec2],
        theta: f64,
        peaks: usize,
        planner: &mut FftPlanner<f32>,
        bufs: &mut Buffers,
    ) -> (Vec<Scored>, Vec<Scored>) {
        let splat = self.correlation(pb, theta, planner, &mut bufs.z);
        let scores = (&mut bufs.plain, &mut bufs.normalized);
        self.peaks(&bufs.z, theta, &splat, peaks, scores)
    }

    /// The correlation images of [`Self::correlate`] into `buf` (`C(t)` in the real parts,
    /// for a normalised field `N(t)` in the imaginary ones, both times `nw * nh`).
    fn correlation(
        &self,
        pb: &[DVec2],
        theta: f64,
        planner: &mut FftPlanner<f32>,
        buf: &mut Vec<Complex32>,
    ) -> Splat {
        let (nw, nh) = (self.nw, self.nh);
        buf.clear();
        buf.resize(nw * nh, Complex32::default());
        let splat = self.splat(pb, theta, buf, false);
        fft2(buf, (nw, nh), splat.rows, planner, false);
        for (x, y) in buf.iter_mut().zip(&self.spectrum) {
            *x = y * x.conj();
        }
        fft2(buf, (nw, nh), nh, planner, true);
        splat
    }

    /// [`Self::correlate`] for two angles at once, with one forward transform for both: B's
    /// two turned images are real, so one goes into the real part and the other into the
    /// imaginary part, and their transforms are parted by symmetry
    /// (`X1[k] = (Z[k] + conj Z[-k]) / 2`, `X2[k] = (Z[k] - conj Z[-k]) / 2i`). The same
    /// correlations as two [`Self::correlate`]s up to the transforms' rounding.
    fn correlate_pair(
        &self,
        pb: &[DVec2],
        thetas: [f64; 2],
        peaks: usize,
        planner: &mut FftPlanner<f32>,
        bufs: &mut Buffers,
    ) -> [(Vec<Scored>, Vec<Scored>); 2] {
        let splats = self.correlations(pb, thetas, planner, (&mut bufs.z, &mut bufs.second));
        let (plain, normalized) = (&mut bufs.plain, &mut bufs.normalized);
        let first = self.peaks(&bufs.z, thetas[0], &splats[0], peaks, (plain, normalized));
        let second = self.peaks(
            &bufs.second,
            thetas[1],
            &splats[1],
            peaks,
            (plain, normalized),
        );
        [first, second]
    }

    /// The correlation images of [`Self::correlate_pair`]: those of [`Self::correlation`] for
    /// each angle, into each of `bufs`.
    fn correlations(
        &self,
        pb: &[DVec2],
        thetas: [f64; 2],
        planner: &mut FftPlanner<f32>,
        (z, second): (&mut Vec<Complex32>, &mut Vec<Complex32>),
    ) -> [Splat; 2] {
        let (nw, nh) = (self.nw, self.nh);
        z.clear();
        z.resize(nw * nh, Complex32::default());
        second.clear();
        second.resize(nw * nh, Complex32::default());
        let splats = [
            self.splat(pb, thetas[0], z, false),
            self.splat(pb, thetas[1], z, true),
        ];
        fft2(
            z,
            (nw, nh),
            splats[0].rows.max(splats[1].rows),
            planner,
            false,
        );
        // Part the transforms and multiply each by A's spectrum, a cell and its mirror
        // `-k` together (the product overwrites both).
        let half = Complex32::new(0.5, 0.0);
        let minus_half_i = Complex32::new(0.0, -0.5);
        for ky in 0..nh {
            let my = if ky == 0 { 0 } else { nh - ky };
            for kx in 0..nw {
                let mx = if kx == 0 { 0 } else { nw - kx };
                let (k, m) = (ky * nw + kx, my * nw + mx);
                if m < k {
                    continue;
                }
                let (zk, zm) = (z[k], z[m]);
                let (x1k, x2k) = ((zk + zm.conj()) * half, (zk - zm.conj()) * minus_half_i);
                let (x1m, x2m) = ((zm + zk.conj()) * half, (zm - zk.conj()) * minus_half_i);
                let (sk, sm) = (self.spectrum[k], self.spectrum[m]);
                (z[k], second[k]) = (sk * x1k.conj(), sk * x2k.conj());
                (z[m], second[m]) = (sm * x1m.conj(), sm * x2m.conj());
            }
        }
        fft2(z, (nw, nh), nh, planner, true);
        fft2(second, (nw, nh), nh, planner, true);
        splats
    }

    /// B's wall points `pb` turned by `theta`, as ones on the coarse grid (shifted so that the
    /// lowest lands at 0) in the real part of `buf` (the imaginary part when `imaginary`),
    /// which must be zero there.
    fn splat(&self, pb: &[DVec2], theta: f64, buf: &mut [Complex32], imaginary: bool) -> Splat {
        let (nw, nh, scale) = (self.nw, self.nh, self.scale);
        let rot = DVec2::from_angle(theta);
        let q: Vec<DVec2> = pb.iter().map(|p| rot.rotate(*p)).collect();
        let qmin = q
            .iter()
            .copied()
            .fold(DVec2::splat(f64::INFINITY), DVec2::min);
        let (mut cells, mut rows) = (0usize, 0usize);
        for p in &q {
            let u = (*p - qmin) / scale;
            // `u` is not negative: `u + 0.5` truncated is `u` rounded (`f64::round` is a library
            // call), but where `u + 0.5` rounds up to a whole number (`u` within 2^-53 below a
            // half).
            let (ux, uy) = ((u.x + 0.5) as usize, (u.y + 0.5) as usize);
            if ux < nw && uy < nh {
                let z = &mut buf[uy * nw + ux];
                let part = if imaginary { &mut z.im } else { &mut z.re };
                if *part == 0.0 {
                    *part = 1.0;
                    cells += 1;
                    rows = rows.max(uy + 1);
                }
            }
        }
        Splat { qmin, cells, rows }
    }

    /// The peaks of [`Self::correlate`] from the inverse transform `buf` of the product of A's
    /// spectrum and B's image (splatted as `splat`) turned by `theta`; `scores` is scratch
    /// space for the plain and the normalised score images.
    fn peaks(
        &self,
        buf: &[Complex32],
        theta: f64,
        splat: &Splat,
        peaks: usize,
        (plain, normalized): (&mut Vec<f32>, &mut Vec<f32>),
    ) -> (Vec<Scored>, Vec<Scored>) {
        let (nw, nh, scale) = (self.nw, self.nh, self.scale);
        let (qmin, cells) = (splat.qmin, splat.cells);
        // B's image is real, so the real part is C(t) and, for a normalised field, the
        // imaginary part N(t): how many of B's wall cells land on known cells of A (both scaled
        // by the image size, the inverse FFT being unnormalised).
        let placement = |tx: usize, ty: usize| {
            let wrap = |t: usize, n: usize| {
                if t > n / 2 {
                    t as f64 - n as f64
                } else {
                    t as f64
                }
            };
            // Negative shifts are wrapped around.
            let t = scale * DVec2::new(wrap(tx, nw), wrap(ty, nh)) - qmin;
            Rigid2::new(theta, t.x, t.y).normalized()
        };
        let best = |score: &[f32]| {
            local_maxima(score, nw, nh, peaks, self.peak_radius)
                .into_iter()
                .map(|(v, tx, ty)| (v, placement(tx, ty)))
                .collect::<Vec<_>>()
        };
        plain.clear();
        plain.extend(buf.iter().map(|z| z.re));
        let Some((mean, sd)) = self.normalization else {
            return (best(plain), Vec::new());
        };
        // A random placement scores about `mean * N` with a spread of `sd * sqrt(N)`; the
        // normalised ranking is by how far above that a placement is, so that a larger overlap
        // does not win by its size alone. Placements with fewer than a tenth of B's wall cells
        // on known cells of A are not considered.
        let size = (nw * nh) as f32;
        let min_cells = (0.1 * cells as f32).max(5.0);
        normalized.clear();
        normalized.extend(buf.iter().map(|z| {
            let (c, n) = (z.re / size, z.im / size);
            // Computed everywhere and then chosen, without a branch, so that the loop
            // vectorises (a square root of a negative rounding error is chosen away).
            let v = (c - mean * n) / (sd * n.sqrt());
            if n >= min_cells { v } else { 0.0 }
        }));
        (best(plain), best(normalized))
    }
}

/// Scratch space of the correlations, one per thread: the transforms' images and the score
/// images their peaks are read from, allocated once rather than per angle (each a fresh
/// mapping of a few hundred kilobytes, whose pages the kernel faults in and zeroes).
#[derive(Default)]
struct Buffers {
    z: Vec<Complex32>,
    second: Vec<Complex32>,
    plain: Vec<f32>,
    normalized: Vec<f32>,
}

/// Where [`CoarseField::splat`] put B's turned walls: the shift of its lowest point to the
/// origin, the cells set and the rows they reach.
struct Splat {
    qmin: DVec2,
    cells: usize,
    rows: usize,
}

/// The best `peaks` positive local maxima `(value, x, y)` of the `w x h` image `score` (its
/// borders wrapped around), highest first: cells that no cell within `radius` cells (a
/// square of side `2 radius + 1`; at least 1) exceeds.
fn local_maxima(
    score: &[f32],
    w: usize,
    h: usize,
    peaks: usize,
    radius: usize,
) -> Vec<(f32, usize, usize)> {
    // The best so far, highest first; among equal values, first found first (a stable sort
    // of all maxima, truncated, gives the same).
    let mut found: Vec<(f32, usize, usize)> = Vec::with_capacity(peaks + 1);
    if peaks == 0 {
        return found;
    }
    let wrap = |t: usize, d: i64, n: usize| (t as i64 + d).rem_euclid(n as i64) as usize;
    // Only a value above the worst kept can enter (ties keep the earlier one).
    let enters = |v: f32, found: &[(f32, usize, usize)]| {
        v > 0.0 && (found.len() < peaks || v > found[peaks - 1].0)
    };
    // A row is read a run of cells at a time, and a run whose largest value cannot enter is
    // skipped whole (most are, once `peaks` maxima are kept): the same cells enter.
    const RUN: usize = 32;
    for ty in 0..h {
        let inner_row = ty > 0 && ty + 1 < h;
        let row = &score[ty * w..(ty + 1) * w];
        for x0 in (0..w).step_by(RUN) {
            let end = (x0 + RUN).min(w);
            let top = row[x0..end]
                .iter()
                .copied()
                .fold(f32::NEG_INFINITY, f32::max);
            if !enters(top, &found) {
                continue;
            }
            for tx in x0..end {
                let v = row[tx];
                if !enters(v, &found) {
                    continue;
                }
                // The eight neighbours first: most cells fail there, and a cell that is not
                // the largest of those is not the largest of a wider window either.
                let is_max = if inner_row && tx > 0 && tx + 1 < w {
                    // Away from the borders the neighbours need no wrapping.
                    let i = ty * w + tx;
                    [
                        i - w - 1,
                        i - w,
                        i - w + 1,
                        i - 1,
                        i + 1,
                        i + w - 1,
                        i + w,
                        i + w + 1,
                    ]
                    .iter()
                    .all(|&j| score[j] <= v)
                } else {
                    (-1i64..=1).all(|dy| {
                        (-1i64..=1).all(|dx| {
                            (dx == 0 && dy == 0)
                                || score[wrap(ty, dy, h) * w + wrap(tx, dx, w)] <= v
                        })
                    })
                };
                if is_max && (radius <= 1 || window_max(score, (w, h), (tx, ty), radius, v)) {
                    let at = found.partition_point(|f| f.0 >= v);
                    found.insert(at, (v, tx, ty));
                    found.truncate(peaks);
                }
            }
        }
    }
    found
}

/// Whether no cell of the `w x h` image `score` (borders wrapped around) within `radius`
/// cells of `(x, y)` exceeds `v`.
fn window_max(
    score: &[f32],
    (w, h): (usize, usize),
    (x, y): (usize, usize),
    radius: usize,
    v: f32,
) -> bool {
    if x >= radius && x + radius < w && y >= radius && y + radius < h {
        // Inside the image the window needs no wrapping.
        return (y - radius..=y + radius).all(|r| {
            score[r * w + x - radius..=r * w + x + radius]
                .iter()
                .all(|&s| s <= v)
        });
    }
    // A window wider than the image meets some cells twice, which is harmless.
    let wrap = |t: usize, d: usize, n: usize| (t + n * (1 + radius / n) + d - radius) % n;
    (0..=2 * radius).all(|dy| {
        let row = &score[wrap(y, dy, h) * w..][..w];
        (0..=2 * radius).all(|dx| row[wrap(x, dx, w)] <= v)
    })
}

/// The rotation of B onto A (radians) that the Hough spectra of the maps' walls give nearest
/// to `theta`, if one lies within `max_delta` of it (modulo a half turn, the spectrum's
/// period): the spectrum correlation's peaks, interpolated to a fraction of a bin, over
/// `bins` bins of `[0, pi)`. The spectra take every wall of both maps, in the overlap or not,
/// so on maps whose walls share their directions (buildings, a walled arena) this angle does
/// not depend on how much the maps overlap.
pub fn spectrum_rotation_near(
    a: &PreparedMap,
    b: &PreparedMap,
    theta: f64,
    bins: usize,
    max_points: usize,
    max_delta: f64,
) -> Option<f64> {
    let pa = strided(&a.wall_samples, max_points);
    let pb = strided(&b.wall_samples, max_points);
    if pa.len() < 10 || pb.len() < 10 || bins < 3 {
        return None;
    }
    let (sa, sb) = (hough_spectrum(&pa, bins), hough_spectrum(&pb, bins));
    let half = |d: f64| {
        let d = d.rem_euclid(PI);
        if d > PI / 2.0 { d - PI } else { d }
    };
    rotation_candidates(&sa, &sb, 6)
        .into_iter()
        .map(|k| half(k - theta))
        .filter(|d| d.abs() <= max_delta)
        .min_by(|x, y| x.abs().total_cmp(&y.abs()))
        .map(|d| theta + d)
}

/// A map's dominant wall direction modulo a quarter turn ([`manhattan_direction`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManhattanDirection {
    /// Normal angle of the dominant wall family, radians in `[0, pi/2)`; the walls at right
    /// angles to it count with it.
    pub angle: f64,
    /// How much sharper the walls' projections are along that direction and its right angle
    /// than along the directions 45 degrees off: the Hough spectrum (sum of squared counts over
    /// 1 px distance bins) of both there over both here. About 1 for walls without a dominant
    /// direction (rubble, round obstacles); a floor of straight walls at right angles scores
    /// several times that.
    pub contrast: f64,
}

/// Hough spectrum value of centred `points` at normal angle `phi`: the sum of squared counts
/// over 1 px distance bins, each point's vote split linearly between its two bins so that
/// the value is continuous in `phi` (a search for its maximum can then go below a bin's
/// angle).
fn projection_sharpness(points: &[DVec2], phi: f64, rmax: f64, acc: &mut Vec<f64>) -> f64 {
    let (s, c) = phi.sin_cos();
    acc.clear();
    acc.resize(2 * rmax.ceil() as usize + 3, 0.0);
    for p in points {
        let r = p.x * c + p.y * s + rmax;
        let f = r.floor();
        let w = r - f;
        let i = f as usize;
        acc[i] += 1.0 - w;
        acc[i + 1] += w;
    }
    acc.iter().map(|v| v * v).sum()
}

/// The dominant direction of a set of wall points modulo a quarter turn, where the Hough
/// spectrum of the walls and of the walls at right angles to them is sharpest: on a floor
/// built at right angles (a warehouse, most buildings: the "Manhattan world" of indoor
/// mapping) every straight wall of the map votes for it, wherever it is, so the angle does not
/// rest on the short lever of a small overlap. A coarse scan every half degree on at most
/// [`MANHATTAN_COARSE_POINTS`] of the points (evenly strided), then a golden-section search of
/// the continuous spectrum of all of them within a step of the best; `None` for fewer than 10
/// points.
pub fn manhattan_direction(points: &[DVec2]) -> Option<ManhattanDirection> {
    if points.len() < 10 {
        return None;
    }
    let c = points.iter().copied().sum::<DVec2>() / points.len() as f64;
    let centred: Vec<DVec2> = points.iter().map(|p| *p - c).collect();
    let coarse = strided(&centred, MANHATTAN_COARSE_POINTS);
    let rmax = centred.iter().map(|p| p.length()).fold(0.0, f64::max) + 1.0;
    let mut acc = Vec::new();
    let mut both = |points: &[DVec2], phi: f64| {
        projection_sharpness(points, phi, rmax, &mut acc)
            + projection_sharpness(points, phi + PI / 2.0, rmax, &mut acc)
    };
    let step = 0.5f64.to_radians();
    let steps = (PI / 2.0 / step).round() as usize;
    let (mut best, mut best_value) = (0.0, f64::MIN);
    for k in 0..steps {
        let phi = k as f64 * step;
        let v = both(&coarse, phi);
        if v > best_value {
            (best, best_value) = (phi, v);
        }
    }
    // Golden section on all the points: the bracket shrinks by 0.618 an evaluation, to well
    // under a thousandth of a degree.
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (best - step, best + step);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (both(&centred, x1), both(&centred, x2));
    for _ in 0..30 {
        if f1 < f2 {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = both(&centred, x2);
        } else {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = both(&centred, x1);
        }
    }
    let angle = (0.5 * (lo + hi)).rem_euclid(PI / 2.0);
    let contrast = both(&centred, angle) / both(&centred, angle + PI / 4.0).max(1e-12);
    Some(ManhattanDirection { angle, contrast })
}

/// Points [`manhattan_direction`]'s coarse scan takes at most: on the warehouse pairs of
/// `cargo xtask eval --suites large --seed 7` 3000 points found the same peak as 20 000.
pub const MANHATTAN_COARSE_POINTS: usize = 3000;

/// Append global-search hypotheses (B→A, pixel convention) to `out`.
pub fn global_hypotheses(
    a: &PreparedMap,
    b: &PreparedMap,
    config: &GlobalConfig,
    out: &mut Vec<Rigid2>,
) {
    let pa = strided(&a.wall_samples, config.max_points);
    let pb = strided(&b.wall_samples, config.max_points);
    if pa.len() < 10 || pb.len() < 10 {
        return;
    }
    let sa = hough_spectrum(&pa, config.angle_bins);
    let sb = hough_spectrum(&pb, config.angle_bins);
    let mut angles = Vec::new();
    for base in rotation_candidates(&sa, &sb, config.rotation_peaks) {
        angles.push(base);
        angles.push(base + PI);
    }
    let field = CoarseField::of_global(a, b, config);
    // The angles' correlations are independent: side by side, collected in order.
    let found: Vec<Vec<Rigid2>> = angles
        .par_iter()
        .map_init(
            || (FftPlanner::<f32>::new(), Buffers::default()),
            |(planner, bufs), &theta| {
                let (found, _) =
                    field.correlate(&pb, theta, config.translation_peaks, planner, bufs);
                found.into_iter().map(|(_, t)| t).collect()
            },
        )
        .collect();
    out.extend(found.into_iter().flatten());
}

/// Append the twins of placement `b_to_a` to `out`: for its angle, and its angle plus a
/// quarter, a half and three quarters of a turn, the best `config.translation_peaks`
/// translations of B's walls on A's coarse wall field (as in [`global_hypotheses`]), in that
/// order (deterministic). Maps that look alike shifted or turned (a row of rooms, a bare
/// room) fit a twin about as well as the placement itself; [`crate::register_with`] refines
/// and verifies the twins so that such a pair is declined as ambiguous rather than answered
/// by a coin toss.
pub fn twins(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    config: &GlobalConfig,
    out: &mut Vec<Rigid2>,
) {
    let pb = strided(&b.wall_samples, config.max_points);
    if pb.len() < 10 || a.wall_samples.len() < 10 {
        return;
    }
    let field = CoarseField::of_global(a, b, config);
    // The first turn is none: the other translation peaks of the placement's own angle are
    // its shifted twins (a row of alike rooms).
    // Two angles share a forward transform ([`CoarseField::correlate_pair`]).
    let found: Vec<Rigid2> = [[0.0, 0.5], [1.0, 1.5]]
        .par_iter()
        .map_init(
            || (FftPlanner::<f32>::new(), Buffers::default()),
            |(planner, bufs), turns| {
                let thetas = turns.map(|k| b_to_a.theta + k * PI);
                field
                    .correlate_pair(&pb, thetas, config.translation_peaks, planner, bufs)
                    .map(|(plain, _)| plain)
            },
        )
        .flatten_iter()
        .flatten_iter()
        .map(|(_, t)| t)
        .collect();
    out.extend(found);
}

/// Parameters of the rotation sweep, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepConfig {
    /// Angle step of the sweep over the full turn, in degrees. Default 2.
    pub step_deg: f64,
    /// Cells of the coarse correlation images across the longest of the side of A's known
    /// cells' bounding box and the diagonal of B's (as [`GlobalConfig::coarse_size`]).
    /// Default 96 (about 5 px per cell for the 400 x 400 simulated maps): coarse enough to be
    /// cheap and to absorb walls that a noisy sensor smeared over several pixels.
    pub coarse_size: usize,
    /// The largest coarse cell, in pixels: a map whose extent (as for `coarse_size`) would
    /// put more pixels in a cell gets more than `coarse_size` cells, up to twice as many.
    /// Default 12 (`f64::INFINITY`: always `coarse_size` cells, the rule before 2026-12-06).
    /// At `coarse_size` cells the robots' maps of the uos_cic floor (1000-1500 px across) had
    /// cells of 13-15 px, which smear a large hall's few walls into its clutter: in three of
    /// the pairs at 30 % overlap declined at seed 23 the placement near the truth ranked
    /// 101st-139th by the normalised correlation, after the 100 screened, and 29th-82nd with
    /// cells of at most 12 px (scratch code). With 12, the uos_cic floor at 30 % overlap
    /// (`cargo xtask eval --suites floors`, seeds 7 and 8, and seed 23 of the full table)
    /// registered 13, 15 and 18 of 20 pairs instead of 13, 14 and 15 (with 10: 13, 15, 17);
    /// no other floor's row changed, and every row that changed in the regression batch
    /// (the large floors) rose or held. The hard bench pair's registration takes 5 % more
    /// instructions (`docs/EVALUATION.md`, "Large floors swept on finer cells").
    pub max_cell_px: f64,
    /// Wall points of B correlated at most. Default 4000.
    pub max_points: usize,
    /// Placements kept, best correlation first, pairwise distinct (see `distinct_px`).
    /// Default 8.
    pub keep: usize,
    /// Placements of the normalised ranking kept (see `normalized`), besides the `keep` of
    /// the plain one. Default 24; see `translation_peaks` for how it was chosen.
    pub keep_normalized: usize,
    /// Translations kept per angle (local maxima of the correlation, best first) before the
    /// placements of all angles are ranked. Default 10. At 30 % overlap the placement near the
    /// truth is often not the best translation of its angle (B's long walls laid along A's
    /// score more) and ranks 15th-30th among the normalised ranking's distinct placements
    /// (disaster cases 7000006 and 7000014 of `cargo xtask eval --seed 7`). On `cargo xtask
    /// eval --suites overlap --only "overlap 0.3" --cases 20 --seed S`, disaster 30 %
    /// registered at seeds 7, 3 and 4: 55, 25 and 40 % with one translation and 8 normalised
    /// placements (the rule before), 65, 25 and 45 % with 10 and 24, 60, 30 and 45 % with 10
    /// and 40; at seed 7 alone 50 % with 10 and 8, 55 % with 1 and 40; indoor 30 % unchanged
    /// in each (95, 85, 80 %). Swept pairs take about 10-35 % longer with 10 and 24 (see
    /// "What the sweep's lesser peaks and the screen changed" in `docs/EVALUATION.md`).
    pub translation_peaks: usize,
    /// How far apart the `translation_peaks` of one angle are at least, in coarse cells: a
    /// translation is kept only where no other within this many cells (a square of side
    /// `2 peak_radius + 1`) correlates better. Default 3. With 1 (local maxima among the eight
    /// neighbours, the rule before) an angle's places went to the lesser bumps of its best few
    /// hills (the coarse correlation of noisy walls is bumpy), which the ranking then drops as
    /// not `distinct_px` from the hills' tops. Of the 24 pairs of the 30 % rows of `cargo xtask
    /// eval --suites overlap --only "overlap 0.3" --seed S` (S = 7, 8, 9, both mappers) with no
    /// candidate within 3 px of the truth, declined, 21 had no placement within 15 px and 4
    /// degrees of it among the normalised ranking's first 1000 with 1; with 3, 18 had one
    /// among the 100 screened and 14 among the 24 the screen keeps (scratch code). Over those
    /// rows and the real floors (seeds 7-9; hector 8-9) the successes went from 84, 99, 107
    /// and 127 to 88, 105, 107 and 127 with 3 (88, 105, 105, 127 with 5), and every
    /// zero-overlap outcome stayed (`docs/EVALUATION.md`, "Sweep peaks apart").
    pub peak_radius: usize,
    /// Placements of the normalised ranking screened before the `keep_normalized` best are
    /// refined: [`crate::register_with`] runs its correlative local search from each of the
    /// `screened` best and keeps the `keep_normalized` that then pass verification, or else
    /// that the maps agree with most ([`crate::verify::Verification::score`]; passing first
    /// since 2026-12-05, see "The screen keeps passing placements" in `docs/EVALUATION.md`).
    /// `0` (or no more than `keep_normalized`) screens nothing. Default 100. In the disaster
    /// 30 % pairs of `cargo xtask eval --suites overlap --only "overlap 0.3" --seed 3` and
    /// `--seed 4` with no candidate near the truth, the placement near it ranked 18th-43rd by
    /// the normalised correlation and second once searched and scored (3000005, 3000018,
    /// 4000016; scratch code). On that command, disaster 30 % at seeds 7, 3 and 4: 65, 25 and
    /// 45 % unscreened, 60, 30 and 50 % with 100 screened (4 of the 5 pairs of seeds 3 and 4
    /// with no candidate within 30 px of the truth got one within 5.2 px; seed 7's loss is case
    /// 7000013, 2.99 -> 3.11 px), 55, 30 and 50 % keeping 12 of the 100; indoor 30 % unchanged
    /// (95, 85, 80 %). With the lesser peaks it raised the mean time per case of the eval
    /// table's rows by 10-60 % (`docs/EVALUATION.md`, "What the sweep's lesser peaks and the
    /// screen changed"). With passing placements first,
    /// 200 screened registered 2 pairs more and lost 3 over the 30 % rows at seeds 7-12 (both
    /// mappers), and accepted two answers 215 and 412 px off (`--sweep-screen 200`), so 100
    /// stays.
    pub screened: usize,
    /// Two placements are distinct when B's wall centre lands this far apart under them, or
    /// their angles differ by more than twice the step. Default 12 px.
    pub distinct_px: f64,
    /// The sweep is skipped when a feature-based (RANSAC) candidate passed verification with
    /// at least this wall lift (see [`crate::verify::Verification::wall_lift`]). Default 0.8.
    /// Sweeping after every other accepted answer too, rather than only when nothing passed,
    /// improved the eval (`cargo xtask eval --suites overlap,zero,paper,real --seed 3` and
    /// `--seed 4`, and `--seed 7` with `noise`: 19 pairs more within 3 px, 4 fewer, all 4 on
    /// seed 3 and 3 of them aws_small_house, where the sweep found a placement 5 px off that
    /// fits better than the one 2.5 px off; on `--suites mismatch --seed 7`, over the three
    /// methods, 1 more and 3 fewer pairs, each moving across the 3 px line), at about 0.4 s
    /// per swept pair.
    pub confident_wall_lift: f64,
    /// What a wall of B landing on a free coarse cell of A costs, against 1 for landing on a
    /// wall of A and 0 on unknown. Default 0.5. A dearer free space (1.0) puts a placement
    /// within 15 px of the truth among the kept ones far more often at 30 % overlap (disaster
    /// worlds, first 20 cases of seeds 7, 3 and 4: 7, 9 and 8 pairs at 0.5 against 14, 16
    /// and 14 at 1.0; scratch code), but those placements then refine 3-7 px off as often as
    /// not, and `cargo xtask eval --suites overlap,zero,paper,real,noise --seed 7
    /// --sweep-free-penalty 1` registers no more pairs (two fewer over all rows; `--seed 3`'s
    /// 30 % rows: three more), so the default stays.
    pub free_penalty: f32,
    /// Rank placements by how far their correlation lies above what a random placement with
    /// as much of B's walls on known cells of A would reach, in standard deviations, instead of
    /// by the correlation itself (see `CoarseField::correlate`): the `keep_normalized` best of
    /// that ranking are proposed besides the `keep` best by the plain correlation (those distinct
    /// from them). Default true: the plain correlation grows with how much of B lands on A's
    /// known area, so large wrong overlaps outrank a small true one. On `cargo xtask eval
    /// --suites overlap,zero,paper,real,noise --cases 20 --seed 7` (with the spectrum angle)
    /// disaster 0.3 rose from 35 to 40 %, indoor 0.3 from 90 to 95 %, wpi 10 -> 15 %, uos
    /// 15 -> 25 %, intel 50 -> 65 %, no row fell, and every zero-overlap pair was declined.
    pub normalized: bool,
    /// When no candidate passes verification after the sweep, or the best that passes would be
    /// declined (its walls in the other map's free space, a misfit, a rival), sweep again with the
    /// maps' roles swapped (A's walls turned over B's coarse field) and propose those placements
    /// too, inverted, screened like the first ones. Default true. (The second case since
    /// 2026-12-07: over the regression batch no pair won or lost and one answer to a pair that
    /// shares nothing, 229 px off, was declined; at five held-out seeds' 30 % rows 2 pairs won and
    /// none lost: docs/EVALUATION.md, "A clean placement succeeds a declined best".) The sweep
    /// correlates one map's walls over the other's field, and its normalised ranking weighs the
    /// moving map's walls that land on the field's known cells, so the two directions rank a small
    /// true overlap differently: over the 30 % rows of `cargo xtask eval --suites overlap --only
    /// "overlap 0.3" --seed S` (S = 7-12) it registered 181 instead of 177 of the default mapper's
    /// 240 pairs (false accepts 52 -> 50) and 222 of hector's as before (false accepts 8 -> 10,
    /// both 3.7-6.2 px off), the default mapper's real floors (seeds 7-9) 109 instead of 107 of
    /// 240, hector's (seeds 8-9) as before; of the zero-overlap pairs it accepted no more of the
    /// 281 of `--suites zero,noise --only "must decline"` (seeds 1, 2, 3, 7: the same four as
    /// without) and one more of the 63 of the seed-7 table, 221 px off (`--no-reverse-sweep`;
    /// `docs/EVALUATION.md`, "The sweep the other way round"). Only pairs that would be declined
    /// pay for it: about 200 ms more per zero-overlap pair of the eval.
    pub reverse: bool,
    /// How deep the deep screen reaches down each sweep's normalised ranking. When no
    /// candidate passes after both sweeps, the placements of both normalised rankings after
    /// the `screened` ones, down to this many, are searched and verified as the screen's are,
    /// and of those that pass the `keep_normalized` the maps agree with most are proposed. An
    /// answer found after it ran must share no less than a small overlap
    /// ([`crate::verify::SmallOverlap::below`]) whatever its fit: the deep screen's slivers
    /// serve as rivals only. `0` (or no more than `screened`) turns it off. Default 0 (off);
    /// 1000 is the depth measured.
    ///
    /// On a large floor the placement near the truth can rank far down: in the four pairs of
    /// the uos_cic floor at 30 % overlap declined at seed 7 (`cargo xtask eval --suites floors
    /// --only "uos_cic world, overlap 0.3" --seed 7`) it ranked 149th-616th where it ranked
    /// at all (`cargo run --release -p mapmerge --example sweep_ranks`), the truth fitting at
    /// wall lift 0.65-0.80 once refined, anything screened at 0.40-0.47. Over the
    /// regression batch it registered 11 pairs more and lost none, and answered no pair that
    /// shares nothing (docs/EVALUATION.md, "The deep screen, off by default"). Only pairs
    /// where nothing passed pay for it, but they pay much: the declined bench pair (2048 x
    /// 2048) takes about three times as long (`cargo bench -p mapmerge --bench register`,
    /// `end_to_end_partial_maps_declined_deep_screen`: 669 ms against 239 ms without it, on
    /// 2 cores). It stays off because
    /// at five held-out seeds it answered five open-hall pairs of the simulated 30 % rows
    /// 206-233 px off (declined without it) for two more registered. `mapmerge estimate|merge
    /// --deep-screen` turns it on at 1000.
    pub deep_screened: usize,
}

impl SweepConfig {
    /// How far down the normalised ranking the screen reaches: [`Self::screened`], or
    /// [`Self::keep_normalized`] when that is more. The deep screen starts below it.
    pub fn screen_depth(&self) -> usize {
        self.screened.max(self.keep_normalized)
    }
}

impl Default for SweepConfig {
    fn default() -> Self {
        Self {
            step_deg: 2.0,
            coarse_size: 96,
            max_cell_px: 12.0,
            max_points: 4000,
            keep: 8,
            keep_normalized: 24,
            translation_peaks: 10,
            peak_radius: 3,
            screened: 100,
            distinct_px: 12.0,
            confident_wall_lift: 0.8,
            free_penalty: 0.5,
            normalized: true,
            reverse: true,
            deep_screened: 0,
        }
    }
}

/// Append rotation-sweep hypotheses (B→A, pixel convention) to `out`: for every angle of a
/// full turn, in steps of `step_deg`, the `translation_peaks` best translations of B's turned
/// walls on A's coarse wall field (FFT correlation, as in [`global_hypotheses`]); then the
/// `keep` best distinct placements over all angles, and the `keep_normalized` best of the
/// normalised ranking distinct from those.
///
/// Unlike the Hough spectrum, which reads the rotation off the maps' dominant wall directions
/// and fails when the shared part is small next to the rest, the sweep tries every angle; it
/// costs one FFT correlation per angle (180 at the default step), so [`crate::register_with`]
/// runs it (as [`sweep_placements`], screening the normalised ranking) last, and not after a
/// feature-based candidate that passed with a good fit.
/// Deterministic: the angles are independent and their results are merged in angle order.
pub fn sweep_hypotheses(
    a: &PreparedMap,
    b: &PreparedMap,
    config: &SweepConfig,
    out: &mut Vec<Rigid2>,
) {
    let found = sweep_placements(a, b, config, config.keep_normalized);
    out.extend(found.plain);
    out.extend(found.normalized);
}

/// The rotation sweep's placements (B→A, pixel convention), by ranking.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SweepPlacements {
    /// The `keep` best distinct placements by the plain correlation, best first.
    pub plain: Vec<Rigid2>,
    /// The best distinct placements by the normalised correlation (empty when
    /// [`SweepConfig::normalized`] is off), best first, less those not distinct from a plain one.
    pub normalized: Vec<Rigid2>,
}

/// The rotation sweep of [`sweep_hypotheses`], its two rankings apart and `normalized_count`
/// (rather than `keep_normalized`) placements taken from the normalised one, for a caller that
/// screens them (see [`SweepConfig::screened`]).
pub fn sweep_placements(
    a: &PreparedMap,
    b: &PreparedMap,
    config: &SweepConfig,
    normalized_count: usize,
) -> SweepPlacements {
    let pb = strided(&b.wall_samples, config.max_points);
    if pb.len() < 10
        || a.wall_samples.len() < 10
        || !config.step_deg.is_finite()
        || config.step_deg <= 0.0
    {
        return SweepPlacements::default();
    }
    let centre = pb.iter().copied().sum::<DVec2>() / pb.len() as f64;
    let distinct = |kept: &[Rigid2], t: &Rigid2| {
        kept.iter().all(|k| {
            grid_core::wrap_angle(k.theta - t.theta).abs() > 2.0 * config.step_deg.to_radians()
                || (k.apply(centre) - t.apply(centre)).length() > config.distinct_px
        })
    };
    let steps = (360.0 / config.step_deg).round().max(1.0) as usize;
    // One field and one pair of transforms per angle serve both rankings: with the known mask
    // packed into the field, the plain correlation is the real part.
    let field = CoarseField::new(
        a,
        b,
        (config.coarse_size, config.max_cell_px),
        config.free_penalty,
        config.normalized,
        config.peak_radius,
        &mut FftPlanner::new(),
    );
    // Two angles share a forward transform ([`CoarseField::correlate_pair`]).
    let angle = |k: usize| (k as f64 * 2.0 * PI / steps as f64) - PI;
    let (plain, normalized): (Vec<_>, Vec<_>) = (0..steps.div_ceil(2))
        .into_par_iter()
        .map_init(
            || (FftPlanner::<f32>::new(), Buffers::default()),
            |(planner, bufs), pair| {
                let k = 2 * pair;
                if k + 1 < steps {
                    let peaks = config.translation_peaks;
                    field
                        .correlate_pair(&pb, [angle(k), angle(k + 1)], peaks, planner, bufs)
                        .to_vec()
                } else {
                    let found =
                        field.correlate(&pb, angle(k), config.translation_peaks, planner, bufs);
                    vec![found]
                }
            },
        )
        .flatten_iter()
        .unzip();
    // The `keep` best distinct placements of one ranking over all angles.
    let best = |per_angle: Vec<Vec<Scored>>, keep: usize| {
        let found: Vec<Scored> = per_angle.into_iter().flatten().collect();
        let mut order: Vec<usize> = (0..found.len()).collect();
        // Stable: ties keep angle order.
        order.sort_by(|&i, &j| found[j].0.total_cmp(&found[i].0));
        let mut kept: Vec<Rigid2> = Vec::new();
        for i in order {
            if kept.len() >= keep {
                break;
            }
            if distinct(&kept, &found[i].1) {
                kept.push(found[i].1);
            }
        }
        kept
    };
    let plain = best(plain, config.keep);
    // Then the normalised correlation's best (none when it is off), those distinct from the
    // plain ones.
    let normalized = best(normalized, normalized_count)
        .into_iter()
        .filter(|t| distinct(&plain, t))
        .collect();
    SweepPlacements { plain, normalized }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testmaps::room;
    use crate::verify::VerifyConfig;

    #[test]
    fn correlation_images_take_the_next_length_of_factors_2_3_and_5() {
        let smooth = |m: usize| {
            let mut m = m;
            for p in [2, 3, 5] {
                while m.is_multiple_of(p) {
                    m /= p;
                }
            }
            m == 1
        };
        for (n, len) in [
            (1, 1),
            (7, 8),
            (97, 100),
            (129, 135),
            (193, 200),
            (257, 270),
        ] {
            assert_eq!(fft_len(n), len, "{n}");
        }
        for n in 1..2000 {
            let len = fft_len(n);
            assert!(
                len >= n && smooth(len) && (n..len).all(|m| !smooth(m)),
                "{n} -> {len}"
            );
        }
    }

    #[test]
    fn the_local_maxima_are_those_of_a_cell_by_cell_scan() {
        // A width that is not a multiple of the runs, ties, negative and zero cells, maxima on
        // the wrapped borders, and windows wider than the image; against every maximum,
        // stably sorted and truncated.
        for (w, h) in [(75, 41), (9, 7)] {
            let mut state = 12345u64;
            let score: Vec<f32> = (0..w * h)
                .map(|_| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((state >> 33) % 23) as f32 - 6.0
                })
                .collect();
            let at = |x: i64, y: i64| {
                score[y.rem_euclid(h as i64) as usize * w + x.rem_euclid(w as i64) as usize]
            };
            for radius in [1usize, 2, 5] {
                let r = radius as i64;
                let mut all = Vec::new();
                for y in 0..h as i64 {
                    for x in 0..w as i64 {
                        let v = at(x, y);
                        let window = (-r..=r).flat_map(|dy| (-r..=r).map(move |dx| (dx, dy)));
                        if v > 0.0 && window.into_iter().all(|(dx, dy)| at(x + dx, y + dy) <= v) {
                            all.push((v, x as usize, y as usize));
                        }
                    }
                }
                all.sort_by(|p, q| q.0.total_cmp(&p.0));
                assert!(!all.is_empty(), "{w} x {h}, radius {radius}");
                for peaks in [0, 1, 5, 40, 10_000] {
                    let expected: Vec<_> = all.iter().copied().take(peaks).collect();
                    assert_eq!(
                        local_maxima(&score, w, h, peaks, radius),
                        expected,
                        "{w} x {h}, radius {radius}, {peaks} peaks"
                    );
                }
            }
        }
    }

    #[test]
    fn the_sweep_finds_a_turned_copy_and_is_deterministic() {
        let a = room();
        let vc = VerifyConfig::default();
        let pa = PreparedMap::new(&a, &vc);
        for deg in [137.0f64, -61.0, 3.0] {
            // B is A turned by `deg` and shifted onto a larger canvas; the truth maps B to A.
            let a_to_b = Rigid2::new(deg.to_radians(), 110.0, 30.0);
            let b = a.warp(&a_to_b, 240, 220).unwrap();
            let truth = a_to_b.inverse();
            let pb = PreparedMap::new(&b, &vc);
            let run = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| {
                        let mut out = Vec::new();
                        sweep_hypotheses(&pa, &pb, &SweepConfig::default(), &mut out);
                        out
                    })
            };
            let found = run(2);
            assert_eq!(found, run(1), "the thread count changed the answer");
            // The plain ranking's `keep` best, then the normalised ranking's distinct ones.
            let c = SweepConfig::default();
            assert!(found.len() <= c.keep + c.keep_normalized);
            // Within what a 2-degree step and 5-pixel cells allow: the refinement takes it
            // from there.
            let best = found
                .iter()
                .map(|t| grid_core::metrics::displacement_error(&b, t, &truth).unwrap())
                .fold(f64::INFINITY, f64::min);
            assert!(best < 6.0, "{deg} deg: nearest placement {best} px off");
            // and it is the strongest correlation, not a lucky runner-up.
            let first = grid_core::metrics::displacement_error(&b, &found[0], &truth).unwrap();
            assert!(first < 6.0, "{deg} deg: first placement {first} px off");
        }
    }

    #[test]
    fn a_deeper_normalised_ranking_begins_with_the_shallower_one() {
        // One sweep serves the screen and the deep screen (`SweepConfig::deep_screened`): the
        // first placements of a ranking must not depend on how many are taken.
        let a = room();
        let vc = VerifyConfig::default();
        let pa = PreparedMap::new(&a, &vc);
        let b = a.warp(&Rigid2::new(0.7, 110.0, 30.0), 240, 220).unwrap();
        let pb = PreparedMap::new(&b, &vc);
        let c = SweepConfig::default();
        let (shallow, deep) = (
            sweep_placements(&pa, &pb, &c, 20),
            sweep_placements(&pa, &pb, &c, 200),
        );
        assert_eq!(shallow.plain, deep.plain);
        assert!(deep.normalized.len() > shallow.normalized.len());
        assert_eq!(
            shallow.normalized[..],
            deep.normalized[..shallow.normalized.len()]
        );
    }

    #[test]
    fn a_pair_of_angles_correlates_as_each_alone() {
        let a = room();
        let vc = VerifyConfig::default();
        let b = a.warp(&Rigid2::new(0.7, 110.0, 30.0), 240, 220).unwrap();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let points = strided(&pb.wall_samples, 4000);
        let mut planner = FftPlanner::new();
        let field = CoarseField::new(&pa, &pb, (96, f64::INFINITY), 0.5, true, 1, &mut planner);
        let (mut z, mut second, mut alone) = (Vec::new(), Vec::new(), Vec::new());
        for thetas in [[-0.7, -0.66], [2.0, -3.1], [0.0, 0.0]] {
            let splats = field.correlations(&points, thetas, &mut planner, (&mut z, &mut second));
            for (k, paired) in [&z, &second].into_iter().enumerate() {
                let splat = field.correlation(&points, thetas[k], &mut planner, &mut alone);
                assert_eq!(
                    (splats[k].qmin, splats[k].cells, splats[k].rows),
                    (splat.qmin, splat.cells, splat.rows)
                );
                // Both images (C and N) the same up to the transforms' rounding.
                let top = alone
                    .iter()
                    .map(|z| z.re.abs().max(z.im.abs()))
                    .fold(0.0, f32::max);
                assert!(top > 1e3, "{thetas:?}: an empty correlation");
                for (p, q) in paired.iter().zip(&alone) {
                    assert!((p - q).norm() <= 1e-5 * top, "{thetas:?}: {p} against {q}");
                }
            }
        }
    }

    /// The row-by-row count puts each pixel in the cell of its own coordinates divided by
    /// the scale, as a pixel-by-pixel count does, with fields cut short of the grid too.
    #[test]
    fn the_coarse_field_counts_each_pixel_in_its_cell() {
        let definition = |g: &OccupancyGrid, scale: f64, w: usize, h: usize| {
            let (mut occ, mut free) = (vec![0u32; w * h], vec![0u32; w * h]);
            for y in 0..g.height() {
                for x in 0..g.width() {
                    let (cx, cy) = ((x as f64 / scale) as usize, (y as f64 / scale) as usize);
                    if cx < w && cy < h {
                        match g.state(x, y) {
                            CellState::Occupied => occ[cy * w + cx] += 1,
                            CellState::Free => free[cy * w + cx] += 1,
                            CellState::Unknown => {}
                        }
                    }
                }
            }
            (occ, free)
        };
        let vc = VerifyConfig::default();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for (gw, gh) in [(1, 1), (1, 9), (9, 1), (17, 12), (40, 33)] {
            let cells: Vec<u8> = (0..gw * gh)
                .map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    [0, 100, grid_core::UNKNOWN, 0, 70, 30][(seed % 6) as usize]
                })
                .collect();
            let g = OccupancyGrid::from_cells(gw, gh, 0.05, Default::default(), cells).unwrap();
            let pg = PreparedMap::new(&g, &vc);
            for scale in [1.0, 2.5, 3.0, 4.7] {
                let full = (
                    (gw as f64 / scale).ceil() as usize + 1,
                    (gh as f64 / scale).ceil() as usize + 1,
                );
                for (w, h) in [full, (full.0.div_ceil(2), full.1.div_ceil(2))] {
                    let (occ, free) = definition(&g, scale, w, h);
                    // The field and mask of those counts, by the rule of `coarse_field`.
                    let (field, known) = coarse_field(&pg, scale, w, h, 0.5);
                    for i in 0..w * h {
                        let (x, y) = (i % w, i / w);
                        let wall_next =
                            [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)]
                                .iter()
                                .any(|&(dx, dy)| {
                                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                                    nx >= 0
                                        && ny >= 0
                                        && (nx as usize) < w
                                        && (ny as usize) < h
                                        && occ[ny as usize * w + nx as usize] > 0
                                });
                        let expected = if occ[i] > 0 {
                            1.0
                        } else if wall_next {
                            0.5
                        } else if free[i] > 0 {
                            -0.5
                        } else {
                            0.0
                        };
                        assert_eq!(field[i], expected, "{gw} x {gh} at scale {scale}, cell {i}");
                        assert_eq!(known[i], occ[i] > 0 || free[i] > 0 || wall_next);
                    }
                }
            }
        }
    }

    #[test]
    fn a_large_map_gets_cells_of_at_most_max_cell_px_and_at_most_twice_the_cells() {
        // A known block of `w` x `h` cells (free, walled round) on a canvas 4 cells larger.
        let block = |w: usize, h: usize| {
            let (cw, ch) = (w + 4, h + 4);
            let mut cells = vec![grid_core::UNKNOWN; cw * ch];
            for y in 2..2 + h {
                for x in 2..2 + w {
                    let wall = x == 2 || y == 2 || x == w + 1 || y == h + 1;
                    cells[y * cw + x] = if wall { 100 } else { 0 };
                }
            }
            OccupancyGrid::from_cells(cw, ch, 0.05, grid_core::Pose2::default(), cells).unwrap()
        };
        let vc = VerifyConfig::default();
        let b = block(20, 15);
        let pb = PreparedMap::new(&b, &vc);
        let scale = |a_side: usize, max_cell_px: f64| {
            let a = block(a_side, 10);
            let pa = PreparedMap::new(&a, &vc);
            CoarseField::new(
                &pa,
                &pb,
                (10, max_cell_px),
                0.5,
                true,
                1,
                &mut FftPlanner::new(),
            )
            .scale
        };
        // B's diagonal (25 px) spans the 10 cells when A is smaller ...
        assert_eq!(scale(20, 4.0), 2.5);
        // ... and A's side when it is larger: 10 cells of 3 px, within the bound of 4 ...
        assert_eq!(scale(30, 4.0), 3.0);
        // ... 15 cells of 4 px rather than 10 of 6 ...
        assert_eq!(scale(60, 4.0), 4.0);
        assert_eq!(scale(60, f64::INFINITY), 6.0);
        // ... and no more than 20 cells, of 5 px rather than 4.
        assert_eq!(scale(100, 4.0), 5.0);
    }

    #[test]
    fn the_coarse_known_mask_does_not_depend_on_the_free_space_charge() {
        let a = room();
        let pa = PreparedMap::new(&a, &VerifyConfig::default());
        let (w, h) = (a.width().div_ceil(3) + 1, a.height().div_ceil(3) + 1);
        let (charged, known) = coarse_field(&pa, 3.0, w, h, 0.5);
        let (free_of_charge, known_too) = coarse_field(&pa, 3.0, w, h, 0.0);
        assert_eq!(known, known_too);
        // With a charge every known cell has a value, as the field's old rule assumed ...
        let valued = |f: &[f32]| f.iter().map(|v| *v != 0.0).collect::<Vec<_>>();
        assert_eq!(valued(&charged), known);
        // ... without one, free space has none and is still known.
        let (n_known, n_valued) = (
            known.iter().filter(|k| **k).count(),
            valued(&free_of_charge).iter().filter(|k| **k).count(),
        );
        assert!(
            n_valued < n_known / 2,
            "{n_valued} valued of {n_known} known"
        );
        // Unknown cells are those with no pixel of A and no wall next to them.
        assert!(known.iter().any(|k| !k));
    }

    #[test]
    fn the_spectrum_gives_the_angle_near_a_placement() {
        // The L-shaped room and a copy turned by 23.4 degrees: from a placement 1.5 degrees
        // off, the spectra give the true angle to a fraction of their quarter-degree bins.
        let a = crate::testmaps::room();
        let vc = VerifyConfig::default();
        let a_to_b = Rigid2::new(23.4f64.to_radians(), 60.0, 30.0);
        let b = a.warp(&a_to_b, 200, 190).unwrap();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let truth = a_to_b.inverse();
        let near = |theta: f64, max_deg: f64| {
            spectrum_rotation_near(&pa, &pb, theta, 720, 6000, max_deg.to_radians())
        };
        let got = near(truth.theta + 1.5f64.to_radians(), 2.0).unwrap();
        let err = grid_core::wrap_angle(got - truth.theta).to_degrees();
        assert!(err.abs() < 0.1, "{err} degrees off");
        // From the other side too, and modulo the spectrum's half-turn period.
        let got = near(truth.theta - 1.2f64.to_radians() + PI, 2.0).unwrap();
        let err = grid_core::wrap_angle(got - truth.theta - PI).to_degrees();
        assert!(err.abs() < 0.1, "{err} degrees off");
        // A peak farther than allowed is not taken: the room's other peaks are a quarter turn
        // away, so 4 degrees off with a 2-degree window finds none.
        assert_eq!(near(truth.theta + 4f64.to_radians(), 2.0), None);
    }

    #[test]
    fn the_twins_of_a_bare_room_include_its_half_turn() {
        let a = crate::testmaps::bare_room();
        let vc = VerifyConfig::default();
        let pa = PreparedMap::new(&a, &vc);
        let a_to_b = Rigid2::new(37f64.to_radians(), 60.0, 20.0);
        let b = a.warp(&a_to_b, 200, 190).unwrap();
        let (truth, pb) = (a_to_b.inverse(), PreparedMap::new(&b, &vc));
        // The room's half turn about its centre (59.5, 49.5) maps it onto itself.
        let c = DVec2::new(59.5, 49.5);
        let half = Rigid2::new(PI, 2.0 * c.x, 2.0 * c.y);
        let twin = half.compose(&truth);
        let mut out = Vec::new();
        twins(&pa, &pb, &truth, &GlobalConfig::default(), &mut out);
        assert_eq!(out.len(), 4 * GlobalConfig::default().translation_peaks);
        let nearest = |target: &Rigid2| {
            out.iter()
                .map(|t| grid_core::metrics::displacement_error(&b, t, target).unwrap())
                .fold(f64::INFINITY, f64::min)
        };
        // Within a coarse cell (about 1.5 px for these maps) and the rounding of the walls.
        assert!(
            nearest(&twin) < 4.0,
            "half-turn twin {} px off",
            nearest(&twin)
        );
        assert!(
            nearest(&truth) < 4.0,
            "unturned twin {} px off",
            nearest(&truth)
        );
    }

    #[test]
    fn spectrum_correlation_finds_the_rotation() {
        // An L of two walls plus a slanted one, and the same turned by 30 degrees.
        let mut pts = Vec::new();
        for i in 0..200 {
            pts.push(DVec2::new(i as f64, 0.0));
            pts.push(DVec2::new(0.0, i as f64 * 0.7));
            pts.push(DVec2::new(50.0 + i as f64 * 0.5, 80.0 + i as f64 * 0.3));
        }
        let theta = 30f64.to_radians();
        let rot: Vec<DVec2> = pts
            .iter()
            .map(|p| DVec2::from_angle(theta).rotate(*p))
            .collect();
        let sa = hough_spectrum(&rot, 360);
        let sb = hough_spectrum(&pts, 360);
        let best = rotation_candidates(&sa, &sb, 1)[0];
        assert!(
            (best - theta).abs() < 0.6f64.to_radians(),
            "{}",
            best.to_degrees()
        );
    }

    /// Points every half pixel along the outlines of `rects` (centre, half sizes), all turned
    /// by `angle` about the origin.
    fn outlines(rects: &[(DVec2, DVec2)], angle: f64) -> Vec<DVec2> {
        let turn = DVec2::from_angle(angle);
        let mut points = Vec::new();
        for &(c, h) in rects {
            let corners = [
                (-1.0, -1.0),
                (1.0, -1.0),
                (1.0, 1.0),
                (-1.0, 1.0),
                (-1.0, -1.0),
            ]
            .map(|(x, y)| c + h * DVec2::new(x, y));
            for w in corners.windows(2) {
                let n = ((w[1] - w[0]).length() * 2.0) as usize;
                points.extend((0..n).map(|k| turn.rotate(w[0].lerp(w[1], k as f64 / n as f64))));
            }
        }
        points
    }

    #[test]
    fn the_dominant_direction_of_walls_at_right_angles_is_found_to_a_hundredth_of_a_degree() {
        let rects = [
            (DVec2::new(0.0, 0.0), DVec2::new(300.0, 200.0)),
            (DVec2::new(-120.0, 40.0), DVec2::new(60.0, 15.0)),
            (DVec2::new(150.0, -90.0), DVec2::new(20.0, 80.0)),
        ];
        for deg in [0.0f64, 7.3, 23.4, 44.6, 61.05, 89.9, 133.3] {
            let d = manhattan_direction(&outlines(&rects, deg.to_radians())).unwrap();
            let expected = deg.to_radians().rem_euclid(PI / 2.0);
            let err = (d.angle - expected + PI / 4.0).rem_euclid(PI / 2.0) - PI / 4.0;
            assert!(
                err.to_degrees().abs() < 0.01,
                "{deg}: {}",
                d.angle.to_degrees()
            );
            assert!(d.contrast > 3.0, "{deg}: contrast {}", d.contrast);
        }
    }

    #[test]
    fn walls_without_a_dominant_direction_have_no_contrast() {
        // Rings of radius 20 to 200 px: every direction alike.
        let points: Vec<DVec2> = (1..=10)
            .flat_map(|r| {
                let r = 20.0 * r as f64;
                let n = (r * 4.0 * PI) as usize;
                (0..n).map(move |k| DVec2::from_angle(2.0 * PI * k as f64 / n as f64) * r)
            })
            .collect();
        let d = manhattan_direction(&points).unwrap();
        assert!(d.contrast < 1.2, "contrast {}", d.contrast);
        assert_eq!(manhattan_direction(&points[..9]), None);
    }
}
