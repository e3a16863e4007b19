use super::*;
use crate::testmaps::{bare_room, room, room_with_wall_across};
use grid_core::DVec2;
use grid_core::metrics::{displacement_error, rotation_error_deg};

/// B is `a` turned by 37 degrees and shifted onto a larger canvas; returns B and the truth.
fn turned(a: &OccupancyGrid) -> (OccupancyGrid, Rigid2) {
    let a_to_b = Rigid2::new(37f64.to_radians(), 60.0, 20.0);
    (a.warp(&a_to_b, 200, 190).unwrap(), a_to_b.inverse())
}

fn pair_config(symmetry_probes: bool) -> RegisterConfig {
    RegisterConfig {
        pair: PairConfig {
            symmetry_probes,
            ..PairConfig::default()
        },
        ..RegisterConfig::default()
    }
}

#[test]
fn a_frame_is_the_known_cells_grown_by_the_margin_wherever_they_lie() {
    let a = room();
    let (x0, y0, w, h) = a.known_bounds(0).unwrap();
    let (frame, offset) = framed(&a, 3);
    assert_eq!((frame.width(), frame.height()), (w + 6, h + 6));
    assert_eq!(offset, DVec2::new(x0 as f64 - 3.0, y0 as f64 - 3.0));
    // The same cells, padded unevenly first: the same frame, at the offset moved with them.
    let padded = a.region(-40, -7, a.width() + 50, a.height() + 9).unwrap();
    let (again, moved) = framed(&padded, 3);
    assert_eq!(again.cells(), frame.cells());
    assert_eq!(moved, offset + DVec2::new(40.0, 7.0));
    // A transform between frames, given in the maps' pixels.
    let t = Rigid2::new(0.7, 12.0, -5.0);
    let (oa, ob) = (DVec2::new(3.0, -4.0), DVec2::new(-10.0, 25.0));
    let p = DVec2::new(17.0, 9.0);
    let got = unframed(&t, oa, ob).apply(p);
    assert!((got - (t.apply(p - ob) + oa)).length() < 1e-12, "{got}");
    // A map with no known cell stays as it is.
    let blank = OccupancyGrid::new(10, 8, 0.05, grid_core::Pose2::default()).unwrap();
    assert_eq!(framed(&blank, 3), (blank.clone(), DVec2::ZERO));
    // The configuration's frame: the margin it names, or none.
    let config = PairConfig {
        frame_margin: Some(3),
        ..PairConfig::default()
    };
    assert_eq!(config.frame(&a), Some((frame, offset)));
    let as_given = PairConfig {
        frame_margin: None,
        ..config
    };
    assert_eq!(as_given.frame(&a), None);
}

#[test]
fn turning_about_the_overlap_keeps_the_shared_walls_in_place() {
    // B holds the room's left part, moved right by 50 px; the placement puts it 60 px
    // further right on A, so only some of its walls land on A's known cells.
    let a = room();
    let b = a.warp(&Rigid2::new(0.0, 50.0, 0.0), 120, 100).unwrap();
    let vc = VerifyConfig::default();
    let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
    let placement = Rigid2::new(0.0, 10.0, 0.0);
    let t = turned_about_overlap(&pa, &pb, &placement, 0.02).unwrap();
    assert!((t.theta - 0.02).abs() < 1e-12);
    // The centre of B's walls that land on A's known cells stays where the placement put
    // it.
    let landed: Vec<DVec2> = pb
        .wall_samples
        .iter()
        .map(|p| placement.apply(*p))
        .filter(|q| {
            let (x, y) = (q.x.round(), q.y.round());
            x >= 0.0
                && y >= 0.0
                && x < 120.0
                && y < 100.0
                && a.state(x as usize, y as usize) != grid_core::CellState::Unknown
        })
        .collect();
    assert!(!landed.is_empty() && landed.len() < pb.wall_samples.len());
    let centre = landed.iter().copied().sum::<DVec2>() / landed.len() as f64;
    let centre_b = placement.inverse().apply(centre);
    assert!((t.apply(centre_b) - centre).length() < 1e-9);
    // Nothing of B on A: no pivot.
    let away = Rigid2::new(0.0, 500.0, 0.0);
    assert_eq!(turned_about_overlap(&pa, &pb, &away, 0.02), None);
}

