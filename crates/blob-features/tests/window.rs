//! Extraction works on the known cells' bounding box only; the blobs must be exactly those of
//! the whole grid.

use blob_features::{Blob, BlobConfig, Blobs, MaskKind};
use grid_core::io::{LoadOptions, load_map};
use grid_core::{FeatureExtractor, OccupancyGrid, Rigid2};

/// A real floor turned by 30 degrees on a canvas with a wide unknown surround.
fn canvas() -> OccupancyGrid {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/maps/uos_cic/uos_cic.yaml"
    );
    let map = load_map(path, &LoadOptions::default()).expect("fixture loads");
    map.warp(&Rigid2::new(30f64.to_radians(), 900.0, 150.0), 2000, 2000)
        .expect("canvas")
}

/// The blobs without their labels (label numbering follows the window, not the grid).
fn blobs(grid: &OccupancyGrid, config: BlobConfig) -> Vec<Blob> {
    let mut out = Vec::new();
    Blobs::new(config).extract(grid, &mut out);
    out.iter_mut().for_each(|b| b.label = 0);
    out
}

#[test]
fn windowed_extraction_equals_whole_grid_extraction() {
    let grid = canvas();
    let (x0, y0, w, h) = grid.known_bounds(0).expect("known cells");
    assert!(
        w * h < grid.width() * grid.height() / 2,
        "the test needs a big surround"
    );
    // Free corner cells make the known bounding box the whole grid, so nothing is cropped; a
    // corner cell only ever touches the surround, which no mask kind keeps as a blob.
    let mut whole = grid.clone();
    let (gw, gh) = (grid.width(), grid.height());
    for (x, y) in [(0, 0), (gw - 1, 0), (0, gh - 1), (gw - 1, gh - 1)] {
        whole.set_probability(x, y, Some(0.0));
    }
    assert_eq!(whole.known_bounds(0), Some((0, 0, gw, gh)));
    for mask in [MaskKind::NotFreeIslands, MaskKind::Occupied] {
        for close_radius in [0, 1, 2] {
            let config = BlobConfig {
                mask,
                close_radius,
                ..BlobConfig::default()
            };
            let (windowed, reference) = (blobs(&grid, config), blobs(&whole, config));
            assert!(
                reference.len() >= 5,
                "{mask:?} r {close_radius}: too few blobs to be a test ({})",
                reference.len()
            );
            assert_eq!(windowed, reference, "{mask:?} r {close_radius}");
            // And every blob lies in the known window.
            for b in &windowed {
                let c = b.shape.centroid;
                assert!(c.x >= x0 as f64 && c.x < (x0 + w) as f64);
                assert!(c.y >= y0 as f64 && c.y < (y0 + h) as f64);
            }
        }
    }
}
