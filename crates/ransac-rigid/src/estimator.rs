//! The estimator axis: models from minimal samples, residuals, refinement, and the rigid
//! estimator that mixes 2-point and oriented 1-point hypotheses.

use std::f64::consts::PI;

use grid_core::{Correspondence, DVec2, EvidenceKind, Orientation, Rigid2, wrap_angle};

use crate::procrustes::fit_rigid_weighted;

/// Builds models from samples of data and measures how well a datum fits a model.
///
/// A sample may yield zero models (degenerate, pruned) or several (an axis orientation fixes
/// the angle only modulo `pi`), so the driver needs no special case for hybrid samples.
pub trait Estimator {
    /// One observation (here a [`Correspondence`]).
    type Datum;
    /// The fitted model (here a [`Rigid2`]).
    type Model: Clone;

    /// Cheap check run before [`Self::estimate`]; a rejected sample does not count as an
    /// iteration. The default accepts every sample.
    fn is_sample_valid(&self, data: &[Self::Datum], sample: &[usize]) -> bool {
        let _ = (data, sample);
        true
    }

    /// Append the models fixed by `sample` (indices into `data`) to `out`.
    fn estimate(&self, data: &[Self::Datum], sample: &[usize], out: &mut Vec<Self::Model>);

    /// Replace `out` by the squared residual of every datum under `model`.
    fn residuals_sq(&self, model: &Self::Model, data: &[Self::Datum], out: &mut Vec<f64>);

    /// Weight of a datum in the consensus score and in refinement. The default is 1.
    fn weight(&self, datum: &Self::Datum) -> f64 {
        let _ = datum;
        1.0
    }

    /// Least-squares model over the given inliers, `None` when they do not fix one.
    fn refine(&self, data: &[Self::Datum], inliers: &[usize]) -> Option<Self::Model>;

    /// Whether two models are the same hypothesis for the top-k list.
    fn is_same(&self, a: &Self::Model, b: &Self::Model) -> bool;
}

/// Settings of [`RigidEstimator`]; see [`crate::RansacConfig`] for the meaning and defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidEstimatorConfig {
    /// Inlier threshold in pixels; also the tolerance of the distance-preservation pre-check.
    pub threshold_px: f64,
    /// Minimum distance between the two points of a 2-point sample, in both maps.
    pub min_pair_distance_px: f64,
    /// Reject a 2-point hypothesis whose angle disagrees by more than this (radians) with the
    /// orientation difference of every oriented member of the sample. `None` disables it.
    pub orientation_prune_rad: Option<f64>,
    /// Whether oriented [`EvidenceKind::Area`] correspondences give 1-point hypotheses.
    pub single_point: bool,
    /// Hypotheses closer than this in angle (radians) ...
    pub distinct_angle_rad: f64,
    /// ... and moving the centre of B's points less than this apart (pixels) are the same.
    pub distinct_shift_px: f64,
}

/// Rigid B→A estimator over [`Correspondence`]s: 2-point samples fitted in closed form and
/// 1-point samples from an oriented area correspondence.
#[derive(Debug, Clone)]
pub struct RigidEstimator {
    config: RigidEstimatorConfig,
    /// Centre of B's points: where translation differences between hypotheses are measured,
    /// so that "distinct" does not depend on where B's pixel origin lies.
    centre_b: DVec2,
}

/// Whether an orientation can fix a rotation (finite angles, positive finite period).
pub fn orientation_usable(o: &Orientation) -> bool {
    o.a.is_finite() && o.b.is_finite() && o.period.is_finite() && o.period > 0.0
}

/// Whether a correspondence can seed a 1-point hypothesis: kind Area with a usable orientation.
pub fn is_single_point_seed(c: &Correspondence) -> bool {
    c.kind == EvidenceKind::Area && c.orientation.as_ref().is_some_and(orientation_usable)
}

/// Distance of `angle` to the nearest multiple of `period`.
fn angle_distance_mod(angle: f64, period: f64) -> f64 {
    let r = angle.rem_euclid(period);
    r.min(period - r)
}

impl RigidEstimator {
    /// An estimator for `data` (the centre of B's points is taken from it).
    pub fn new(config: RigidEstimatorConfig, data: &[Correspondence]) -> Self {
        let centre_b = if data.is_empty() {
            DVec2::ZERO
        } else {
            data.iter().map(|c| c.b).sum::<DVec2>() / data.len() as f64
        };
        Self { config, centre_b }
    }

    /// The settings.
    pub fn config(&self) -> &RigidEstimatorConfig {
        &self.config
    }