#[test]
fn a_room_that_looks_the_same_turned_is_declined_as_ambiguous() {
    let a = bare_room();
    let (b, _) = turned(&a);
    let r = register(&a, &b, &pair_config(true)).unwrap();
    assert!(r.accepted.is_none(), "accepted {:?}", r.accepted);
    let reason = r.reason.unwrap();
    assert!(reason.starts_with("ambiguous"), "{reason}");
    // The rival is a twin that passed on its own.
    assert!(
        r.candidates
            .iter()
            .any(|c| c.accepted && c.origin == Origin::Symmetry),
        "{:?}",
        r.candidates
    );
}

/// The screens' case: A, B (the room moved by (7, -4) px) and placements of B onto A, the
/// third the truth moved 5 px (within the local search's reach), the others wrong: a half
/// turn, and far shifts.
fn screen_case() -> (OccupancyGrid, OccupancyGrid, Vec<Rigid2>) {
    let a = room();
    let truth = Rigid2::new(0.0, -7.0, 4.0);
    let b = a.warp(&truth.inverse(), 120, 100).unwrap();
    let placements = vec![
        Rigid2::new(std::f64::consts::PI, 120.0, 100.0),
        Rigid2::new(0.0, 40.0, 0.0),
        Rigid2::new(0.0, -2.0, 4.0),
        Rigid2::new(0.0, -7.0, 45.0),
    ];
    (a, b, placements)
}

#[test]
fn the_screen_keeps_the_placements_that_fit_once_searched() {
    let (a, b, placements) = screen_case();
    let vc = VerifyConfig::default();
    let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
    let near = placements[2];
    let config = PairConfig::default();
    let poses = |kept: &[Placement]| kept.iter().map(|p| p.pose).collect::<Vec<_>>();
    let one = screen(&pa, &pb, placements.clone(), 1, &config);
    assert_eq!(poses(&one), vec![near]);
    // The screen hands over where it searched the placement: what the search gives.
    let searched = local_search(&pa, &pb, &near, &config.search.unwrap());
    let verified = verify(&pa, &pb, &searched, &config.verify);
    assert_eq!(one[0].searched, Some((searched, verified)));
    let two = screen(&pa, &pb, placements.clone(), 2, &config);
    assert_eq!((two.len(), two[0].pose), (2, near));
    // No more placements than kept: all of them, in their order, unscreened.
    let all = screen(&pa, &pb, placements.clone(), 4, &config);
    assert_eq!(poses(&all), placements);
    assert!(all.iter().all(|p| p.searched.is_none()));
}

#[test]
fn the_deep_screen_keeps_only_the_placements_that_pass_once_searched() {
    // The room's half turn fits it too.
    let (a, b, placements) = screen_case();
    let vc = VerifyConfig::default();
    let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
    let config = PairConfig::default();
    let searched: Vec<Placement> = placements
        .iter()
        .map(|p| {
            let moved = local_search(&pa, &pb, p, config.search.as_ref().unwrap());
            Placement {
                pose: *p,
                searched: Some((moved, verify(&pa, &pb, &moved, &config.verify))),
            }
        })
        .collect();
    let passes = |p: &Placement| p.searched.unwrap().1.accepted(&config.verify);
    let score = |p: &Placement| p.searched.unwrap().1.score();
    // Some pass and some do not, so that the test tells.
    assert_eq!(searched.iter().filter(|p| passes(p)).count(), 3);
    // Those that pass, with where they were searched to, the best score first.
    let mut expected: Vec<Placement> = searched.iter().copied().filter(passes).collect();
    expected.sort_by(|x, y| score(y).total_cmp(&score(x)));
    assert_eq!(expected[0].pose, placements[2]);
    assert_eq!(
        deep_screen(&pa, &pb, placements.clone(), 4, &config),
        expected
    );
    assert_eq!(
        deep_screen(&pa, &pb, placements.clone(), 1, &config),
        expected[..1]
    );
    // None that passes: none kept.
    let failing = vec![placements[1]];
    assert!(deep_screen(&pa, &pb, failing, 4, &config).is_empty());
}

