//! One pose per map from pairwise registrations: a spanning tree of the most confident
//! answers, then a joint least-squares refinement over the loops the other answers close.

use faer::Mat;
use faer::prelude::SolveLstsq;
use grid_core::{DVec2, Rigid2, wrap_angle};

use crate::{FusionError, Result};

/// One accepted pairwise registration: `b_to_a` maps a pixel of map `b` onto map `a`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairEdge {
    /// The map the answer is expressed in.
    pub a: usize,
    /// The map placed into `a`.
    pub b: usize,
    /// The registration's answer, B's pixels onto A's.
    pub b_to_a: Rigid2,
    /// Confidence of the answer (greater than 0); the tree prefers the most confident edges and
    /// the refinement weighs each edge's equations by it.
    pub weight: f64,
}

/// Settings of [`solve_poses`].
#[derive(Debug, Clone, PartialEq)]
pub struct PoseGraphConfig {
    /// Refine the tree's poses by least squares over every consistent edge; default `true`.
    /// Without loops the refinement gives the tree's poses back.
    pub refine: bool,
    /// A loop edge that disagrees with the tree's poses by more than this angle (degrees) is
    /// dropped as a wrong registration; default 3.
    pub max_rotation_deg: f64,
    /// ... or by more than this distance (pixels, at the centre of map `b`); default 8: three
    /// answers each within the 3 px of a success can close a loop that far apart.
    pub max_translation_px: f64,
}

impl Default for PoseGraphConfig {
    fn default() -> Self {
        Self {
            refine: true,
            max_rotation_deg: 3.0,
            max_translation_px: 8.0,
        }
    }
}

/// What became of an edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeStatus {
    /// In the spanning tree from the reference.
    Tree,
    /// Closes a loop, agrees with the tree, and takes part in the refinement.
    Loop,
    /// Closes a loop but disagrees with the tree beyond the bounds: left out.
    Dropped,
    /// Joins maps that no edge links to the reference.
    Unreached,
}

/// How far the solved poses are from an edge's answer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EdgeResidual {
    /// Angle between the edge's answer and the poses' relative angle, degrees.
    pub rotation_deg: f64,
    /// Distance, in reference pixels, between where the edge and the poses put map `b`'s
    /// centre.
    pub translation_px: f64,
}

/// The result of [`solve_poses`].
#[derive(Debug, Clone, PartialEq)]
pub struct PoseGraphSolution {
    /// Per map, its pixels onto the reference's; `None` for a map no edge links to the
    /// reference.
    pub poses: Vec<Option<Rigid2>>,
    /// Per edge (in the order given), what became of it.
    pub status: Vec<EdgeStatus>,
    /// Per edge, its residual under the final poses (before the refinement for a dropped
    /// edge, measured against the tree; zero for an unreached one).
    pub residuals: Vec<EdgeResidual>,
}

