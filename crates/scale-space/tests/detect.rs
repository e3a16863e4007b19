//! Detector tests against known truth: a Gaussian blob, an oracle blur, quarter-turn symmetry.

use scale_space::{GaussianKernel, Image, Keypoint, ScaleSpace, ScaleSpaceConfig, gaussian_blur};

fn blob(size: usize, cx: f32, cy: f32, s0: f32) -> Image {
    let mut img = Image::filled(size, size, 0.0);
    for y in 0..size {
        for x in 0..size {
            let r2 = (x as f32 - cx).powi(2) + (y as f32 - cy).powi(2);
            img.data[y * size + x] = (-r2 / (2.0 * s0 * s0)).exp();
        }
    }
    img
}

fn detect(img: &Image, config: &ScaleSpaceConfig) -> Vec<Keypoint> {
    let mut space = ScaleSpace::new();
    space.build(img, config).unwrap();
    let mut out = Vec::new();
    space.detect((0.0, 0.0), &mut out);
    out
}

/// The DoG `D(sigma) = G(k sigma) - G(sigma)` applied to a Gaussian blob of std `s0`, in an
/// image assumed to carry blur `sigma_in`, has at the blob centre the value
/// `c [1 / (a + k^2 sigma^2) - 1 / (a + sigma^2)]` with `a = s0^2 - sigma_in^2` (variances add
/// and a unit-mass 2-D Gaussian of variance `t` peaks at `1 / (2 pi t)`). Setting the derivative
/// in `u = sigma^2` to zero gives `a^2 = k^2 u^2`, so the extremum is at
/// `sigma* = sqrt((s0^2 - sigma_in^2) / k)`, `k = 2^(1 / n_spo)`: about `0.89 s0` for n_spo 3.
fn expected_sigma(s0: f32, config: &ScaleSpaceConfig) -> f32 {
    let k = 2f32.powf(1.0 / config.n_spo as f32);
    ((s0 * s0 - config.sigma_in * config.sigma_in) / k).sqrt()
}

#[test]
fn gaussian_blob_is_found_at_its_centre_and_scale() {
    // The default half-resolution first octave, the IPOL one, and the up-sampled one.
    for (delta_min, sigma_min) in [(2.0, 1.6), (1.0, 0.8), (0.5, 0.8)] {
        for s0 in [3.0f32, 6.0] {
            let config = ScaleSpaceConfig {
                delta_min,
                sigma_min,
                crop_margin: None,
                ..ScaleSpaceConfig::default()
            };
            let (cx, cy) = (60.3, 63.7);
            let kps = detect(&blob(128, cx, cy, s0), &config);
            assert_eq!(kps.len(), 1, "delta_min {delta_min} s0 {s0}: {kps:?}");
            let kp = kps[0];
            let err = ((kp.x - cx as f64).powi(2) + (kp.y - cy as f64).powi(2)).sqrt();
            assert!(
                err < 0.05,
                "delta_min {delta_min} s0 {s0}: centre off by {err}"
            );
            let want = expected_sigma(s0, &config) as f64;
            let rel = (kp.sigma - want).abs() / want;
            assert!(
                rel < 0.05,
                "delta_min {delta_min} s0 {s0}: sigma {} want {want}",
                kp.sigma
            );
            assert!(kp.response < 0.0, "a bright blob is a DoG minimum");
        }
    }
}

#[test]
fn blur_matches_the_image_crate_oracle() {
    let (w, h) = (61, 47);
    let mut img = Image::filled(w, h, 0.0);
    let mut s = 12345u64;
    for v in &mut img.data {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *v = (s >> 40) as f32 / (1u64 << 24) as f32;
    }
    let oracle_src =
        image::ImageBuffer::<image::Luma<f32>, _>::from_raw(w as u32, h as u32, img.data.clone())
            .unwrap();
    // The oracle truncates its kernel at the radius it derives from sigma (1, 4 and 8 here),
    // so ours is truncated the same way for the comparison.
    for (sigma, r) in [(0.8f32, 1), (1.6, 4), (3.0, 8)] {
        let oracle = image::imageops::blur(&oracle_src, sigma);
        let (mut tmp, mut dst) = (Image::default(), Image::default());
        gaussian_blur(
            &img,
            &GaussianKernel::with_radius(sigma, r),
            &mut tmp,
            &mut dst,
        );
        // Borders differ by design (mirror here, clamp there): compare the interior only.
        let mut worst = 0f32;
        for y in r..h - r {
            for x in r..w - r {
                worst = worst.max((dst.at(x, y) - oracle.get_pixel(x as u32, y as u32).0[0]).abs());
            }
        }
        assert!(worst < 1e-5, "sigma {sigma}: max difference {worst}");
    }
}

