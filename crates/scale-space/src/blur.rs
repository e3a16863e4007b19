//! Separable f32 Gaussian blur with mirrored borders, parallel over rows.

use rayon::prelude::*;

use crate::Image;

/// Rows handed to one rayon task: large enough that task overhead is negligible.
const ROWS_PER_TASK: usize = 16;

/// A normalised, symmetric 1-D Gaussian kernel: `taps[0]` is the centre weight, `taps[k]` the
/// weight at offsets `±k`.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianKernel {
    /// Standard deviation in pixels.
    pub sigma: f32,
    /// Half kernel, centre first; `taps[0] + 2 * sum(taps[1..]) == 1`.
    pub taps: Vec<f32>,
}

impl GaussianKernel {
    /// A kernel truncated at `ceil(4 sigma)` (at least radius 1), as in the IPOL reference.
    pub fn new(sigma: f32) -> Self {
        let sigma = sigma.max(1e-3);
        Self::with_radius(sigma, ((4.0 * sigma).ceil() as usize).max(1))
    }

    /// A kernel of standard deviation `sigma` truncated at `radius` pixels (then renormalised).
    pub fn with_radius(sigma: f32, radius: usize) -> Self {
        let sigma = sigma.max(1e-3);
        let mut taps: Vec<f32> = (0..=radius)
            .map(|k| (-((k * k) as f32) / (2.0 * sigma * sigma)).exp())
            .collect();
        let sum = taps[0] + 2.0 * taps[1..].iter().sum::<f32>();
        taps.iter_mut().for_each(|t| *t /= sum);
        Self { sigma, taps }
    }

    /// Radius in pixels (`taps.len() - 1`).
    pub fn radius(&self) -> usize {
        self.taps.len() - 1
    }
}

/// Mirror an index into `0..n` (half-sample symmetric: `-1 -> 0`, `n -> n - 1`).
#[inline]
fn mirror(i: isize, n: usize) -> usize {
    let n = n as isize;
    let period = 2 * n;
    let mut i = i.rem_euclid(period);
    if i >= n {
        i = period - 1 - i;
    }
    i as usize
}

/// Blur `src` with `kernel` in both directions into `dst` (reshaped to `src`'s size), using
/// `tmp` as the intermediate image. Every output pixel is computed by the same sequence of
/// operations whatever the thread count, so the result is deterministic.
pub fn gaussian_blur(src: &Image, kernel: &GaussianKernel, tmp: &mut Image, dst: &mut Image) {
    gaussian_blur_sampled(src, kernel, 1, tmp, dst);
}

/// [`gaussian_blur`] of `src` kept only every `step` pixels along both axes: `dst(m, n)` is
/// the blurred image at `(step * m, step * n)`, for `m = 0..=(width - 1) / step` and `n =
/// 0..=(height - 1) / step`. Each kept pixel gets exactly the value [`gaussian_blur`] gives it
/// (one code path: [`gaussian_blur`] is this with `step` 1), at about `1 / step` of the
/// horizontal pass's work and `1 / step^2` of the vertical pass's: the seed of a scale space
/// whose first octave is coarser than the input (`delta_min` of 2) needs only those pixels.
///
/// # Panics
/// When `step` is 0.
pub fn gaussian_blur_sampled(
    src: &Image,
    kernel: &GaussianKernel,
    step: usize,
    tmp: &mut Image,
    dst: &mut Image,
) {
    assert!(step > 0, "sampling step 0");
    let (w, h) = (src.width, src.height);
    // Samples kept of `n`: `0, step, ...` up to `n - 1`.
    let kept = |n: usize| if n == 0 { 0 } else { (n - 1) / step + 1 };
    let (ws, hs) = (kept(w), kept(h));
    if w == 0 || h == 0 {
        tmp.reshape(ws, h);
        dst.reshape(ws, hs);
        return;
    }
    // Horizontal: every row, the kept columns only.
    tmp.reshape(ws, h);
    let r = kernel.radius();
    let taps = &kernel.taps;
    tmp.data
        .par_chunks_mut(ws * ROWS_PER_TASK)
        .enumerate()
        .for_each_init(
            || (vec![0.0f32; w + 2 * r], Vec::new()),
            |(padded, phases): &mut (Vec<f32>, Vec<Vec<f32>>), (chunk, out_rows)| {
                for (i, out) in out_rows.chunks_exact_mut(ws).enumerate() {
                    pad_row(src.row(chunk * ROWS_PER_TASK + i), r, padded);
                    // Sampled, the padded row split by index modulo `step`: padded sample
                    // `step * j + p` is `phases[p][j]`, so that kept column `m`'s taps at
                    // `step * m + c` read one phase along `m`, which vectorises as the whole
                    // row does.
                    if step > 1 {
                        phases.resize_with(step, Vec::new);
                        for (p, phase) in phases.iter_mut().enumerate() {
                            phase.clear();
                            phase.extend(padded.iter().skip(p).step_by(step));
                        }
                    }
                    let at = |c: usize| -> &[f32] {
                        if step == 1 {
                            &padded[c..][..ws]
                        } else {
                            &phases[c % step][c / step..][..ws]
                        }
                    };
                    // Centre tap, then symmetric pairs.
                    for (o, v) in out.iter_mut().zip(at(r)) {
                        *o = taps[0] * v;
                    }
                    for (k, &t) in taps.iter().enumerate().skip(1) {
                        for ((o, a), b) in out.iter_mut().zip(at(r - k)).zip(at(r + k)) {
                            *o += t * (a + b);
                        }
                    }
                }
            },
        );
    // Vertical: the kept rows only.
    dst.reshape(ws, hs);
    let tmp = &*tmp;
    dst.data
        .par_chunks_mut(ws)
        .enumerate()
        .with_min_len(ROWS_PER_TASK)
        .for_each(|(n, out)| vertical_row(tmp, taps, n * step, out));
}

