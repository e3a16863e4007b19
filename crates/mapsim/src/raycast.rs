//! Exact grid traversal (Amanatides & Woo) in the pixel convention: cell `(i, j)` covers
//! `[i - 0.5, i + 0.5) x [j - 0.5, j + 0.5)`.

use glam::DVec2;

use crate::world::World;

/// Visit the cells a ray from `origin` along unit `dir` crosses, in order, while the entry
/// distance is below `max_t`. `visit(x, y, t_enter)` returns `false` to stop.
#[inline]
pub(crate) fn traverse(
    origin: DVec2,
    dir: DVec2,
    max_t: f64,
    mut visit: impl FnMut(i64, i64, f64) -> bool,
) {
    // Shift so that cells are [i, i + 1).
    let p = origin + DVec2::splat(0.5);
    let (mut cx, mut cy) = (p.x.floor() as i64, p.y.floor() as i64);
    let step_x: i64 = if dir.x > 0.0 { 1 } else { -1 };
    let step_y: i64 = if dir.y > 0.0 { 1 } else { -1 };
    let delta_x = if dir.x != 0.0 {
        1.0 / dir.x.abs()
    } else {
        f64::INFINITY
    };
    let delta_y = if dir.y != 0.0 {
        1.0 / dir.y.abs()
    } else {
        f64::INFINITY
    };
    let mut next_x = if dir.x > 0.0 {
        (cx as f64 + 1.0 - p.x) * delta_x
    } else if dir.x < 0.0 {
        (p.x - cx as f64) * delta_x
    } else {
        f64::INFINITY
    };
    let mut next_y = if dir.y > 0.0 {
        (cy as f64 + 1.0 - p.y) * delta_y
    } else if dir.y < 0.0 {
        (p.y - cy as f64) * delta_y
    } else {
        f64::INFINITY
    };
    let mut t = 0.0;
    while t < max_t {
        if !visit(cx, cy, t) {
            return;
        }
        if next_x < next_y {
            t = next_x;
            next_x += delta_x;
            cx += step_x;
        } else {
            t = next_y;
            next_y += delta_y;
            cy += step_y;
        }
    }
}

/// Distance from `origin` along unit `dir` to the boundary of the first obstacle cell, or `None`
/// when there is none within `max_t`.
#[inline]
pub(crate) fn cast(world: &World, origin: DVec2, dir: DVec2, max_t: f64) -> Option<f64> {
    let mut hit = None;
    traverse(origin, dir, max_t, |x, y, t| {
        if world.is_occupied(x, y) {
            hit = Some(t);
            false
        } else {
            true
        }
    });
    hit
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traverse_axis_aligned() {
        let mut cells = Vec::new();
        traverse(DVec2::new(0.0, 0.0), DVec2::X, 3.0, |x, y, t| {
            cells.push((x, y, t));
            true
        });
        assert_eq!(
            cells,
            vec![(0, 0, 0.0), (1, 0, 0.5), (2, 0, 1.5), (3, 0, 2.5)]
        );
    }

    #[test]
    fn cast_hits_cell_boundary() {
        let mut occ = vec![false; 100];
        occ[5 * 10 + 7] = true; // cell (7, 5)
        let w = World::from_raster(10, 10, 0.05, occ).unwrap();
        let t = cast(&w, DVec2::new(2.0, 5.0), DVec2::X, 20.0).unwrap();
        assert!((t - 4.5).abs() < 1e-12, "{t}");
        // Diagonal ray through (2,0): reaches cell boundary x = 6.5 of the border? No: the raster
        // edge counts as an obstacle, at x = 9.5.
        let t = cast(&w, DVec2::new(2.0, 0.0), DVec2::X, 20.0).unwrap();
        assert!((t - 7.5).abs() < 1e-12, "{t}");
        assert_eq!(cast(&w, DVec2::new(2.0, 5.0), DVec2::X, 4.0), None);
    }
}