/// Piecewise-constant rooms-and-obstacles picture, deterministic.
fn rooms(size: usize) -> Image {
    let mut img = Image::filled(size, size, 0.0);
    let mut s = 99u64;
    let mut next = |m: usize| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 33) as usize % m
    };
    for i in 0..40 {
        let (x0, y0) = (next(size - 20), next(size - 20));
        let (w, h) = (4 + next(40), 4 + next(40));
        let v = if i % 3 == 0 { 0.0 } else { 1.0 };
        for y in y0..(y0 + h).min(size) {
            for x in x0..(x0 + w).min(size) {
                img.data[y * size + x] = v;
            }
        }
    }
    img
}

/// `new(x', y') = old(y', n - 1 - x')`: a quarter turn taking old `(x, y)` to `(n - 1 - y, x)`.
fn rotate_quarter(img: &Image) -> Image {
    let n = img.width;
    let mut out = Image::filled(n, n, 0.0);
    for y in 0..n {
        for x in 0..n {
            out.data[y * n + x] = img.at(y, n - 1 - x);
        }
    }
    out
}

#[test]
fn keypoints_turn_with_the_image() {
    // 2^k + 1 pixels: every octave's samples are symmetric under the quarter turn.
    let n = 257;
    let img = rooms(n);
    let turned = rotate_quarter(&img);
    for (delta_min, sigma_min) in [(2.0, 1.6), (1.0, 0.8), (0.5, 0.8)] {
        let config = ScaleSpaceConfig {
            delta_min,
            sigma_min,
            crop_margin: None,
            ..ScaleSpaceConfig::default()
        };
        let a = detect(&img, &config);
        let b = detect(&turned, &config);
        assert!(a.len() > 50, "too few keypoints to be a test: {}", a.len());
        let found = a
            .iter()
            .filter(|k| {
                let (x, y) = ((n - 1) as f64 - k.y, k.x);
                b.iter().any(|q| {
                    (q.x - x).abs() < 1e-3
                        && (q.y - y).abs() < 1e-3
                        && (q.sigma - k.sigma).abs() < 1e-3
                })
            })
            .count();
        // Float rounding differs between row and column passes, which may flip a borderline
        // threshold decision; everything else must coincide.
        assert!(
            found as f64 >= 0.98 * a.len() as f64 && b.len().abs_diff(a.len()) <= a.len() / 50,
            "delta_min {delta_min}: {found} of {} found, {} in the turned image",
            a.len(),
            b.len()
        );
    }
}

#[test]
fn cropped_detection_reports_grid_coordinates() {
    use grid_core::{OccupancyGrid, Pose2, UNKNOWN};
    use scale_space::{IntensityMapping, detect_grid};
    // A free disk of radius 6 centred on cell (203, 151) in an unknown 320 x 240 grid.
    let (w, h, cx, cy) = (320usize, 240usize, 203i64, 151i64);
    let cells = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            if (x - cx).pow(2) + (y - cy).pow(2) <= 36 {
                0
            } else {
                UNKNOWN
            }
        })
        .collect();
    let grid = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
    // Margins 66 and 26 put the disk centre on a sample of every octave up to 2 (72 and 32
    // cells from the crop corner). With margin 64 it would fall midway between two samples of
    // octave 2, where the IPOL refinement oscillates (offset 0.62 > 0.6 both ways) and drops the
    // extremum: faithful, and a known weakness on binary maps.
    for crop_margin in [None, Some(66), Some(26)] {
        let config = ScaleSpaceConfig {
            crop_margin,
            ..ScaleSpaceConfig::default()
        };
        let mut out = Vec::new();
        let offset = detect_grid(
            &grid,
            &IntensityMapping::default(),
            &config,
            &mut ScaleSpace::new(),
            &mut out,
        )
        .unwrap();
        let want_offset = crop_margin.map_or((0.0, 0.0), |m| {
            ((cx - 6 - m as i64) as f64, (cy - 6 - m as i64) as f64)
        });
        assert_eq!(offset, Some(want_offset));
        // The disk is symmetric about its centre, so its blob keypoint sits there, up to the
        // quadratic interpolation error of a coarse octave whose samples (every 2^o cells) are
        // not centred on the disk (measured 0.037 px without crop).
        let blob = out
            .iter()
            .min_by(|a, b| a.response.total_cmp(&b.response))
            .unwrap_or_else(|| panic!("crop {crop_margin:?}: no keypoint in {out:?}"));
        let err = ((blob.x - cx as f64).powi(2) + (blob.y - cy as f64).powi(2)).sqrt();
        assert!(
            err < 0.1,
            "crop {crop_margin:?}: blob at ({}, {})",
            blob.x,
            blob.y
        );
    }
    let empty = OccupancyGrid::new(50, 40, 0.05, Pose2::default()).unwrap();
    let mut out = Vec::new();
    let got = detect_grid(
        &empty,
        &IntensityMapping::default(),
        &ScaleSpaceConfig::default(),
        &mut ScaleSpace::new(),
        &mut out,
    );
    assert_eq!(got, Ok(None));
    assert!(out.is_empty());
}

