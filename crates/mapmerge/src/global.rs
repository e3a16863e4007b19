//! Global search: transform hypotheses without any feature match.
//!
//! When the keypoints of two maps disagree (strong sensor noise, walls seen only in part), their
//! RANSAC hypotheses fail verification, yet the walls may still line up. Following Carpin's
//! Hough-spectrum merger: the rotation is where the Hough spectra of the two maps' walls
//! correlate best (the spectrum is invariant to translation), and for each candidate rotation
//! the translation is where B's rotated walls best hit A's wall likelihood field (an FFT
//! cross-correlation at a coarse scale). The hypotheses go through the same refinement and
//! verification as the feature-based ones, so a wrong one costs time, not trust.

use std::f64::consts::PI;

use grid_core::{CellState, DVec2, Rigid2};
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
    /// Longest side of the coarse correlation images, in coarse cells. Default 192.
    pub coarse_size: usize,
    /// Translation peaks kept per angle. Default 2.
    pub translation_peaks: usize,
}

impl Default for GlobalConfig {
    fn default() -> Self {
        Self {
            angle_bins: 360,
            rotation_peaks: 3,
            max_points: 6000,
            coarse_size: 192,
            translation_peaks: 2,
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

/// Coarse likelihood field of A: high near walls, negative on free space, zero where unknown.
fn coarse_field(a: &PreparedMap, scale: f64, w: usize, h: usize) -> Vec<f32> {
    let mut occ = vec![0u32; w * h];
    let mut free = vec![0u32; w * h];
    let g = a.grid;
    for y in 0..g.height() {
        for x in 0..g.width() {
            let (cx, cy) = ((x as f64 / scale) as usize, (y as f64 / scale) as usize);
            if cx >= w || cy >= h {
                continue;
            }
            match g.state(x, y) {
                CellState::Occupied => occ[cy * w + cx] += 1,
                CellState::Free => free[cy * w + cx] += 1,
                CellState::Unknown => {}
            }
        }
    }
    let mut field = vec![0f32; w * h];
    for i in 0..w * h {
        field[i] = if occ[i] > 0 {
            1.0
        } else if free[i] > 0 {
            -0.5
        } else {
            0.0
        };
    }
    // Spread walls by one coarse cell so a wall off by a fraction of a cell still scores.
    let mut spread = field.clone();
    for y in 0..h {
        for x in 0..w {
            if field[y * w + x] == 1.0 {
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                        let s = &mut spread[ny as usize * w + nx as usize];
                        *s = s.max(0.5);
                    }
                }
            }
        }
    }
    spread
}

fn fft2(data: &mut [Complex32], w: usize, h: usize, planner: &mut FftPlanner<f32>, inverse: bool) {
    let row = if inverse {
        planner.plan_fft_inverse(w)
    } else {
        planner.plan_fft_forward(w)
    };
    for r in data.chunks_mut(w) {
        row.process(r);
    }
    let col = if inverse {
        planner.plan_fft_inverse(h)
    } else {
        planner.plan_fft_forward(h)
    };
    let mut buf = vec![Complex32::default(); h];
    for x in 0..w {
        for y in 0..h {
            buf[y] = data[y * w + x];
        }
        col.process(&mut buf);
        for y in 0..h {
            data[y * w + x] = buf[y];
        }
    }
}

/// A's coarse likelihood field, transformed, with the geometry of the correlation images.
struct CoarseField {
    /// Coarse cell size in pixels.
    scale: f64,
    /// Side lengths of the (zero-padded) correlation images.
    nw: usize,
    nh: usize,
    /// Fourier transform of A's coarse field.
    spectrum: Vec<Complex32>,
}

impl CoarseField {
    /// A's field at a scale where the larger of A's sides and B's diagonal spans `coarse_size`
    /// cells, padded so that every shift of B stays unambiguous.
    fn new(
        a: &PreparedMap,
        b: &PreparedMap,
        coarse_size: usize,
        planner: &mut FftPlanner<f32>,
    ) -> Self {
        let (wa, ha) = (a.grid.width() as f64, a.grid.height() as f64);
        let diag_b = ((b.grid.width() as f64).powi(2) + (b.grid.height() as f64).powi(2)).sqrt();
        let scale = (wa.max(ha).max(diag_b) / coarse_size as f64).max(1.0);
        let (cw, ch) = (
            (wa / scale).ceil() as usize + 1,
            (ha / scale).ceil() as usize + 1,
        );
        let bside = (diag_b / scale).ceil() as usize + 2;
        let (nw, nh) = (
            (cw + bside).next_power_of_two(),
            (ch + bside).next_power_of_two(),
        );
        let field = coarse_field(a, scale, cw, ch);
        let mut spectrum = vec![Complex32::default(); nw * nh];
        for y in 0..ch {
            for x in 0..cw {
                spectrum[y * nw + x].re = field[y * cw + x];
            }
        }
        fft2(&mut spectrum, nw, nh, planner, false);
        Self {
            scale,
            nw,
            nh,
            spectrum,
        }
    }