/// Row `y` of the vertical pass of `src` with the half kernel `taps`, into `out`: row `y`
/// accumulates whole input rows `y ± k`, which vectorises over `x` and reads memory in order
/// (no transpose needed).
fn vertical_row(src: &Image, taps: &[f32], y: usize, out: &mut [f32]) {
    let (h, y) = (src.height, y as isize);
    for (o, s) in out.iter_mut().zip(src.row(y as usize)) {
        *o = taps[0] * s;
    }
    for (k, &t) in taps.iter().enumerate().skip(1) {
        let up = src.row(mirror(y - k as isize, h));
        let down = src.row(mirror(y + k as isize, h));
        for ((o, a), b) in out.iter_mut().zip(up).zip(down) {
            *o += t * (a + b);
        }
    }
}

/// `row` copied into `padded` (resized to `row.len() + 2 r`) between `r` mirrored samples on
/// each side.
fn pad_row(row: &[f32], r: usize, padded: &mut Vec<f32>) {
    let w = row.len();
    padded.resize(w + 2 * r, 0.0);
    // Copy the row, then mirror only the 2r border samples.
    padded[r..r + w].copy_from_slice(row);
    for k in 1..=r {
        padded[r - k] = row[mirror(-(k as isize), w)];
        padded[r + w - 1 + k] = row[mirror((w - 1 + k) as isize, w)];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_indices() {
        let got: Vec<usize> = (-3..7).map(|i| mirror(i, 4)).collect();
        assert_eq!(got, vec![2, 1, 0, 0, 1, 2, 3, 3, 2, 1]);
        assert_eq!(mirror(-1, 1), 0);
        assert_eq!(mirror(5, 1), 0);
    }

    #[test]
    fn kernel_is_normalised_with_the_right_variance() {
        let k = GaussianKernel::new(2.0);
        let sum = k.taps[0] + 2.0 * k.taps[1..].iter().sum::<f32>();
        assert!((sum - 1.0).abs() < 1e-6);
        let var: f32 = k
            .taps
            .iter()
            .enumerate()
            .map(|(i, t)| 2.0 * t * (i * i) as f32)
            .sum();
        assert!((var - 4.0).abs() < 0.01, "variance {var}");
    }

    #[test]
    fn the_sampled_blur_is_the_blur_at_the_kept_pixels_exactly() {
        // Odd and even sizes, sides shorter than the kernel, steps 1 to 3.
        for (w, h) in [(37, 23), (64, 41), (5, 3), (1, 9), (20, 1)] {
            let src = Image {
                width: w,
                height: h,
                data: (0..w * h)
                    .map(|i| ((i * 7919) % 101) as f32 / 100.0)
                    .collect(),
            };
            for sigma in [0.6, 1.52, 3.0] {
                let kernel = GaussianKernel::new(sigma);
                let (mut tmp, mut full, mut kept) =
                    (Image::default(), Image::default(), Image::default());
                gaussian_blur(&src, &kernel, &mut tmp, &mut full);
                for step in 1..=3 {
                    gaussian_blur_sampled(&src, &kernel, step, &mut tmp, &mut kept);
                    let (ws, hs) = ((w - 1) / step + 1, (h - 1) / step + 1);
                    assert_eq!((kept.width, kept.height), (ws, hs));
                    for n in 0..hs {
                        for m in 0..ws {
                            assert_eq!(
                                kept.at(m, n).to_bits(),
                                full.at(step * m, step * n).to_bits(),
                                "{w} x {h}, sigma {sigma}, step {step}, at ({m}, {n})"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn blur_keeps_constants_and_mass_of_an_impulse() {
        let src = Image::filled(37, 23, 0.25);
        let (mut tmp, mut dst) = (Image::default(), Image::default());
        gaussian_blur(&src, &GaussianKernel::new(1.6), &mut tmp, &mut dst);
        assert!(dst.data.iter().all(|v| (v - 0.25).abs() < 1e-6));

        let mut imp = Image::filled(41, 41, 0.0);
        imp.data[20 * 41 + 20] = 1.0;
        gaussian_blur(&imp, &GaussianKernel::new(2.0), &mut tmp, &mut dst);
        let mass: f32 = dst.data.iter().sum();
        assert!((mass - 1.0).abs() < 1e-5);
        // Separable: the response is the outer product of the 1-D kernel with itself.
        let k = GaussianKernel::new(2.0);
        assert!((dst.at(23, 18) - k.taps[3] * k.taps[2]).abs() < 1e-7);
    }
}