#[test]
fn a_coarse_first_octave_needs_enough_blur() {
    let config = |delta_min, sigma_min| ScaleSpaceConfig {
        delta_min,
        sigma_min,
        ..ScaleSpaceConfig::default()
    };
    assert_eq!(ScaleSpaceConfig::default().validate(), Ok(()));
    assert_eq!(config(2.0, 1.6).validate(), Ok(()));
    assert_eq!(
        config(2.0, 0.8).validate(),
        Err(scale_space::Error::Config(
            "a first octave coarser than the input (delta_min > 1) needs sigma_min >= 0.8 delta_min, or it aliases"
        ))
    );
    assert_eq!(
        config(2.5, 2.0).validate(),
        Err(scale_space::Error::Config("delta_min must be in (0, 2]"))
    );
}

/// `img` turned by `theta` about its centre onto an `n x n` canvas (n the image's diagonal),
/// nearest neighbour, as a map is warped: straight edges become staircases. Outside: 0.
fn turned_nearest(img: &Image, theta: f32) -> Image {
    let (w, h) = (img.width as f32, img.height as f32);
    let n = (w * w + h * h).sqrt().ceil() as usize;
    let (sin, cos) = theta.sin_cos();
    let c = (n as f32 - 1.0) / 2.0;
    let (cx, cy) = ((w - 1.0) / 2.0, (h - 1.0) / 2.0);
    let mut out = Image::filled(n, n, 0.0);
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f32 - c, y as f32 - c);
            let (sx, sy) = (cos * u + sin * v + cx, -sin * u + cos * v + cy);
            let (ix, iy) = (sx.round(), sy.round());
            if ix >= 0.0 && iy >= 0.0 && ix < w && iy < h {
                out.data[y * n + x] = img.at(ix as usize, iy as usize);
            }
        }
    }
    out
}

#[test]
fn a_turned_copy_has_about_as_many_keypoints() {
    // The edge test reads the spatial Hessian of the DoG; with plain 3-point second
    // differences a straight edge turned to a staircase at 30 degrees passed it all along its
    // length (the nav2 warehouse map turned by 30 degrees: 4152 keypoints against 738). With
    // the second differences averaged over the cross difference's 3 x 3 footprint, 765. Here
    // (measured): 154, 139 and 149 keypoints at 30, 45 and 60 degrees against 139, where the
    // plain differences gave 236, 169 and 235 against 141.
    let img = rooms(257);
    // The same canvas for both: the unturned picture at the centre of its turned size.
    let config = ScaleSpaceConfig {
        crop_margin: None,
        ..ScaleSpaceConfig::default()
    };
    let straight = detect(&turned_nearest(&img, 0.0), &config).len();
    assert!(straight > 50, "too few keypoints to be a test: {straight}");
    for deg in [30f32, 45.0, 60.0] {
        let turned = detect(&turned_nearest(&img, deg.to_radians()), &config).len();
        let ratio = turned as f64 / straight as f64;
        assert!(
            (0.75..1.33).contains(&ratio),
            "{deg} degrees: {turned} keypoints against {straight} unturned"
        );
    }
}
