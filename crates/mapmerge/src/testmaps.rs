//! Small synthetic maps shared by the unit tests.

use grid_core::{OccupancyGrid, Pose2, UNKNOWN};

/// An L-shaped room with a pillar on a 120 x 100 canvas: walls in both directions pin the pose,
/// and no turn of it but the identity fits it.
pub(crate) fn room() -> OccupancyGrid {
    let (w, h) = (120, 100);
    let mut cells = vec![UNKNOWN; w * h];
    for y in 10..90 {
        for x in 10..110 {
            let wall = x == 10 || x == 109 || y == 10 || y == 89 || (x >= 60 && y == 50);
            let pillar = (30..36).contains(&x) && (30..34).contains(&y);
            cells[y * w + x] = if wall || pillar { 100 } else { 0 };
        }
    }
    OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
}
