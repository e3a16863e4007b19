use std::f64::consts::PI;
use std::ops::Mul;

use glam::{DMat2, DVec2};

use crate::GridGeometry;

/// Wrap an angle in radians to `(-pi, pi]`.
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI { w - 2.0 * PI } else { w }
}

/// A rigid 2-D transform: rotation by `theta` (radians) then translation by `(tx, ty)`.
///
/// In the pixel convention (y down) a registration result maps a point of map B onto map A:
/// `x_a = cos(theta) x_b - sin(theta) y_b + tx`, `y_a = sin(theta) x_b + cos(theta) y_b + ty`.
/// `a * b` applies `b` first, then `a`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Rigid2 {
    /// Rotation angle in radians.
    pub theta: f64,
    /// Translation along x.
    pub tx: f64,
    /// Translation along y.
    pub ty: f64,
}

impl Rigid2 {
    /// The identity transform.
    pub const IDENTITY: Self = Self {
        theta: 0.0,
        tx: 0.0,
        ty: 0.0,
    };

    /// A transform from angle and translation.
    pub const fn new(theta: f64, tx: f64, ty: f64) -> Self {
        Self { theta, tx, ty }
    }

    /// The rotation by `theta` about the point `pivot` (which it leaves in place).
    pub fn rotation_about(theta: f64, pivot: DVec2) -> Self {
        let m = pivot - Self::new(theta, 0.0, 0.0).apply(pivot);
        Self::new(theta, m.x, m.y)
    }

    /// The translation as a vector.
    pub fn translation(&self) -> DVec2 {
        DVec2::new(self.tx, self.ty)
    }

    /// The rotation matrix.
    pub fn rotation(&self) -> DMat2 {
        DMat2::from_angle(self.theta)
    }

    /// Apply to a point.
    #[inline]
    pub fn apply(&self, p: DVec2) -> DVec2 {
        let (s, c) = self.theta.sin_cos();
        DVec2::new(c * p.x - s * p.y + self.tx, s * p.x + c * p.y + self.ty)
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let t = DVec2::from_angle(-self.theta).rotate(-self.translation());
        Self {
            theta: wrap_angle(-self.theta),
            tx: t.x,
            ty: t.y,
        }
    }

    /// `self * other`: apply `other`, then `self`.
    pub fn compose(&self, other: &Self) -> Self {
        let t = self.apply(other.translation());
        Self {
            theta: wrap_angle(self.theta + other.theta),
            tx: t.x,
            ty: t.y,
        }
    }

    /// The same transform with its angle wrapped to `(-pi, pi]`.
    pub fn normalized(&self) -> Self {
        Self {
            theta: wrap_angle(self.theta),
            ..*self
        }
    }

    /// Convert a pixel-convention registration result into B's map frame expressed in A's map
    /// frame (metres, yaw counter-clockwise), ready to be published as a ROS TF transform.
    ///
    /// Both maps must have the same resolution for the result to be rigid; with different
    /// resolutions the caller must rescale B first.
    pub fn to_world(&self, a: &GridGeometry, b: &GridGeometry) -> Self {
        // A world map frame point w_b -> B pixel -> A pixel -> A world: rigid, since the two
        // reflections (y down in pixels, up in the world) cancel.
        Self::from_rigid_map(|w| a.pixel_to_world(self.apply(b.world_to_pixel(w))))
    }

    /// The inverse of [`Self::to_world`]: a pose of B's map frame in A's map frame turned into
    /// the pixel transform from B's pixels to A's pixels.
    pub fn from_world(world: &Self, a: &GridGeometry, b: &GridGeometry) -> Self {
        Self::from_rigid_map(|p| a.world_to_pixel(world.apply(b.pixel_to_world(p))))
    }
}

impl Rigid2 {
    /// Read a rigid transform off a map known to be rigid, from where it sends the origin and
    /// the unit x vector.
    fn from_rigid_map(f: impl Fn(DVec2) -> DVec2) -> Self {
        let o = f(DVec2::ZERO);
        let ex = f(DVec2::X) - o;
        Self {
            theta: wrap_angle(ex.y.atan2(ex.x)),
            tx: o.x,
            ty: o.y,
        }
    }
}

