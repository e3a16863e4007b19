//! Moments of rasterised analytic shapes.

mod common;

use std::f64::consts::PI;

use blob_features::{Blob, BlobConfig, Blobs, UnknownPolicy};
use common::{Analytic, grid_with};
use grid_core::FeatureExtractor;

/// Exact-shape extraction: no closing, no area filter, no unknown weighting.
fn exact() -> Blobs {
    Blobs::new(BlobConfig {
        close_radius: 0,
        min_area: 1,
        unknown: UnknownPolicy::Keep,
        ..BlobConfig::default()
    })
}

fn one_blob(shape: Analytic) -> Blob {
    let grid = grid_with(&[shape], 300, 300);
    let mut blobs = Vec::new();
    exact().extract(&grid, &mut blobs);
    assert_eq!(blobs.len(), 1, "{shape:?}");
    blobs[0]
}

/// Difference of two axis angles modulo pi, in degrees, in [0, 90].
fn axis_diff_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(PI);
    d.min(PI - d).to_degrees()
}

#[test]
fn rectangles_and_ellipses_at_known_angles() {
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..36 {
        // Irrational-ish centre offsets so that rasterisation is not aligned with the grid.
        let angle = -PI / 2.0 + k as f64 * PI / 36.0 + 0.013;
        // Centres near half-pixels: a shape with integer half-extent aligned with the grid covers
        // rows ceil(c - a) ..= floor(c + a), whose mean is off by |frac(c) - 0.5| (up to 0.5 px
        // from quantisation alone, not from the moments).
        let (cx, cy) = (150.47 + 0.002 * k as f64, 149.53 - 0.002 * k as f64);
        for shape in [
            Analytic::Rect {
                cx,
                cy,
                a: 120.0,
                b: 20.0,
                angle,
            },
            Analytic::Ellipse {
                cx,
                cy,
                a: 120.0,
                b: 30.0,
                angle,
            },
            Analytic::Rect {
                cx,
                cy,
                a: 80.0,
                b: 40.0,
                angle,
            },
        ] {
            let blob = one_blob(shape);
            let s = &blob.shape;
            let c_err = (s.centroid.x - cx).hypot(s.centroid.y - cy);
            let a_err = (s.area as f64 - shape.area()).abs() / shape.area();
            let o = blob
                .orientation
                .expect("elongated shape has an orientation");
            let o_err = axis_diff_deg(o, angle);
            assert!(c_err < 0.1, "{shape:?}: centroid off by {c_err}");
            assert!(
                a_err < 0.01,
                "{shape:?}: area {} vs {}",
                s.area,
                shape.area()
            );
            assert!(o_err < 1.0, "{shape:?}: orientation {o} off by {o_err} deg");
            assert!((-PI / 2.0..=PI / 2.0).contains(&o));
            worst = (worst.0.max(c_err), worst.1.max(a_err), worst.2.max(o_err));
        }
    }
    println!(
        "worst centroid {:.4} px, area {:.4}, orientation {:.3} deg",
        worst.0, worst.1, worst.2
    );
}

#[test]
fn eigenvalues_of_an_axis_aligned_rectangle_are_exact() {
    // 41 x 11 pixel centres: variances (n^2 - 1)/12 + 1/12 = n^2 / 12 along each axis.
    let blob = one_blob(Analytic::Rect {
        cx: 80.0,
        cy: 80.0,
        a: 20.0,
        b: 5.0,
        angle: 0.0,
    });
    let s = blob.shape;
    assert_eq!(s.area, 41 * 11);
    assert!((s.eigenvalues[0] - 41.0f64.powi(2) / 12.0).abs() < 1e-9);
    assert!((s.eigenvalues[1] - 11.0f64.powi(2) / 12.0).abs() < 1e-9);
    assert_eq!(blob.orientation, Some(0.0));
    assert_eq!(
        (s.bbox.min_x, s.bbox.max_x, s.bbox.min_y, s.bbox.max_y),
        (60, 100, 75, 85)
    );
    // Boundary pixels: the ring of the 41 x 11 rectangle.
    assert_eq!(s.perimeter, 41 * 11 - 39 * 9);
}

#[test]
fn vertical_shape_points_down_the_rows() {
    let blob = one_blob(Analytic::Rect {
        cx: 80.0,
        cy: 80.0,
        a: 30.3,
        b: 3.3,
        angle: PI / 2.0,
    });
    assert!(axis_diff_deg(blob.orientation.unwrap(), PI / 2.0) < 1e-6);
    // Positive angle turns from +x towards +y (down on screen): a shape along x = y.
    let blob = one_blob(Analytic::Rect {
        cx: 80.0,
        cy: 80.0,
        a: 30.0,
        b: 3.0,
        angle: PI / 4.0,
    });
    assert!(axis_diff_deg(blob.orientation.unwrap(), PI / 4.0) < 0.5);
}

#[test]
fn round_shapes_have_no_orientation() {
    let config = BlobConfig::default();
    for shape in [
        Analytic::Ellipse {
            cx: 80.2,
            cy: 79.7,
            a: 20.0,
            b: 20.0,
            angle: 0.0,
        },
        Analytic::Rect {
            cx: 80.2,
            cy: 79.7,
            a: 15.0,
            b: 15.0,
            angle: 0.4,
        },
        Analytic::Ellipse {
            cx: 80.2,
            cy: 79.7,
            a: 20.0,
            b: 19.0,
            angle: 0.3,
        },
    ] {
        let blob = one_blob(shape);
        assert!(blob.shape.roundness() > config.round_ratio, "{shape:?}");
        assert_eq!(blob.orientation, None, "{shape:?}");
    }
}

#[test]
fn hu_invariants_do_not_change_under_rotation() {
    let base = one_blob(Analytic::Triangle {
        cx: 150.0,
        cy: 150.0,
        a: 100.0,
        b: 70.0,
        angle: 0.0,
    });
    for k in 1..8 {
        let angle = k as f64 * 0.7;
        let b = one_blob(Analytic::Triangle {
            cx: 150.0,
            cy: 150.0,
            a: 100.0,
            b: 70.0,
            angle,
        });
        for i in 0..4 {
            let d = (b.shape.hu[i] - base.shape.hu[i]).abs();
            assert!(d < 0.02, "hu{} differs by {d} at angle {angle}", i + 1);
        }
    }
}

#[test]
fn centroid_is_exact_far_from_the_origin() {
    // Moments are accumulated relative to each component, so a shape near the corner of a
    // large map keeps sub-pixel accuracy.
    let (w, h) = (5000, 3000);
    let shape = Analytic::Ellipse {
        cx: 4950.25,
        cy: 2950.75,
        a: 30.0,
        b: 10.0,
        angle: 0.3,
    };
    let mut cells = vec![0u8; w * h];
    shape.paint(&mut cells, w, h, 100);
    let grid = grid_core::OccupancyGrid::from_cells(w, h, 0.05, Default::default(), cells).unwrap();
    let mut blobs = Vec::new();
    exact().extract(&grid, &mut blobs);
    assert_eq!(blobs.len(), 1);
    let c = blobs[0].shape.centroid;
    assert!(
        (c.x - 4950.25).abs() < 0.1 && (c.y - 2950.75).abs() < 0.1,
        "{c}"
    );
}
