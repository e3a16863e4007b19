//! What the two mask kinds turn into components.

use blob_features::{BlobConfig, Blobs, MaskKind, UnknownPolicy};
use grid_core::{FeatureExtractor, OccupancyGrid, Pose2, UNKNOWN};

/// 60 x 40 free map; a 10 x 8 obstacle seen from all around (1 px occupied ring, unknown
/// inside) at x 10..20, y 10..18; a wall along the left border; one unknown column on the right.
fn map() -> OccupancyGrid {
    let (w, h) = (60, 40);
    let mut cells = vec![0u8; w * h];
    for y in 10..18 {
        for x in 10..20 {
            let ring = y == 10 || y == 17 || x == 10 || x == 19;
            cells[y * w + x] = if ring { 100 } else { UNKNOWN };
        }
    }
    for y in 0..h {
        cells[y * w] = 100;
        cells[y * w + w - 1] = UNKNOWN;
    }
    OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
}

fn blobs(mask: MaskKind) -> Vec<blob_features::Blob> {
    let cfg = BlobConfig {
        mask,
        min_area: 1,
        close_radius: 0,
        unknown: UnknownPolicy::Keep,
        ..BlobConfig::default()
    };
    let mut out = Vec::new();
    Blobs::new(cfg).extract(&map(), &mut out);
    out
}

#[test]
fn islands_are_whole_footprints_and_border_components_are_dropped() {
    let b = blobs(MaskKind::NotFreeIslands);
    assert_eq!(b.len(), 1, "{b:?}");
    assert_eq!(b[0].shape.area, 80);
    assert_eq!(b[0].shape.unknown_contact, 0.0);
    assert!((b[0].shape.centroid - grid_core::DVec2::new(14.5, 13.5)).length() < 1e-9);
}

#[test]
fn occupied_components_are_the_drawn_cells() {
    let b = blobs(MaskKind::Occupied);
    // The ring (2 x 10 + 2 x 6 = 32 cells) and the border wall (40 cells); the unknown column
    // is not an obstacle.
    let mut areas: Vec<_> = b.iter().map(|b| b.shape.area).collect();
    areas.sort();
    assert_eq!(areas, vec![32, 40]);
    let ring = b.iter().find(|b| b.shape.area == 32).unwrap();
    // Every ring pixel is on the boundary and has an unknown interior cell among its 8
    // neighbours.
    assert!(
        (ring.shape.unknown_contact - 1.0).abs() < 1e-12,
        "{}",
        ring.shape.unknown_contact
    );
}