/// Solve one pose per map (`centres.len()` maps; `centres[k]` is a pixel at the middle of map
/// `k`'s known cells, where translation residuals are measured) from pairwise `edges`, in the
/// frame of map `reference`.
///
/// 1. A maximum-weight spanning tree from the reference (Prim) gives first poses by composing
///    the edges' answers.
/// 2. Every other edge between reached maps closes a loop; those within
///    [`PoseGraphConfig::max_rotation_deg`] and [`PoseGraphConfig::max_translation_px`] of the
///    tree's poses are kept, the rest dropped.
/// 3. With [`PoseGraphConfig::refine`], the angles and then the translations are solved by
///    weighted linear least squares (QR with column pivoting, `faer`) over the tree and the
///    kept edges, the reference held at the identity. The angles come first: with them fixed,
///    each edge's translation equation `t_b - t_a = R_a T_ab(c_b) - R_b c_b` is linear.
pub fn solve_poses(
    centres: &[DVec2],
    reference: usize,
    edges: &[PairEdge],
    config: &PoseGraphConfig,
) -> Result<PoseGraphSolution> {
    for (name, value) in [
        ("max_rotation_deg", config.max_rotation_deg),
        ("max_translation_px", config.max_translation_px),
    ] {
        if value.is_nan() || value < 0.0 {
            return Err(FusionError::Setting { name, value });
        }
    }
    let n = centres.len();
    if reference >= n {
        return Err(FusionError::Reference {
            reference,
            nodes: n,
        });
    }
    for (index, e) in edges.iter().enumerate() {
        if e.a >= n || e.b >= n || e.a == e.b {
            return Err(FusionError::BadEdge {
                index,
                a: e.a,
                b: e.b,
                nodes: n,
            });
        }
        let t = e.b_to_a;
        if ![t.theta, t.tx, t.ty].iter().all(|v| v.is_finite()) {
            return Err(FusionError::NotFinite {
                what: format!("pair edge {index}'s transform"),
            });
        }
        if !(e.weight.is_finite() && e.weight > 0.0) {
            return Err(FusionError::EdgeWeight {
                index,
                weight: e.weight,
            });
        }
    }
    let (mut poses, mut status) = spanning_tree(n, reference, edges);
    let mut residuals = vec![EdgeResidual::default(); edges.len()];
    for (i, e) in edges.iter().enumerate() {
        if status[i] == EdgeStatus::Loop {
            let r = residual(&poses, centres, e);
            residuals[i] = r;
            if r.rotation_deg > config.max_rotation_deg
                || r.translation_px > config.max_translation_px
            {
                status[i] = EdgeStatus::Dropped;
            }
        }
    }
    if config.refine {
        let used: Vec<&PairEdge> = edges
            .iter()
            .zip(&status)
            .filter(|(_, s)| matches!(s, EdgeStatus::Tree | EdgeStatus::Loop))
            .map(|(e, _)| e)
            .collect();
        poses = refine(&poses, centres, reference, &used)?;
    }
    for (i, e) in edges.iter().enumerate() {
        if matches!(status[i], EdgeStatus::Tree | EdgeStatus::Loop) {
            residuals[i] = residual(&poses, centres, e);
        }
    }
    Ok(PoseGraphSolution {
        poses,
        status,
        residuals,
    })
}

/// Prim's maximum-weight spanning tree from `reference`: poses by composing the tree's
/// answers, and each edge marked [`EdgeStatus::Tree`], [`EdgeStatus::Loop`] (both ends
/// reached, not in the tree) or [`EdgeStatus::Unreached`]. Ties go to the earlier edge, so the
/// result does not depend on anything but the input order.
fn spanning_tree(
    n: usize,
    reference: usize,
    edges: &[PairEdge],
) -> (Vec<Option<Rigid2>>, Vec<EdgeStatus>) {
    let mut poses: Vec<Option<Rigid2>> = vec![None; n];
    poses[reference] = Some(Rigid2::IDENTITY);
    let mut status = vec![EdgeStatus::Unreached; edges.len()];
    loop {
        // The heaviest edge with exactly one end reached.
        let mut best: Option<(usize, f64)> = None;
        for (i, e) in edges.iter().enumerate() {
            if poses[e.a].is_some() != poses[e.b].is_some()
                && best.is_none_or(|(_, w)| e.weight > w)
            {
                best = Some((i, e.weight));
            }
        }
        let Some((i, _)) = best else { break };
        let e = &edges[i];
        match (poses[e.a], poses[e.b]) {
            (Some(pa), None) => poses[e.b] = Some(pa.compose(&e.b_to_a).normalized()),
            (None, Some(pb)) => poses[e.a] = Some(pb.compose(&e.b_to_a.inverse()).normalized()),
            _ => unreachable!("one end reached"),
        }
        status[i] = EdgeStatus::Tree;
    }
    for (i, e) in edges.iter().enumerate() {
        if status[i] != EdgeStatus::Tree && poses[e.a].is_some() && poses[e.b].is_some() {
            status[i] = EdgeStatus::Loop;
        }
    }
    (poses, status)
}

/// How far `poses` are from edge `e`'s answer.
fn residual(poses: &[Option<Rigid2>], centres: &[DVec2], e: &PairEdge) -> EdgeResidual {
    let (Some(pa), Some(pb)) = (poses[e.a], poses[e.b]) else {
        return EdgeResidual::default();
    };
    let c = centres[e.b];
    EdgeResidual {
        rotation_deg: wrap_angle(pa.theta + e.b_to_a.theta - pb.theta)
            .abs()
            .to_degrees(),
        translation_px: (pa.apply(e.b_to_a.apply(c)) - pb.apply(c)).length(),
    }
}