#[test]
fn the_screen_keeps_passing_placements_first() {
    let config = VerifyConfig::default();
    let scored = |lift: f64, support: usize, overlap: f64| Verification {
        wall_lift: lift,
        wall_support: support,
        acceptance_index: 0.95,
        overlap_fraction: overlap,
        ..Verification::default()
    };
    // A wide wrong placement (score 0.3 * 15000 * 0.95 = 4275), the truth's small overlap
    // (0.75 * 900 * 0.95 = 641), a wrong one that passes all but the overlap, and a
    // second wide one scoring less than the first.
    let wide = scored(0.3, 15_000, 0.9);
    let truth = scored(0.75, 900, 0.29);
    let sliver = scored(0.9, 2_000, 0.05);
    let wide2 = scored(0.25, 14_000, 0.9);
    assert!(wide.score() > truth.score() && !wide.accepted(&config));
    assert!(truth.accepted(&config) && !sliver.accepted(&config));
    assert_eq!(
        screen_order(&[wide2, wide, truth, sliver], &config),
        vec![2, 1, 0, 3]
    );
    // Ties keep the given order.
    assert_eq!(screen_order(&[truth, truth, wide], &config), vec![0, 1, 2]);
}

#[test]
fn a_decline_names_the_bars_missed_and_speckle_where_both_maps_have_it() {
    let v = Verification {
        wall_lift: 0.42,
        wide_wall_lift: 0.63,
        acceptance_index: 0.96,
        overlap_fraction: 0.511,
        ..Verification::default()
    };
    let config = VerifyConfig::default();
    assert_eq!(
        unverified_reason(&v, &config, (0.151, 0.09)),
        "no hypothesis passed verification (best: wall lift 0.42 where 0.65 passes, or 0.63 at 4 px where 0.80 passes; acceptance index 0.96; overlap 51.1% of the smaller map)"
    );
    let speckled = unverified_reason(&v, &config, (0.151, 0.16));
    assert!(
        speckled.ends_with("; both maps' walls are speckle (lone wall cells 15.1 % and 16.0 %), as a range sensor with strong noise leaves them: there a right placement fits about as poorly as a wrong one"),
        "{speckled}"
    );
}

#[test]
fn a_value_short_of_its_bar_never_reads_as_the_bar() {
    assert_eq!(short_of(0.42, 0.65), "0.42");
    assert_eq!(short_of(0.8774, 0.88), "0.877");
    assert_eq!(short_of(0.87996, 0.88), "0.87996");
    assert_eq!(short_of(0.881, 0.88), "0.88");
    assert_eq!(short_of(0.9, 0.88), "0.90");
    let v = Verification {
        wall_lift: 0.6496,
        wide_wall_lift: 0.7999,
        acceptance_index: 0.85,
        overlap_fraction: 0.2,
        ..Verification::default()
    };
    assert_eq!(
        unverified_reason(&v, &VerifyConfig::default(), (0.01, 0.01)),
        "no hypothesis passed verification (best: wall lift 0.6496 where 0.65 passes, or 0.7999 at 4 px where 0.80 passes; acceptance index 0.85; overlap 20.0% of the smaller map)"
    );
}