impl Mul for Rigid2 {
    type Output = Rigid2;
    fn mul(self, rhs: Rigid2) -> Rigid2 {
        self.compose(&rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Pose2;
    use proptest::prelude::*;

    fn close(a: &Rigid2, b: &Rigid2, tol: f64) -> bool {
        wrap_angle(a.theta - b.theta).abs() < tol
            && (a.tx - b.tx).abs() < tol
            && (a.ty - b.ty).abs() < tol
    }

    fn rigid() -> impl Strategy<Value = Rigid2> {
        (-PI..PI, -1e3..1e3, -1e3..1e3).prop_map(|(t, x, y)| Rigid2::new(t, x, y))
    }

    #[test]
    fn a_rotation_about_a_pivot_keeps_it_and_turns_the_rest() {
        let pivot = DVec2::new(3.0, -2.0);
        let t = Rigid2::rotation_about(PI / 2.0, pivot);
        assert!((t.apply(pivot) - pivot).length() < 1e-12, "{t:?}");
        // A point one to the right of the pivot ends one below it (y down: clockwise on screen).
        let p = t.apply(pivot + DVec2::X);
        assert!((p - (pivot + DVec2::Y)).length() < 1e-12, "{p}");
        assert_eq!(
            Rigid2::rotation_about(0.3, DVec2::ZERO),
            Rigid2::new(0.3, 0.0, 0.0)
        );
    }

    #[test]
    fn quarter_turn_of_a_3_by_2_map() {
        // B is 3 wide, 2 high. A is B turned by +90 deg in the pixel convention (clockwise on
        // screen) and shifted so it fits a 2 x 3 canvas: B (x, y) -> A (1 - y, x).
        let t = Rigid2::new(PI / 2.0, 1.0, 0.0);
        let cases = [
            ((0.0, 0.0), (1.0, 0.0)),
            ((2.0, 0.0), (1.0, 2.0)),
            ((0.0, 1.0), (0.0, 0.0)),
            ((2.0, 1.0), (0.0, 2.0)),
        ];
        for ((bx, by), (ax, ay)) in cases {
            let p = t.apply(DVec2::new(bx, by));
            assert!(
                (p - DVec2::new(ax, ay)).length() < 1e-12,
                "({bx},{by}) -> {p}"
            );
        }
        // In the world (y up, same resolution and origins), a clockwise quarter turn on screen
        // is yaw -90 deg.
        let a = GridGeometry {
            width: 2,
            height: 3,
            resolution: 1.0,
            origin: Pose2::default(),
        };
        let b = GridGeometry {
            width: 3,
            height: 2,
            resolution: 1.0,
            origin: Pose2::default(),
        };
        let w = t.to_world(&a, &b);
        assert!((w.theta + PI / 2.0).abs() < 1e-12, "{w:?}");
        // B pixel (0,1) is its lower-left cell, world (0.5, 0.5); it lands on A pixel (0,0), the
        // top-left cell of A, world (0.5, 2.5).
        let p = w.apply(DVec2::new(0.5, 0.5));
        assert!((p - DVec2::new(0.5, 2.5)).length() < 1e-12, "{p}");
    }

    #[test]
    fn wrap_angle_range() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
    }

    proptest! {
        #[test]
        fn inverse_is_identity(t in rigid(), x in -1e3..1e3f64, y in -1e3..1e3f64) {
            prop_assert!(close(&(t * t.inverse()), &Rigid2::IDENTITY, 1e-9));
            prop_assert!(close(&(t.inverse() * t), &Rigid2::IDENTITY, 1e-9));
            let p = DVec2::new(x, y);
            prop_assert!((t.inverse().apply(t.apply(p)) - p).length() < 1e-8);
        }

        #[test]
        fn composition_is_associative(a in rigid(), b in rigid(), c in rigid()) {
            prop_assert!(close(&((a * b) * c), &(a * (b * c)), 1e-8));
        }

        #[test]
        fn compose_matches_sequential_application(a in rigid(), b in rigid(), x in -1e3..1e3f64, y in -1e3..1e3f64) {
            let p = DVec2::new(x, y);
            prop_assert!(((a * b).apply(p) - a.apply(b.apply(p))).length() < 1e-8);
        }

        #[test]
        fn world_pixel_round_trip(t in rigid(), yaw_a in -PI..PI, yaw_b in -PI..PI, ox in -50.0..50.0f64,
                                  oy in -50.0..50.0f64, r in 0.01..0.5f64) {
            let a = GridGeometry { width: 120, height: 80, resolution: r, origin: Pose2::new(ox, oy, yaw_a) };
            let b = GridGeometry { width: 60, height: 90, resolution: r, origin: Pose2::new(-oy, ox, yaw_b) };
            let w = t.to_world(&a, &b);
            prop_assert!(close(&Rigid2::from_world(&w, &a, &b), &t, 1e-6));
            // The world transform is rigid: it maps B's pixel centres, taken to world, onto the
            // world positions of the A pixels the pixel transform gives.
            let p = DVec2::new(17.0, 42.0);
            let lhs = w.apply(b.pixel_to_world(p));
            let rhs = a.pixel_to_world(t.apply(p));
            prop_assert!((lhs - rhs).length() < 1e-8);
        }
    }
}