/// Weighted least squares over `edges`, starting from the tree's `poses`; maps without a pose
/// keep none, the reference keeps the identity.
fn refine(
    poses: &[Option<Rigid2>],
    centres: &[DVec2],
    reference: usize,
    edges: &[&PairEdge],
) -> Result<Vec<Option<Rigid2>>> {
    // Unknowns: the reached maps other than the reference, in index order.
    let mut column = vec![usize::MAX; poses.len()];
    let mut unknowns = 0;
    for (k, p) in poses.iter().enumerate() {
        if p.is_some() && k != reference {
            column[k] = unknowns;
            unknowns += 1;
        }
    }
    if unknowns == 0 || edges.is_empty() {
        return Ok(poses.to_vec());
    }
    let pose = |k: usize| poses[k].expect("edges join reached maps");
    // Angles: theta_b - theta_a = the tree's difference plus the edge's wrapped disagreement
    // with it, so that no equation asks for a jump of a full turn.
    let m = edges.len();
    let mut a = Mat::<f64>::zeros(m, unknowns);
    let mut rhs = Mat::<f64>::zeros(m, 1);
    for (row, e) in edges.iter().enumerate() {
        let s = e.weight.sqrt();
        let tree = pose(e.b).theta - pose(e.a).theta;
        let target = tree + wrap_angle(e.b_to_a.theta - tree);
        if column[e.b] != usize::MAX {
            a[(row, column[e.b])] += s;
        }
        if column[e.a] != usize::MAX {
            a[(row, column[e.a])] -= s;
        }
        // The reference's angle is known: it moves to the right-hand side.
        let mut known = target;
        if column[e.a] == usize::MAX {
            known += pose(e.a).theta;
        }
        if column[e.b] == usize::MAX {
            known -= pose(e.b).theta;
        }
        rhs[(row, 0)] = s * known;
    }
    let theta = a.col_piv_qr().solve_lstsq(&rhs);
    let angle = |k: usize| {
        if k == reference {
            pose(reference).theta
        } else {
            theta[(column[k], 0)]
        }
    };
    // Translations: t_b - t_a = R_a T_ab(c_b) - R_b c_b, two rows per edge.
    let mut a = Mat::<f64>::zeros(2 * m, 2 * unknowns);
    let mut rhs = Mat::<f64>::zeros(2 * m, 1);
    let reference_t = pose(reference).translation();
    for (row, e) in edges.iter().enumerate() {
        let s = e.weight.sqrt();
        let c = centres[e.b];
        let ra = Rigid2::new(angle(e.a), 0.0, 0.0);
        let rb = Rigid2::new(angle(e.b), 0.0, 0.0);
        let mut target = ra.apply(e.b_to_a.apply(c)) - rb.apply(c);
        if column[e.a] == usize::MAX {
            target += reference_t;
        }
        if column[e.b] == usize::MAX {
            target -= reference_t;
        }
        for d in 0..2 {
            let r = 2 * row + d;
            if column[e.b] != usize::MAX {
                a[(r, 2 * column[e.b] + d)] += s;
            }
            if column[e.a] != usize::MAX {
                a[(r, 2 * column[e.a] + d)] -= s;
            }
            rhs[(r, 0)] = s * if d == 0 { target.x } else { target.y };
        }
    }
    let t = a.col_piv_qr().solve_lstsq(&rhs);
    let mut out = poses.to_vec();
    for (k, p) in out.iter_mut().enumerate() {
        if p.is_some() && k != reference {
            let (th, tx, ty) = (angle(k), t[(2 * column[k], 0)], t[(2 * column[k] + 1, 0)]);
            if ![th, tx, ty].iter().all(|v| v.is_finite()) {
                return Err(FusionError::Solve);
            }
            *p = Some(Rigid2::new(th, tx, ty).normalized());
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The answer a perfect registration of `b` onto `a` gives, with the truth's poses.
    fn edge(truth: &[Rigid2], a: usize, b: usize, weight: f64) -> PairEdge {
        PairEdge {
            a,
            b,
            b_to_a: truth[a].inverse().compose(&truth[b]),
            weight,
        }
    }

    fn centres(n: usize) -> Vec<DVec2> {
        vec![DVec2::new(100.0, 80.0); n]
    }

    fn truth() -> Vec<Rigid2> {
        vec![
            Rigid2::IDENTITY,
            Rigid2::new(0.7, 120.0, -35.0),
            Rigid2::new(-2.9, 260.0, 40.0),
            Rigid2::new(1.6, -80.0, 150.0),
        ]
    }

    /// Largest distance between where `poses` and `truth` put the centre of a map.
    fn worst(poses: &[Option<Rigid2>], truth: &[Rigid2], c: DVec2) -> f64 {
        poses
            .iter()
            .zip(truth)
            .map(|(p, t)| (p.unwrap().apply(c) - t.apply(c)).length())
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_chain_composes_its_answers() {
        let t = truth();
        let edges = [
            edge(&t, 0, 1, 0.9),
            edge(&t, 2, 1, 0.8),
            edge(&t, 2, 3, 0.7),
        ];
        let s = solve_poses(&centres(4), 0, &edges, &PoseGraphConfig::default()).unwrap();
        assert_eq!(s.status, vec![EdgeStatus::Tree; 3]);
        assert!(worst(&s.poses, &t, DVec2::new(100.0, 80.0)) < 1e-9);
        for (p, q) in s.poses.iter().zip(&t) {
            assert!(wrap_angle(p.unwrap().theta - q.theta).abs() < 1e-12);
        }
    }

    #[test]
    fn a_wrong_answer_that_breaks_a_loop_is_dropped() {
        let t = truth();
        let mut wrong = edge(&t, 1, 3, 0.5);
        wrong.b_to_a = Rigid2::new(0.0, 30.0, 0.0).compose(&wrong.b_to_a);
        let edges = [
            edge(&t, 0, 1, 0.9),
            edge(&t, 1, 2, 0.8),
            edge(&t, 2, 3, 0.85),
            edge(&t, 0, 2, 0.6),
            wrong,
        ];
        let s = solve_poses(&centres(4), 0, &edges, &PoseGraphConfig::default()).unwrap();
        use EdgeStatus::*;
        assert_eq!(s.status, vec![Tree, Tree, Tree, Loop, Dropped]);
        assert!(s.residuals[4].translation_px > 29.0, "{:?}", s.residuals[4]);
        assert!(worst(&s.poses, &t, DVec2::new(100.0, 80.0)) < 1e-6);
    }

    #[test]
    fn a_bound_that_is_nan_or_negative_is_refused() {
        let t = truth();
        let edges = [edge(&t, 0, 1, 0.9)];
        for (config, name) in [
            (
                PoseGraphConfig {
                    max_rotation_deg: f64::NAN,
                    ..PoseGraphConfig::default()
                },
                "max_rotation_deg",
            ),
            (
                PoseGraphConfig {
                    max_translation_px: -1.0,
                    ..PoseGraphConfig::default()
                },
                "max_translation_px",
            ),
        ] {
            let err = solve_poses(&centres(2), 0, &edges, &config).unwrap_err();
            assert!(
                matches!(err, FusionError::Setting { name: n, .. } if n == name),
                "{err}"
            );
        }
        // An infinite bound drops no loop.
        let config = PoseGraphConfig {
            max_rotation_deg: f64::INFINITY,
            max_translation_px: f64::INFINITY,
            ..PoseGraphConfig::default()
        };
        solve_poses(&centres(2), 0, &edges, &config).unwrap();
    }

    #[test]
    fn the_refinement_spreads_a_loop_s_error_over_its_edges() {
        // Every answer 1 px and 0.2 degrees off, in the same sense: around the ring the errors
        // add up, and the tree puts the whole closure error on the loop edge.
        let t = truth();
        let nudge = Rigid2::new(0.2f64.to_radians(), 1.0, 0.0);
        let mut edges = vec![
            edge(&t, 0, 1, 0.9),
            edge(&t, 1, 2, 0.9),
            edge(&t, 2, 3, 0.9),
            edge(&t, 3, 0, 0.5),
        ];
        for e in &mut edges {
            e.b_to_a = e.b_to_a.compose(&nudge);
        }
        let c = centres(4);
        let tree_only = PoseGraphConfig {
            refine: false,
            ..PoseGraphConfig::default()
        };
        let before = solve_poses(&c, 0, &edges, &tree_only).unwrap();
        let after = solve_poses(&c, 0, &edges, &PoseGraphConfig::default()).unwrap();
        assert_eq!(after.status[3], EdgeStatus::Loop);
        let max = |s: &PoseGraphSolution| {
            s.residuals
                .iter()
                .map(|r| r.translation_px)
                .fold(0.0, f64::max)
        };
        assert!(max(&before) > 1.5, "{:?}", before.residuals);
        assert!(max(&after) < 0.6 * max(&before), "{:?}", after.residuals);
        let rot = |s: &PoseGraphSolution| {
            s.residuals
                .iter()
                .map(|r| r.rotation_deg)
                .fold(0.0, f64::max)
        };
        assert!((rot(&before) - 0.8).abs() < 1e-9, "{}", rot(&before));
        assert!(rot(&after) < 0.5, "{}", rot(&after));
    }

    #[test]
    fn a_map_no_answer_reaches_has_no_pose() {
        let t = truth();
        let edges = [edge(&t, 0, 1, 0.9), edge(&t, 2, 3, 0.9)];
        let s = solve_poses(&centres(4), 0, &edges, &PoseGraphConfig::default()).unwrap();
        assert!(s.poses[2].is_none() && s.poses[3].is_none());
        assert_eq!(s.status, vec![EdgeStatus::Tree, EdgeStatus::Unreached]);
        // Another reference: poses in its frame.
        let s = solve_poses(&centres(4), 3, &edges, &PoseGraphConfig::default()).unwrap();
        let p2 = s.poses[2].unwrap();
        let want = t[3].inverse().compose(&t[2]);
        assert!((p2.translation() - want.translation()).length() < 1e-9);
        assert!(s.poses[0].is_none());
    }

    #[test]
    fn bad_edges_are_refused() {
        let t = truth();
        let c = centres(2);
        let config = PoseGraphConfig::default();
        let mut e = edge(&t, 0, 1, 0.9);
        e.b = 5;
        assert!(matches!(
            solve_poses(&c, 0, &[e], &config),
            Err(FusionError::BadEdge { .. })
        ));
        let mut e = edge(&t, 0, 1, 0.9);
        e.b_to_a.tx = f64::NAN;
        assert!(matches!(
            solve_poses(&c, 0, &[e], &config),
            Err(FusionError::NotFinite { .. })
        ));
        let e = edge(&t, 0, 1, 0.0);
        assert!(matches!(
            solve_poses(&c, 0, &[e], &config),
            Err(FusionError::EdgeWeight { index: 0, .. })
        ));
        assert!(matches!(
            solve_poses(&c, 2, &[], &config),
            Err(FusionError::Reference {
                reference: 2,
                nodes: 2
            })
        ));
    }

    proptest! {
        // A fixed seed, so that CI runs the same cases every time.
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(7),
            ..ProptestConfig::default()
        })]

        /// Answers between every pair of up to six maps that overlap (centres within about
        /// 200 px of each other), each up to 1 px and 0.3 degrees off about the placed map's
        /// centre: every map's centre lands within 2 px of where the truth puts it, and no
        /// answer is dropped.
        #[test]
        fn noisy_answers_between_every_pair_give_poses_near_the_truth(
            n in 2usize..7,
            seed_poses in proptest::collection::vec((-3.1f64..3.1, -100.0f64..100.0, -100.0f64..100.0), 6),
            noise in proptest::collection::vec((-0.3f64..0.3, -0.7f64..0.7, -0.7f64..0.7), 15),
        ) {
            // Each map turned about its centre, the centre moved by up to 100 px each way.
            let c = DVec2::new(100.0, 80.0);
            let mut t: Vec<Rigid2> = seed_poses[..n]
                .iter()
                .map(|&(a, x, y)| Rigid2::new(0.0, x, y).compose(&Rigid2::rotation_about(a, c)))
                .collect();
            t[0] = Rigid2::IDENTITY;
            let mut edges = Vec::new();
            for a in 0..n {
                for b in a + 1..n {
                    let (da, dx, dy) = noise[edges.len()];
                    let mut e = edge(&t, a, b, 0.5 + 0.1 * (a + b) as f64);
                    // The error is about map b's centre, as a registration's would be.
                    let c = DVec2::new(100.0, 80.0);
                    let nudge = Rigid2::rotation_about(da.to_radians(), c).compose(&Rigid2::new(0.0, dx, dy));
                    e.b_to_a = e.b_to_a.compose(&nudge);
                    edges.push(e);
                }
            }
            let s = solve_poses(&centres(n), 0, &edges, &PoseGraphConfig::default()).unwrap();
            prop_assert!(s.status.iter().all(|s| matches!(s, EdgeStatus::Tree | EdgeStatus::Loop)));
            let w = worst(&s.poses, &t, DVec2::new(100.0, 80.0));
            prop_assert!(w < 2.0, "{} px", w);
        }
    }
}