#[test]
fn the_turn_scan_tries_each_step_both_ways_nearest_first() {
    let deg = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .map(|r| (r.to_degrees() * 1e9).round() / 1e9)
            .collect()
    };
    let scan = TurnScan::default();
    assert_eq!(
        deg(&scan.turns()),
        vec![0.25, -0.25, 0.5, -0.5, 0.75, -0.75, 1.0, -1.0]
    );
    // A largest turn between steps stops at the last whole step.
    let scan = TurnScan {
        max_deg: 0.7,
        step_deg: 0.3,
        ..TurnScan::default()
    };
    assert_eq!(deg(&scan.turns()), vec![0.3, -0.3, 0.6, -0.6]);
    // No step, or a largest turn below one step: nothing to try.
    for (max_deg, step_deg) in [(1.0, 0.0), (0.2, 0.25), (1.0, f64::NAN)] {
        let scan = TurnScan {
            max_deg,
            step_deg,
            ..TurnScan::default()
        };
        assert!(scan.turns().is_empty());
    }
}

#[test]
fn a_twin_is_a_rival_only_if_it_fits_about_as_well() {
    // The wide wall lift (walls within 4 px) as the lift: no less, and the same for walls
    // that fit within 2 px.
    let scores = |lift: f64, support: usize, contradiction: f64| Verification {
        wall_lift: lift,
        wide_wall_lift: lift,
        wall_support: support,
        wall_contradiction: contradiction,
        acceptance_index: 0.99,
        ..Verification::default()
    };
    let twin = |verification: Verification| {
        Candidate::scored(
            Rigid2::new(1.6, 40.0, 0.0),
            verification,
            true,
            Origin::Symmetry,
        )
    };
    let config = VerifyConfig::default();
    // The exact copy of a small room (a case proptest found): the best fits every wall,
    // the quarter-turned twin passes but fits 0.90 of a smaller overlap.
    let best = scores(1.0, 622, 0.0);
    assert!(!rivals(&best, &twin(scores(0.90, 292, 0.027)), &config));
    // Scoring 0.6 of the best, or fitting as well, makes it a rival ...
    assert!(rivals(&best, &twin(scores(0.90, 430, 0.015)), &config));
    assert!(rivals(&best, &twin(scores(1.0, 200, 0.0)), &config));
    // ... unless it puts clearly more of its walls into free space: against a best that
    // puts none there, more than 0.02 ...
    assert!(!rivals(&best, &twin(scores(0.90, 430, 0.027)), &config));
    assert!(!rivals(&best, &twin(scores(1.0, 622, 0.06)), &config));
    // ... (the rule before, 0.05 whatever the best, at `clean_contradiction_excess` 0.05)
    let before = VerifyConfig {
        clean_contradiction_excess: 0.05,
        ..VerifyConfig::default()
    };
    assert!(rivals(&best, &twin(scores(0.90, 430, 0.027)), &before));
    // ... and more than the best's own share plus 0.02, up to 0.05: a rival of a best at
    // 0.01 may put up to 0.04 there, of one at 0.04 up to 0.09.
    let at = |c: f64| scores(1.0, 622, c);
    assert!(rivals(&at(0.01), &twin(scores(1.0, 622, 0.039)), &config));
    assert!(!rivals(&at(0.01), &twin(scores(1.0, 622, 0.041)), &config));
    assert!(rivals(&at(0.04), &twin(scores(1.0, 622, 0.089)), &config));
    assert!(!rivals(&at(0.04), &twin(scores(1.0, 622, 0.091)), &config));
    // ... or fails.
    let failed = Candidate {
        accepted: false,
        ..twin(best)
    };
    assert!(!rivals(&best, &failed, &config));
    // A warehouse turned by a quarter (nav2 depot, see
    // `VerifyConfig::trusted_wide_wall_lift`): the best lays twice the walls but fits them
    // imperfectly (wide wall lift 0.86), so a placement near the truth that passes at half
    // its score is a rival; against a best that fits every wall (the exact copy above,
    // wide 1.0) it is not.
    let wide = |lift: f64, support: usize, contradiction: f64, wide: f64| Verification {
        wide_wall_lift: wide,
        ..scores(lift, support, contradiction)
    };
    let near_truth = twin(wide(0.67, 485, 0.025, 0.971));
    assert!(rivals(&wide(0.77, 859, 0.121, 0.855), &near_truth, &config));
    assert!(!rivals(&wide(1.0, 1300, 0.0, 1.0), &near_truth, &config));
}