    fn pruned_by_orientation(&self, theta: f64, members: [&Correspondence; 2]) -> bool {
        let Some(tol) = self.config.orientation_prune_rad else {
            return false;
        };
        let mut oriented = 0;
        for c in members {
            if let Some(o) = c.orientation.as_ref().filter(|o| orientation_usable(o)) {
                oriented += 1;
                if angle_distance_mod(theta - (o.a - o.b), o.period) <= tol {
                    return false;
                }
            }
        }
        oriented > 0
    }
}

impl Estimator for RigidEstimator {
    type Datum = Correspondence;
    type Model = Rigid2;

    fn is_sample_valid(&self, data: &[Correspondence], sample: &[usize]) -> bool {
        match *sample {
            [i] => self.config.single_point && is_single_point_seed(&data[i]),
            [i, j] => {
                let (p, q) = (&data[i], &data[j]);
                let (da2, db2) = (p.a.distance_squared(q.a), p.b.distance_squared(q.b));
                // Rigid transforms preserve distances: a pair whose lengths disagree by more
                // than the inlier threshold cannot be two inliers. Most random pairs fail the
                // necessary condition |da² - db²| = |da - db| (da + db) <= 2 t max(da, db)
                // already, without the square roots this draw-bound loop would wait on.
                let t = self.config.threshold_px;
                let diff = da2 - db2;
                if diff * diff > 4.0 * t * t * da2.max(db2) {
                    return false;
                }
                let (da, db) = (da2.sqrt(), db2.sqrt());
                if da < self.config.min_pair_distance_px
                    || db < self.config.min_pair_distance_px
                    || (da - db).abs() > self.config.threshold_px
                {
                    return false;
                }
                // Orientation pruning here rather than in `estimate`, so that a pruned sample
                // does not use up one of the iterations.
                if self.config.orientation_prune_rad.is_some() {
                    let (va, vb) = (q.a - p.a, q.b - p.b);
                    let theta = va.y.atan2(va.x) - vb.y.atan2(vb.x);
                    return !self.pruned_by_orientation(theta, [p, q]);
                }
                true
            }
            _ => false,
        }
    }

    fn estimate(&self, data: &[Correspondence], sample: &[usize], out: &mut Vec<Rigid2>) {
        match *sample {
            [i] => {
                let c = &data[i];
                let Some(o) = c.orientation.filter(orientation_usable) else {
                    return;
                };
                // An axis (period pi) leaves theta and theta + pi; a directed angle one answer.
                let turns = ((2.0 * PI / o.period).round() as usize).clamp(1, 8);
                for k in 0..turns {
                    let theta = wrap_angle(o.a - o.b + k as f64 * o.period);
                    let t = c.a - DVec2::from_angle(theta).rotate(c.b);
                    out.push(Rigid2::new(theta, t.x, t.y));
                }
            }
            [i, j] => {
                let (p, q) = (&data[i], &data[j]);
                if let Some(m) = fit_rigid_weighted([(p.a, p.b, 1.0), (q.a, q.b, 1.0)])
                    && !self.pruned_by_orientation(m.theta, [p, q])
                {
                    out.push(m);
                }
            }
            _ => {}
        }
    }

    fn residuals_sq(&self, model: &Rigid2, data: &[Correspondence], out: &mut Vec<f64>) {
        let (s, c) = model.theta.sin_cos();
        out.clear();
        out.extend(data.iter().map(|d| {
            let x = c * d.b.x - s * d.b.y + model.tx - d.a.x;
            let y = s * d.b.x + c * d.b.y + model.ty - d.a.y;
            x * x + y * y
        }));
    }

    fn weight(&self, datum: &Correspondence) -> f64 {
        datum.weight
    }

    fn refine(&self, data: &[Correspondence], inliers: &[usize]) -> Option<Rigid2> {
        fit_rigid_weighted(
            inliers
                .iter()
                .map(|&i| (data[i].a, data[i].b, data[i].weight)),
        )
    }

