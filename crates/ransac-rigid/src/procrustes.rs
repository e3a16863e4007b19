//! Closed-form weighted least-squares rigid fit (2-D Procrustes without scale).

use grid_core::{DVec2, Rigid2};

/// Smallest total squared spread of B's points (pixels²) for which the rotation is defined.
const MIN_SPREAD_SQ: f64 = 1e-12;

/// The rigid transform `T` minimising `sum w_i |a_i - T(b_i)|²` over `(a, b, w)` triples.
///
/// Closed form: both centroids, then `theta = atan2(sum w (b' x a'), sum w (b' . a'))` on the
/// centred points, and `t = c_a - R c_b`. Returns `None` when the total weight is not positive
/// or when B's points all coincide (the rotation is then undefined).
pub fn fit_rigid_weighted<I>(pairs: I) -> Option<Rigid2>
where
    I: IntoIterator<Item = (DVec2, DVec2, f64)> + Clone,
{
    let (mut sw, mut sa, mut sb) = (0.0, DVec2::ZERO, DVec2::ZERO);
    for (a, b, w) in pairs.clone() {
        sw += w;
        sa += w * a;
        sb += w * b;
    }
    if !sw.is_finite() || sw <= 0.0 {
        return None;
    }
    let (ca, cb) = (sa / sw, sb / sw);
    // Second pass on centred points: summing raw products and subtracting the centroid terms
    // loses precision at map coordinates in the thousands.
    let (mut dot, mut cross, mut spread) = (0.0, 0.0, 0.0);
    for (a, b, w) in pairs {
        let (da, db) = (a - ca, b - cb);
        dot += w * db.dot(da);
        cross += w * db.perp_dot(da);
        spread += w * db.length_squared();
    }
    if spread / sw < MIN_SPREAD_SQ || (dot == 0.0 && cross == 0.0) {
        return None;
    }
    let theta = cross.atan2(dot);
    let t = ca - DVec2::from_angle(theta).rotate(cb);
    Some(Rigid2::new(theta, t.x, t.y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn exact_on_noise_free_points() {
        let truth = Rigid2::new(2.3, -417.25, 1033.5);
        let bs: Vec<DVec2> = (0..7)
            .map(|i| DVec2::new(100.0 + 37.0 * i as f64, 2000.0 - 13.0 * (i * i) as f64))
            .collect();
        let fit = fit_rigid_weighted(bs.iter().map(|&b| (truth.apply(b), b, 1.0))).unwrap();
        assert!((fit.theta - truth.theta).abs() < 1e-12, "{fit:?}");
        assert!((fit.tx - truth.tx).abs() < 1e-9, "{fit:?}");
        assert!((fit.ty - truth.ty).abs() < 1e-9, "{fit:?}");
    }

    #[test]
    fn two_points_give_the_angle_between_difference_vectors_and_the_midpoint() {
        let (b1, b2) = (DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0));
        let (a1, a2) = (DVec2::new(5.0, 5.0), DVec2::new(5.0, 15.0));
        let fit = fit_rigid_weighted([(a1, b1, 1.0), (a2, b2, 1.0)]).unwrap();
        assert!((fit.theta - PI / 2.0).abs() < 1e-12);
        assert!((fit.apply((b1 + b2) / 2.0) - (a1 + a2) / 2.0).length() < 1e-12);
    }

    #[test]
    fn weights_pull_towards_heavy_pairs() {
        // Three exact pairs plus one pair 4 px off: a tiny weight on the bad pair leaves the
        // fit within a small fraction of a pixel of the truth, equal weights do not.
        let truth = Rigid2::new(0.4, 10.0, -3.0);
        let bs = [
            DVec2::new(0.0, 0.0),
            DVec2::new(50.0, 0.0),
            DVec2::new(0.0, 50.0),
            DVec2::new(50.0, 50.0),
        ];
        let pairs = |w_bad: f64| {
            bs.iter()
                .enumerate()
                .map(move |(i, &b)| {
                    let off = if i == 3 {
                        DVec2::new(4.0, 0.0)
                    } else {
                        DVec2::ZERO
                    };
                    (truth.apply(b) + off, b, if i == 3 { w_bad } else { 1.0 })
                })
                .collect::<Vec<_>>()
        };
        let err = |fit: Rigid2| {
            bs.iter()
                .map(|&b| (fit.apply(b) - truth.apply(b)).length())
                .fold(0.0, f64::max)
        };
        let light = err(fit_rigid_weighted(pairs(1e-6)).unwrap());
        let equal = err(fit_rigid_weighted(pairs(1.0)).unwrap());
        assert!(light < 1e-4, "{light}");
        assert!(equal > 0.5, "{equal}");
    }

    #[test]
    fn degenerate_inputs_give_none() {
        let p = DVec2::new(3.0, 4.0);
        assert_eq!(fit_rigid_weighted(Vec::<(DVec2, DVec2, f64)>::new()), None);
        assert_eq!(fit_rigid_weighted([(p, p, 1.0), (p, p, 1.0)]), None);
        assert_eq!(fit_rigid_weighted([(p, p, 0.0), (p + p, p + p, 0.0)]), None);
    }
}