#[test]
fn a_placement_stands_out_only_if_every_distinct_one_fits_clearly_worse() {
    // Candidates placed `tx` px to the right of the first; `apart` is that distance.
    let at = |tx: f64, wide: f64, acceptance_index: f64| {
        let verification = Verification {
            wall_lift: wide - 0.2,
            wide_wall_lift: wide,
            wall_support: 2000,
            acceptance_index,
            overlap_fraction: 0.4,
            wall_density: 0.05,
            ..Verification::default()
        };
        Candidate::scored(
            Rigid2::new(0.0, tx, 0.0),
            verification,
            false,
            Origin::Sweep,
        )
    };
    let apart = |x: &Rigid2, y: &Rigid2| (x.tx - y.tx).abs();
    let config = VerifyConfig::default();
    let rule = StandOut::default();
    let margin = rule.margin;
    let pick = |cs: &[Candidate]| standing_out(cs, &rule, &config, &apart);
    // Below the rule's wide lift nothing is picked, however clear the margin.
    assert_eq!(pick(&[at(0.0, 0.69, 0.95), at(100.0, 0.2, 0.95)]), None);
    // A placement at 0.75 whose distinct rivals stay `margin` below stands out; a
    // placement within `distance_px` of it is the same answer and is not compared.
    let clear = [
        at(0.0, 0.75, 0.95),
        at(10.0, 0.76, 0.95),
        at(100.0, 0.75 - margin - 0.01, 0.95),
    ];
    // The better scoring of the two near ones (higher lift) is the one picked.
    assert_eq!(pick(&clear), Some(1));
    // A distinct placement within the margin: nothing stands out.
    let close = [at(0.0, 0.75, 0.95), at(100.0, 0.75 - margin + 0.01, 0.95)];
    assert_eq!(pick(&close), None);
    // ... unless that placement fails the acceptance index, and so is no placement at all.
    let failed = [at(0.0, 0.75, 0.95), at(100.0, 0.75, 0.5)];
    assert_eq!(pick(&failed), Some(0));
    // The rule's own acceptance index bar counts, not the main one: a placement between
    // the two is no placement to it, neither the one that stands out nor a rival.
    let between = (config.min_acceptance_index + rule.min_acceptance_index) / 2.0;
    assert!(config.min_acceptance_index < between && between < rule.min_acceptance_index);
    assert_eq!(
        pick(&[at(0.0, 0.75, 0.95), at(100.0, 0.75, between)]),
        Some(0)
    );
    assert_eq!(pick(&[at(0.0, 0.75, between), at(100.0, 0.2, 0.95)]), None);
    // An overlap with too little wall in it (an eroded map's border band) never stands out.
    let mut sparse = at(0.0, 0.9, 0.95);
    sparse.verification.wall_density = rule.min_wall_density * 0.9;
    assert_eq!(pick(&[sparse, at(100.0, 0.2, 0.95)]), None);
}

