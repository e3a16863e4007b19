//! The Gaussian scale space and its differences of Gaussians (IPOL "Anatomy of SIFT", §2).

use rayon::prelude::*;

use crate::blur::{GaussianKernel, gaussian_blur, gaussian_blur_sampled};
use crate::{Error, Image, ScaleSpaceConfig};

/// One octave: `n_spo + 3` Gaussian images and `n_spo + 2` differences, all sampled every
/// `delta` input pixels.
#[derive(Debug, Clone, Default)]
pub struct Octave {
    /// Sampling distance in input pixels: octave pixel `m` sits at input coordinate `delta * m`.
    pub delta: f32,
    /// Gaussian images `v_s`, `s = 0..n_spo + 3`; `v_s` has blur [`ScaleSpace::sigma`]`(o, s)`.
    pub gaussians: Vec<Image>,
    /// Differences `w_s = v_{s+1} - v_s`, `s = 0..n_spo + 2`.
    pub dogs: Vec<Image>,
}

/// A Gaussian scale space with its DoG, reusable across images to keep the allocations.
///
/// Sampling follows IPOL: the seed image samples the input at `delta_min * m` (bilinear), and
/// each octave keeps every other sample of the previous one, so octave pixel `m` of octave `o`
/// sits exactly at input coordinate `delta_o * m` with `delta_o = delta_min * 2^o`. Octave sizes
/// are `(n - 1) / 2 + 1`, so the samples span `[0, w - 1]` symmetrically when `w - 1` is a
/// multiple of `2^o / delta_min`, which makes the detector exactly equivariant to quarter turns
/// for such sizes (and up to a half-sample shift at the far border otherwise).
#[derive(Debug, Clone, Default)]
pub struct ScaleSpace {
    /// Octaves, finest first.
    pub octaves: Vec<Octave>,
    /// Parameters the scale space was built with.
    pub config: ScaleSpaceConfig,
    /// Intermediate buffer of the separable blur.
    tmp: Image,
}

impl ScaleSpace {
    /// An empty scale space; fill it with [`Self::build`].
    pub fn new() -> Self {
        Self::default()
    }

    /// Blur (in input pixels) of Gaussian image `s` of octave `o`:
    /// `(delta_o / delta_min) * sigma_min * 2^(s / n_spo)`.
    pub fn sigma(&self, o: usize, s: f32) -> f32 {
        let c = &self.config;
        2f32.powi(o as i32) * c.sigma_min * 2f32.powf(s / c.n_spo as f32)
    }

    /// Build the scale space of `image` (values in `[0, 1]`).
    pub fn build(&mut self, image: &Image, config: &ScaleSpaceConfig) -> Result<(), Error> {
        config.validate()?;
        if image.width < 2 || image.height < 2 || image.data.len() != image.width * image.height {
            return Err(Error::ImageSize {
                width: image.width,
                height: image.height,
            });
        }
        self.config = config.clone();
        let n_spo = config.n_spo;
        let n_oct = octave_count(image.width, image.height, config);
        self.octaves.resize_with(n_oct, Octave::default);
        self.octaves.truncate(n_oct);
        let k = 2f32.powf(1.0 / n_spo as f32);
        for o in 0..n_oct {
            let delta = config.delta_min * 2f32.powi(o as i32);
            let mut octave = std::mem::take(&mut self.octaves[o]);
            octave.delta = delta;
            octave.gaussians.resize_with(n_spo + 3, Image::default);
            octave.dogs.resize_with(n_spo + 2, Image::default);
            if o == 0 {
                let mut seed = std::mem::take(&mut octave.dogs[0]);
                let extra = (config.sigma_min.powi(2) - config.sigma_in.powi(2)).max(0.0);
                if config.delta_min <= 1.0 {
                    // Seed: resample to delta_min, then blur from sigma_in up to sigma_min.
                    resample(image, config.delta_min, &mut seed);
                    let kernel = GaussianKernel::new(extra.sqrt() / config.delta_min);
                    gaussian_blur(&seed, &kernel, &mut self.tmp, &mut octave.gaussians[0]);
                } else if config.delta_min.fract() == 0.0 {
                    // Coarser than the input by a whole step (the default 2): blur to
                    // sigma_min, so the seed does not alias, computing only the samples kept
                    // (the same values as blurring everything and sampling: bilinear
                    // sampling at whole pixels reads them unchanged).
                    gaussian_blur_sampled(
                        image,
                        &GaussianKernel::new(extra.sqrt()),
                        config.delta_min as usize,
                        &mut self.tmp,
                        &mut octave.gaussians[0],
                    );
                } else {
                    // Coarser than the input: blur to sigma_min first, then sample, so the
                    // seed does not alias.
                    gaussian_blur(
                        image,
                        &GaussianKernel::new(extra.sqrt()),
                        &mut self.tmp,
                        &mut seed,
                    );
                    resample(&seed, config.delta_min, &mut octave.gaussians[0]);
                }
                octave.dogs[0] = seed;
            } else {
                // The first image of an octave is image n_spo of the previous one, decimated.
                let prev = &self.octaves[o - 1].gaussians[n_spo];
                decimate(prev, &mut octave.gaussians[0]);
            }
            for s in 1..n_spo + 3 {
                // Blur (in this octave's pixels) taking sigma_{s-1} to sigma_s.
                let prev = config.sigma_min / config.delta_min * k.powi(s as i32 - 1);
                let rho = prev * (k * k - 1.0).sqrt();
                let (done, rest) = octave.gaussians.split_at_mut(s);
                gaussian_blur(
                    &done[s - 1],
                    &GaussianKernel::new(rho),
                    &mut self.tmp,
                    &mut rest[0],
                );
            }
            let Octave {
                gaussians, dogs, ..
            } = &mut octave;
            dogs.par_iter_mut().enumerate().for_each(|(s, d)| {
                let (a, b) = (&gaussians[s], &gaussians[s + 1]);
                d.reshape(a.width, a.height);
                for ((d, x), y) in d.data.iter_mut().zip(&b.data).zip(&a.data) {
                    *d = x - y;
                }
            });
            self.octaves[o] = octave;
        }
        Ok(())
    }
}