    fn is_same(&self, a: &Rigid2, b: &Rigid2) -> bool {
        wrap_angle(a.theta - b.theta).abs() <= self.config.distinct_angle_rad
            && a.apply(self.centre_b).distance(b.apply(self.centre_b))
                <= self.config.distinct_shift_px
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> RigidEstimatorConfig {
        RigidEstimatorConfig {
            threshold_px: 3.0,
            min_pair_distance_px: 5.0,
            orientation_prune_rad: None,
            single_point: true,
            distinct_angle_rad: 2f64.to_radians(),
            distinct_shift_px: 5.0,
        }
    }

    fn corr(a: DVec2, b: DVec2, o: Option<Orientation>, kind: EvidenceKind) -> Correspondence {
        Correspondence {
            a,
            b,
            orientation: o,
            weight: 1.0,
            kind,
        }
    }

    #[test]
    fn axis_orientation_gives_both_candidates() {
        let truth = Rigid2::new(2.5, 40.0, -7.0);
        let b = DVec2::new(30.0, 80.0);
        let o = Orientation {
            // Axis angles are only known modulo pi: B's axis at 0.3, A's reported as the
            // opposite direction of the true rotated axis.
            a: wrap_angle(0.3 + 2.5 - PI),
            b: 0.3,
            period: PI,
        };
        let data = [corr(truth.apply(b), b, Some(o), EvidenceKind::Area)];
        let est = RigidEstimator::new(cfg(), &data);
        assert!(est.is_sample_valid(&data, &[0]));
        let mut out = Vec::new();
        est.estimate(&data, &[0], &mut out);
        assert_eq!(out.len(), 2);
        let hit = out
            .iter()
            .filter(|m| wrap_angle(m.theta - truth.theta).abs() < 1e-12)
            .count();
        assert_eq!(hit, 1, "{out:?}");
        for m in &out {
            // Both candidates map the seed point exactly.
            assert!((m.apply(b) - truth.apply(b)).length() < 1e-9);
        }
    }

    #[test]
    fn intensity_or_unoriented_correspondences_do_not_seed_alone() {
        let o = Orientation {
            a: 0.1,
            b: 0.2,
            period: 2.0 * PI,
        };
        let p = DVec2::new(1.0, 2.0);
        let data = [
            corr(p, p, Some(o), EvidenceKind::Intensity),
            corr(p, p, None, EvidenceKind::Area),
            corr(
                p,
                p,
                Some(Orientation {
                    period: f64::NAN,
                    ..o
                }),
                EvidenceKind::Area,
            ),
        ];
        let est = RigidEstimator::new(cfg(), &data);
        for i in 0..3 {
            assert!(!est.is_sample_valid(&data, &[i]), "{i}");
        }
    }

    #[test]
    fn pair_precheck_rejects_close_and_length_changing_pairs() {
        let z = DVec2::ZERO;
        let data = [
            corr(z, z, None, EvidenceKind::Intensity),
            corr(
                DVec2::new(20.0, 0.0),
                DVec2::new(0.0, 20.0),
                None,
                EvidenceKind::Intensity,
            ),
            corr(
                DVec2::new(2.0, 0.0),
                DVec2::new(2.0, 0.0),
                None,
                EvidenceKind::Intensity,
            ),
            corr(
                DVec2::new(30.0, 0.0),
                DVec2::new(0.0, 20.0),
                None,
                EvidenceKind::Intensity,
            ),
        ];
        let est = RigidEstimator::new(cfg(), &data);
        assert!(est.is_sample_valid(&data, &[0, 1]));
        assert!(!est.is_sample_valid(&data, &[0, 2]), "closer than 5 px");
        assert!(!est.is_sample_valid(&data, &[0, 3]), "length 30 vs 20");
    }

    #[test]
    fn orientation_pruning_needs_every_oriented_member_to_disagree() {
        let truth = Rigid2::new(1.0, 0.0, 0.0);
        let (b1, b2) = (DVec2::new(0.0, 0.0), DVec2::new(50.0, 0.0));
        let good = Orientation {
            a: 1.4,
            b: 0.4,
            period: 2.0 * PI,
        };
        let bad = Orientation { a: 0.0, ..good };
        let mut c = cfg();
        c.orientation_prune_rad = Some(20f64.to_radians());
        let run = |o1, o2| {
            let data = [
                corr(truth.apply(b1), b1, o1, EvidenceKind::Intensity),
                corr(truth.apply(b2), b2, o2, EvidenceKind::Intensity),
            ];
            let est = RigidEstimator::new(c, &data);
            let mut out = Vec::new();
            est.estimate(&data, &[0, 1], &mut out);
            // The pre-check prunes exactly what `estimate` prunes.
            assert_eq!(est.is_sample_valid(&data, &[0, 1]), out.len() == 1);
            out.len()
        };
        assert_eq!(run(None, None), 1);
        assert_eq!(run(Some(good), Some(bad)), 1);
        assert_eq!(run(Some(bad), None), 0);
        assert_eq!(run(Some(bad), Some(bad)), 0);
    }
}