#[test]
fn a_clean_copy_near_a_quarter_turn_is_polished() {
    // Rigid motion about two centres: `ca` of the source lands on `cb`.
    let about = |deg: f64, ca: DVec2, cb: DVec2| {
        let r = DVec2::from_angle(deg.to_radians());
        let t = cb - r.rotate(ca);
        Rigid2::new(deg.to_radians(), t.x, t.y)
    };
    // A tilted room (its walls are rasterised slopes), and a copy of it turned by 90.8
    // degrees: most of the copy's cells are those of an exact quarter turn.
    let tilt = about(20.0, DVec2::new(60.0, 50.0), DVec2::splat(80.0));
    let a = room().warp(&tilt, 160, 160).unwrap();
    let a_to_b = about(90.8, DVec2::splat(80.0), DVec2::splat(90.0));
    let b = a.warp(&a_to_b, 180, 180).unwrap();
    let truth = a_to_b.inverse();
    let r = register(&a, &b, &RegisterConfig::default()).unwrap();
    let best = r.accepted.expect("accepted");
    assert!(best.verification.wall_lift >= PolishConfig::default().min_wall_lift);
    // Without the polish this copy came out 0.21 degrees off (0.02 with it).
    let err = rotation_error_deg(&best.transform, &truth);
    assert!(err < 0.1, "{err} degrees off");
}

#[test]
fn an_answer_with_much_wall_in_the_other_maps_free_space_is_declined() {
    // B saw an obstacle A's robot saw through: a line of wall cells across A's free space,
    // more than the wide tolerance from A's walls.
    // Both rooms are clean (no lone wall cell), and the obstacle leaves more of B's walls
    // beyond the wide tolerance than the clean-fit bar allows; this test is about the bar
    // on walls in free space, which holds any map, so the clean-fit bar is lifted.
    let a = room();
    let (b, truth) = turned(&room_with_wall_across(22));
    let r = register(&a, &b, &pair_config(true)).unwrap();
    let reason = r.reason.unwrap_or_default();
    assert!(reason.starts_with("misfit: "), "{reason}");
    let config = || {
        let mut config = pair_config(true);
        config.pair.verify.clean_fit = None;
        config
    };
    let with_bar = |bar: f64| {
        let mut config = config();
        config.pair.verify.max_wall_contradiction = bar;
        register(&a, &b, &config).unwrap()
    };
    let r = register(&a, &b, &config()).unwrap();
    let best = r
        .accepted
        .unwrap_or_else(|| panic!("declined: {:?}", r.reason));
    assert!(displacement_error(&b, &best.transform, &truth).unwrap() < 1.0);
    let c = best.verification.wall_contradiction;
    assert!(c > 0.05 && c < 0.21, "contradiction {c}");
    let declined = with_bar(c - 0.01);
    assert!(declined.accepted.is_none());
    let reason = declined.reason.unwrap();
    assert!(reason.starts_with("contradicted: "), "{reason}");
    assert!(with_bar(c + 0.01).accepted.is_some());
}

#[test]
fn the_symmetry_probes_keep_an_asymmetric_room() {
    let a = room();
    let (b, truth) = turned(&a);
    for probes in [false, true] {
        let r = register(&a, &b, &pair_config(probes)).unwrap();
        let best = r
            .accepted
            .unwrap_or_else(|| panic!("declined: {:?}", r.reason));
        let err = displacement_error(&b, &best.transform, &truth).unwrap();
        assert!(err < 1.0, "probes {probes}: {err} px off");
    }
}

#[test]
fn refining_only_the_placements_that_fit_best_keeps_the_answer() {
    // No keypoints: only the whole-map searches (the sweep and the symmetry probes; the
    // global search is off by default) propose placements.
    // Nor a last polish of the best, which would hide which placement was refined.
    let a = room();
    let (b, truth) = turned(&a);
    let register = |refined_placements| {
        let config = PairConfig {
            refined_placements,
            polish: None,
            spectrum_rotation: None,
            ..PairConfig::default()
        };
        register_with(&a, &b, &[], &config).expect("valid settings")
    };
    let all = register(None);
    let one = register(Some(1));
    // Every placement is still a candidate, most of them unrefined.
    let sweep = |r: &Registration| {
        let sweep = r.candidates.iter().filter(|c| c.origin == Origin::Sweep);
        (sweep.clone().count(), sweep.filter(|c| c.refined).count())
    };
    let (proposed, refined) = sweep(&one);
    assert_eq!(sweep(&all), (proposed, proposed));
    assert!(
        proposed > 4 && refined < proposed / 2,
        "{refined} of {proposed} refined"
    );
    // The answer is refined, and the one refining every placement gives.
    let (best, best_of_all) = (one.accepted.unwrap(), all.accepted.unwrap());
    assert!(best.refined);
    assert!(displacement_error(&b, &best.transform, &truth).unwrap() < 0.5);
    let apart = displacement_error(&b, &best.transform, &best_of_all.transform).unwrap();
    assert!(apart < 0.05, "{apart} px from refining all");
}

