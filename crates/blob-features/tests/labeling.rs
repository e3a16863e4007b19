//! The labeller against a BFS flood-fill oracle.

mod common;

use blob_features::{BlobError, Connectivity, Labeler};
use common::{bfs_labels, random_mask};
use proptest::prelude::*;

fn conn() -> impl Strategy<Value = Connectivity> {
    prop_oneof![Just(Connectivity::Four), Just(Connectivity::Eight)]
}

proptest! {
    // Both number components by their first pixel in raster order, so the partitions must be
    // equal label for label (which implies equal up to relabelling).
    #[test]
    fn equals_flood_fill(w in 1usize..48, h in 1usize..48, density in 0.0f64..1.0,
                         seed in any::<u64>(), strips in 1usize..9, conn in conn()) {
        let mask = random_mask(w, h, density, seed);
        let (want, n_want) = bfs_labels(&mask, w, h, conn);
        let mut labels = Vec::new();
        let n = Labeler::new(conn).with_strips(strips).label(&mask, w, h, &mut labels).unwrap();
        prop_assert_eq!(n, n_want);
        prop_assert_eq!(labels, want);
    }
}

#[test]
fn large_random_masks_take_the_parallel_path_and_equal_flood_fill() {
    // 700 x 500 > 2^18 pixels: automatic strip count. Densities around the 8-connectivity
    // percolation threshold give long, branching components that cross many seams.
    let (w, h) = (700, 500);
    let mut labeler = Labeler::new(Connectivity::Eight);
    let mut labels = Vec::new();
    for (seed, density) in [(1u64, 0.3), (2, 0.45), (3, 0.6)] {
        for conn in [Connectivity::Four, Connectivity::Eight] {
            labeler.set_connectivity(conn);
            let mask = random_mask(w, h, density, seed);
            let (want, n_want) = bfs_labels(&mask, w, h, conn);
            let n = labeler.label(&mask, w, h, &mut labels).unwrap();
            assert_eq!(n, n_want, "density {density} {conn:?}");
            assert!(labels == want, "density {density} {conn:?}: labels differ");
        }
    }
}

#[test]
fn one_component_over_the_whole_map() {
    // No recursion: a 1000 x 1000 all-ones map is a single component.
    let (w, h) = (1000, 1000);
    let mask = vec![1u8; w * h];
    let mut labels = Vec::new();
    for conn in [Connectivity::Four, Connectivity::Eight] {
        let n = Labeler::new(conn).label(&mask, w, h, &mut labels).unwrap();
        assert_eq!(n, 1);
        assert!(labels.iter().all(|&l| l == 1));
    }
}

#[test]
fn serpentine_crossing_every_seam_is_one_component() {
    // A snake that turns at alternate ends of every other row: one component whose union-find
    // chains run across every strip seam.
    let (w, h) = (64, 257);
    let mut mask = vec![0u8; w * h];
    for y in 0..h {
        if y % 2 == 0 {
            mask[y * w..(y + 1) * w].fill(1);
        } else {
            let x = if y % 4 == 1 { w - 1 } else { 0 };
            mask[y * w + x] = 1;
        }
    }
    for strips in [1, 2, 7, 64, 257] {
        let mut labels = Vec::new();
        let n = Labeler::new(Connectivity::Four)
            .with_strips(strips)
            .label(&mask, w, h, &mut labels)
            .unwrap();
        assert_eq!(n, 1, "{strips} strips");
    }
}

#[test]
fn checkerboard_depends_on_connectivity() {
    let (w, h) = (9, 7);
    let mask: Vec<u8> = (0..w * h)
        .map(|i| u8::from((i % w + i / w) % 2 == 0))
        .collect();
    let mut labels = Vec::new();
    let n8 = Labeler::new(Connectivity::Eight)
        .label(&mask, w, h, &mut labels)
        .unwrap();
    assert_eq!(n8, 1);
    let n4 = Labeler::new(Connectivity::Four)
        .label(&mask, w, h, &mut labels)
        .unwrap();
    assert_eq!(n4, (w * h).div_ceil(2));
}

#[test]
fn wrong_mask_size_is_an_error() {
    let mut labels = Vec::new();
    let err = Labeler::default()
        .label(&[1, 0, 1], 2, 2, &mut labels)
        .unwrap_err();
    assert_eq!(
        err,
        BlobError::MaskSize {
            got: 3,
            width: 2,
            height: 2
        }
    );
    assert_eq!(err.to_string(), "mask has 3 entries, expected 2 x 2 = 4");
}

#[test]
fn empty_image_has_no_component() {
    let mut labels = vec![7];
    assert_eq!(Labeler::default().label(&[], 0, 5, &mut labels).unwrap(), 0);
    assert!(labels.is_empty());
}
