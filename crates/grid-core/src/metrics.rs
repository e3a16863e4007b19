//! How registration and merging are judged (see the project's conventions): rotation error,
//! displacement error and the acceptance index of Birk & Carpin (2006).

use glam::DVec2;

use crate::{CellState, OccupancyGrid, Rigid2, wrap_angle};

/// `|theta_est - theta_true|` wrapped to `[0, 180]` degrees.
pub fn rotation_error_deg(est: &Rigid2, truth: &Rigid2) -> f64 {
    wrap_angle(est.theta - truth.theta).abs().to_degrees()
}

/// Mean over the known cells `p` of `b` of `|est(p) - truth(p)|`, in pixels; `None` when `b` has
/// no known cell.
pub fn displacement_error(b: &OccupancyGrid, est: &Rigid2, truth: &Rigid2) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 0..b.height() {
        for x in 0..b.width() {
            if b.state(x, y) != CellState::Unknown {
                let p = DVec2::new(x as f64, y as f64);
                sum += (est.apply(p) - truth.apply(p)).length();
                n += 1;
            }
        }
    }
    (n > 0).then(|| sum / n as f64)
}

/// Agreement of two maps after alignment, counted over cells known in both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Agreement {
    /// Cells known in both maps with the same state (free/free or occupied/occupied).
    pub agree: usize,
    /// Cells known in both maps with different states.
    pub disagree: usize,
}

impl Agreement {
    /// The acceptance index `agree / (agree + disagree)`, `None` when nothing overlaps.
    pub fn acceptance_index(&self) -> Option<f64> {
        let n = self.agree + self.disagree;
        (n > 0).then(|| self.agree as f64 / n as f64)
    }

    /// Number of cells known in both maps.
    pub fn overlap(&self) -> usize {
        self.agree + self.disagree
    }
}

/// Agreement of `a` with `b` mapped onto `a` by `b_to_a` (nearest neighbour), over the cells of
/// `a`.
pub fn agreement(a: &OccupancyGrid, b: &OccupancyGrid, b_to_a: &Rigid2) -> Agreement {
    let inv = b_to_a.inverse();
    let (s, c) = inv.theta.sin_cos();
    let mut out = Agreement::default();
    for y in 0..a.height() {
        for x in 0..a.width() {
            let sa = a.state(x, y);
            if sa == CellState::Unknown {
                continue;
            }
            let (xf, yf) = (x as f64, y as f64);
            let bx = (c * xf - s * yf + inv.tx).round();
            let by = (s * xf + c * yf + inv.ty).round();
            if bx < 0.0 || by < 0.0 {
                continue;
            }
            match b.state(bx as usize, by as usize) {
                CellState::Unknown => {}
                sb if sb == sa => out.agree += 1,
                _ => out.disagree += 1,
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Pose2, UNKNOWN};

    #[test]
    fn rotation_error_wraps() {
        let e = rotation_error_deg(&Rigid2::new(3.1, 0.0, 0.0), &Rigid2::new(-3.1, 0.0, 0.0));
        assert!((e - (2.0 * std::f64::consts::PI - 6.2).to_degrees()).abs() < 1e-9);
    }

    #[test]
    fn displacement_error_of_a_pure_shift() {
        let g = OccupancyGrid::from_cells(2, 1, 0.05, Pose2::default(), vec![0, UNKNOWN]).unwrap();
        let e = displacement_error(&g, &Rigid2::new(0.0, 3.0, 4.0), &Rigid2::IDENTITY).unwrap();
        assert_eq!(e, 5.0);
    }

    #[test]
    fn agreement_counts_known_cells_only() {
        // a: free, occ, unknown; b all free, b pixel x lands on a pixel x - 1.
        let a =
            OccupancyGrid::from_cells(3, 1, 0.05, Pose2::default(), vec![0, 100, UNKNOWN]).unwrap();
        let b = OccupancyGrid::from_cells(3, 1, 0.05, Pose2::default(), vec![0, 0, 0]).unwrap();
        let ag = agreement(&a, &b, &Rigid2::new(0.0, -1.0, 0.0));
        assert_eq!(
            ag,
            Agreement {
                agree: 1,
                disagree: 1
            }
        );
        assert_eq!(ag.acceptance_index(), Some(0.5));
    }
}
