//! Small synthetic maps shared by the unit tests.

use grid_core::{OccupancyGrid, Pose2, UNKNOWN};

/// An L-shaped room with a pillar on a 120 x 100 canvas: walls in both directions pin the pose,
/// and no turn of it but the identity fits it.
pub(crate) fn room() -> OccupancyGrid {
    grown_room(0)
}

/// [`room`] with a wall across it along row `y` (cells 20-99), as a robot that saw an obstacle
/// the other robot's map shows as free space would map it.
pub(crate) fn room_with_wall_across(y: usize) -> OccupancyGrid {
    let mut grid = room();
    let w = grid.width();
    for x in 20..100 {
        grid.cells_mut()[y * w + x] = 100;
    }
    grid
}

/// [`room`] with its outer walls moved `d` cells outwards (at most 2), as a range sensor's bias
/// pushes walls seen from inside the room; the half wall and the pillar stay.
pub(crate) fn grown_room(d: usize) -> OccupancyGrid {
    assert!(d <= 2);
    let (w, h) = (120, 100);
    let (x0, x1, y0, y1) = (10 - d, 109 + d, 10 - d, 89 + d);
    let mut cells = vec![UNKNOWN; w * h];
    for y in y0..=y1 {
        for x in x0..=x1 {
            let wall = x == x0 || x == x1 || y == y0 || y == y1 || (x >= 60 && y == 50);
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
