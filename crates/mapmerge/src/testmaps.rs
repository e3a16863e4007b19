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

/// A bare rectangular room (90 x 60 inside) on a 120 x 100 canvas: a half turn about its centre
/// maps it onto itself, so no pose between it and a turned copy can be told from its twin.
pub(crate) fn bare_room() -> OccupancyGrid {
    let (w, h) = (120, 100);
    let mut cells = vec![UNKNOWN; w * h];
    for y in 20..80 {
        for x in 15..105 {
            let wall = x == 15 || x == 104 || y == 20 || y == 79;
            cells[y * w + x] = if wall { 100 } else { 0 };
        }
    }
    OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
}