/// How many octaves fit: the smallest keeps at least `min_octave_size` pixels on its short side.
fn octave_count(w: usize, h: usize, config: &ScaleSpaceConfig) -> usize {
    let mut side = ((w.min(h) - 1) as f32 / config.delta_min).floor() as usize + 1;
    let mut n = 0;
    while side >= config.min_octave_size && n < config.max_octaves {
        n += 1;
        side = (side - 1) / 2 + 1;
    }
    n.max(1)
}

/// Sample `src` at `delta * m` (bilinear, clamped), `m = 0..=floor((w - 1) / delta)`.
fn resample(src: &Image, delta: f32, dst: &mut Image) {
    if delta == 1.0 {
        dst.clone_from(src);
        return;
    }
    let w = ((src.width - 1) as f32 / delta).floor() as usize + 1;
    let h = ((src.height - 1) as f32 / delta).floor() as usize + 1;
    dst.reshape(w, h);
    let taps = |m: usize, n: usize| {
        let x = (m as f32 * delta).min((n - 1) as f32);
        let i = (x.floor() as usize).min(n - 1);
        let j = (i + 1).min(n - 1);
        (i, j, x - i as f32)
    };
    let cols: Vec<_> = (0..w).map(|m| taps(m, src.width)).collect();
    dst.data.par_chunks_mut(w).enumerate().for_each(|(n, out)| {
        let (i, j, fy) = taps(n, src.height);
        let (r0, r1) = (src.row(i), src.row(j));
        for (o, &(a, b, fx)) in out.iter_mut().zip(&cols) {
            let top = r0[a] + fx * (r0[b] - r0[a]);
            let bottom = r1[a] + fx * (r1[b] - r1[a]);
            *o = top + fy * (bottom - top);
        }
    });
}

/// Keep every other sample: `dst(m, n) = src(2m, 2n)`.
fn decimate(src: &Image, dst: &mut Image) {
    let (w, h) = ((src.width - 1) / 2 + 1, (src.height - 1) / 2 + 1);
    dst.reshape(w, h);
    for (n, out) in dst.data.chunks_exact_mut(w).enumerate() {
        let row = src.row(2 * n);
        for (m, o) in out.iter_mut().enumerate() {
            *o = row[2 * m];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_sizes_and_sampling() {
        let img = Image {
            width: 9,
            height: 5,
            data: (0..45).map(|i| i as f32).collect(),
        };
        let mut up = Image::default();
        resample(&img, 0.5, &mut up);
        assert_eq!((up.width, up.height), (17, 9));
        // Up-sampled pixel (3, 1) sits at input (1.5, 0.5).
        assert_eq!(up.at(3, 1), 0.5 * (1.0 + 2.0) + 0.5 * 9.0);
        let mut down = Image::default();
        decimate(&up, &mut down);
        assert_eq!(down, img);
        let config = ScaleSpaceConfig {
            min_octave_size: 3,
            delta_min: 0.5,
            ..ScaleSpaceConfig::default()
        };
        // Short side 5 -> 9 (delta 0.5), 5, 3, then 2 < 3.
        assert_eq!(octave_count(9, 5, &config), 3);
    }

    /// The seed of `delta_min` 2 blurs only the samples kept ([`gaussian_blur_sampled`]),
    /// which is the blur then [`resample`] only if resampling at whole pixels reads them
    /// unchanged.
    #[test]
    fn resampling_by_two_reads_whole_pixels_unchanged() {
        for (w, h) in [(9, 5), (10, 6), (1, 4)] {
            let img = Image {
                width: w,
                height: h,
                data: (0..w * h).map(|i| (i as f32 * 0.37).sin()).collect(),
            };
            let (mut sampled, mut kept) = (Image::default(), Image::default());
            resample(&img, 2.0, &mut sampled);
            decimate(&img, &mut kept);
            assert_eq!(sampled, kept, "{w} x {h}");
        }
    }
}