#[test]
fn the_runner_up_is_the_best_ranked_candidate_clearly_apart_from_the_first() {
    let placed = |tx: f64, lift: f64, accepted: bool| {
        let verification = Verification {
            wall_lift: lift,
            wall_support: 400,
            acceptance_index: 0.98,
            ..Verification::default()
        };
        Candidate::scored(
            Rigid2::new(0.0, tx, 0.0),
            verification,
            accepted,
            Origin::Sweep,
        )
    };
    // Best first: the answer, a placement 3 px from it (one answer), then two apart.
    let r = Registration {
        accepted: Some(placed(0.0, 0.9, true)),
        reason: None,
        candidates: vec![
            placed(0.0, 0.9, true),
            placed(3.0, 0.85, true),
            placed(40.0, 0.72, true),
            placed(80.0, 0.3, false),
        ],
        correspondences: KindTotals::default(),
        inliers: KindTotals::default(),
        timings: Timings::default(),
        matches: Vec::new(),
    };
    let b = room();
    // Translations move every wall cell by the same distance: the mean is exact.
    let u = r.runner_up(&b, 10.0).unwrap();
    assert_eq!(u.candidate, r.candidates[2]);
    assert!((u.apart_px - 40.0).abs() < 1e-9, "{}", u.apart_px);
    assert!(
        (u.score_ratio - 0.72 / 0.9).abs() < 1e-12,
        "{}",
        u.score_ratio
    );
    // The first one farther than the bar, whatever comes after.
    let u = r.runner_up(&b, 41.0).unwrap();
    assert_eq!(u.candidate, r.candidates[3]);
    assert!((u.apart_px - 80.0).abs() < 1e-9);
    assert!(r.runner_up(&b, 81.0).is_none());
    // Turned half a turn about the room's centre, B's walls move by twice their distance
    // from it: the mean over the (strided) wall cells.
    let c = DVec2::new(60.0, 60.0);
    let turned = Candidate {
        transform: Rigid2::rotation_about(std::f64::consts::PI, c),
        ..placed(0.0, 0.8, true)
    };
    let r = Registration {
        candidates: vec![placed(0.0, 0.9, true), turned],
        ..r
    };
    let probe = crate::verify::strided(&wall_cells(&b), APART_POINTS);
    let expected = probe.iter().map(|p| 2.0 * (*p - c).length()).sum::<f64>() / probe.len() as f64;
    let u = r.runner_up(&b, 10.0).unwrap();
    assert!(
        (u.apart_px - expected).abs() < 1e-9,
        "{} against {expected}",
        u.apart_px
    );
    // No wall cell in B, or no other candidate: no runner-up.
    let cells = vec![0; b.width() * b.height()];
    let blank = OccupancyGrid::from_cells(
        b.width(),
        b.height(),
        0.05,
        grid_core::Pose2::default(),
        cells,
    )
    .unwrap();
    assert!(r.runner_up(&blank, 10.0).is_none());
    let alone = Registration {
        candidates: vec![placed(0.0, 0.9, true)],
        ..r
    };
    assert!(alone.runner_up(&b, 10.0).is_none());
}