    /// The best `peaks` translations for B's wall points `pb` turned by `theta`: local maxima
    /// of `C(t) = sum_u F_A(u + t) P_B(u)`, as B→A transforms, best first.
    /// `buf` is scratch space of `nw * nh`.
    fn correlate(
        &self,
        pb: &[DVec2],
        theta: f64,
        peaks: usize,
        planner: &mut FftPlanner<f32>,
        buf: &mut Vec<Complex32>,
    ) -> Vec<Rigid2> {
        let (nw, nh, scale) = (self.nw, self.nh, self.scale);
        let rot = DVec2::from_angle(theta);
        let q: Vec<DVec2> = pb.iter().map(|p| rot.rotate(*p)).collect();
        let qmin = q
            .iter()
            .copied()
            .fold(DVec2::splat(f64::INFINITY), DVec2::min);
        buf.clear();
        buf.resize(nw * nh, Complex32::default());
        for p in &q {
            let u = (*p - qmin) / scale;
            let (ux, uy) = (u.x.round() as usize, u.y.round() as usize);
            if ux < nw && uy < nh {
                buf[uy * nw + ux].re = 1.0;
            }
        }
        fft2(buf, nw, nh, planner, false);
        for (x, y) in buf.iter_mut().zip(&self.spectrum) {
            *x = y * x.conj();
        }
        fft2(buf, nw, nh, planner, true);
        // Negative shifts are wrapped around.
        let mut found: Vec<(f32, usize, usize)> = Vec::new();
        for ty in 0..nh {
            for tx in 0..nw {
                let v = buf[ty * nw + tx].re;
                if v <= 0.0 {
                    continue;
                }
                let is_max = (-1i64..=1).all(|dy| {
                    (-1i64..=1).all(|dx| {
                        let (nx, ny) = (
                            (tx as i64 + dx).rem_euclid(nw as i64),
                            (ty as i64 + dy).rem_euclid(nh as i64),
                        );
                        (dx == 0 && dy == 0) || buf[ny as usize * nw + nx as usize].re <= v
                    })
                });
                if is_max {
                    found.push((v, tx, ty));
                }
            }
        }
        found.sort_by(|x, y| y.0.total_cmp(&x.0));
        found
            .iter()
            .take(peaks)
            .map(|&(_, tx, ty)| {
                let wrap = |t: usize, n: usize| {
                    if t > n / 2 {
                        t as f64 - n as f64
                    } else {
                        t as f64
                    }
                };
                let t = scale * DVec2::new(wrap(tx, nw), wrap(ty, nh)) - qmin;
                Rigid2::new(theta, t.x, t.y).normalized()
            })
            .collect()
    }
}

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
    let mut planner = FftPlanner::<f32>::new();
    let field = CoarseField::new(a, b, config.coarse_size, &mut planner);
    let mut buf = Vec::new();
    for theta in angles {
        out.extend(field.correlate(&pb, theta, config.translation_peaks, &mut planner, &mut buf));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
