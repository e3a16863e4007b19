//! Registration of simulated pairs with known truth: the whole-map searches (the rotation
//! sweep's placements, `PairConfig::turn_search`) and the ambiguity test's basin rule
//! (`VerifyConfig::basin_ratio`), the stand-out rule of acceptance (`VerifyConfig::stand_out`),
//! the acceptance index bar on speckled walls (`VerifyConfig::min_acceptance_index`),
//! the spectrum angle's lever (`SpectrumRotation::max_lever_px`), the angle of a large pair
//! from its walls at right angles (`ManhattanRotation`), the score ascent
//! (`PairConfig::ascent`), the angle scanned about the overlap (`PairConfig::turn_scan`), that
//! the answer does not depend on the maps' unknown border
//! (`PairConfig::frame_margin`), a pair drawn by a mapper no setting was chosen on, how
//! the push of noisy walls grows with the sensor's range, a pair drawn by slam_toolbox's
//! counting mapper, and a clean answer's rival that puts walls in free space
//! (`VerifyConfig::clean_contradiction_excess`).

mod common;

use common::{fixture_floor, floor_case};
use grid_core::metrics::displacement_error;
use grid_core::{DVec2, OccupancyGrid};
use mapmerge::{Origin, RegisterConfig, Registration, register};
use mapsim::{
    Case, CaseConfig, HitRatioModel, InverseSensorModel, MapperModel, RobotConfig, WorldConfig,
    WorldKind, generate_case,
};

/// A case of `cargo xtask eval`'s disaster rows: 400 x 400 world, two lidar robots with range
/// noise `noise`, requested overlap `overlap`, mapped with `model`.
fn disaster_case(seed: u64, overlap: f64, noise: f64, model: impl Into<MapperModel>) -> Case {
    simulated_case(WorldKind::Disaster, seed, overlap, noise, model)
}

/// A case of `cargo xtask eval`'s rows of world `kind` (disaster or indoor): 400 x 400 world,
/// two lidar robots with range noise `noise`, requested overlap `overlap`, mapped with `model`.
fn simulated_case(
    kind: WorldKind,
    seed: u64,
    overlap: f64,
    noise: f64,
    model: impl Into<MapperModel>,
) -> Case {
    let robot = RobotConfig {
        noise_bound: noise,
        ..RobotConfig::default()
    };
    robots_case(kind, seed, overlap, robot, model)
}

/// As [`simulated_case`], both robots carrying `robot`'s sensor (`cargo xtask eval
/// --max-range`, `--beams` and `--noise` set it so).
fn robots_case(
    kind: WorldKind,
    seed: u64,
    overlap: f64,
    robot: RobotConfig,
    model: impl Into<MapperModel>,
) -> Case {
    let config = CaseConfig {
        world: WorldConfig {
            kind,
            width: 400,
            height: 400,
            ..WorldConfig::default()
        },
        robots: vec![robot; 2],
        overlap,
        overlap_tolerance: f64::INFINITY,
        mapper: model.into(),
        ..CaseConfig::default()
    };
    generate_case(&config, seed).unwrap()
}

/// The pair of `case` (robot 1 onto robot 0) registered with `config`, and the accepted
/// answer's displacement error in pixels, if any.
fn registered(case: &Case, config: &RegisterConfig) -> (Registration, Option<f64>) {
    let (a, b) = (&case.robots[0].map, &case.robots[1].map);
    let r = register(a, b, config).unwrap();
    let error = r
        .accepted
        .as_ref()
        .map(|c| displacement_error(b, &c.transform, &case.truth(0, 1)).unwrap());
    (r, error)
}

/// Case `seed` of the disaster 30 % overlap row of `cargo xtask eval` (10 % range noise, the
/// default mapper; seeds 7_000_000 + k come from `--suites overlap,zero,paper,real,noise
/// --seed 7`, 3_000_000 + k from `--suites overlap --only "overlap 0.3" --seed 3`).
fn disaster_30(seed: u64) -> Case {
    disaster_case(seed, 0.3, 0.1, InverseSensorModel::default())
}

/// The sweep as it was before `SweepConfig::translation_peaks` and `screened`: one
/// translation per angle, eight placements per ranking, none screened.
fn with_former_sweep(config: &mut RegisterConfig) {
    let sweep = config.pair.sweep.as_mut().unwrap();
    (
        sweep.translation_peaks,
        sweep.keep_normalized,
        sweep.screened,
    ) = (1, 8, 0);
}

/// Without the sweep the other way round (`SweepConfig::reverse`, 2026-12-05): it registers
/// some pairs pinned below on their own without what they pin, a second way to the same answer,
/// so those pins show what they add to the sweep one way round.
fn one_way(config: &mut RegisterConfig) {
    config.pair.sweep.as_mut().unwrap().reverse = false;
}

/// The local searches as they were before `SearchConfig::free_penalty` (2026-12-05).
fn without_free_penalty(config: &mut RegisterConfig) {
    for search in config.pair.searches_mut() {
        search.free_penalty = 0.0;
    }
}

/// `case` is registered within 3 px with the default configuration and not without `what`
/// (declined, or answered more than 3 px off): the default with `less` applied.
fn registered_only_with(case: &Case, what: &str, less: impl FnOnce(&mut RegisterConfig)) {
    registered_only_from(case, RegisterConfig::default(), what, less);
}

/// As [`registered_only_with`], from the settings `with` rather than the defaults.
fn registered_only_from(
    case: &Case,
    with: RegisterConfig,
    what: &str,
    less: impl FnOnce(&mut RegisterConfig),
) {
    let error = registered(case, &with).1;
    assert!(error.is_some_and(|e| e <= 3.0), "with {what}: {error:?} px");
    let mut without = with;
    less(&mut without);
    let error = registered(case, &without).1;
    assert!(
        error.is_none_or(|e| e > 3.0),
        "without {what}: {error:?} px (the test no longer shows what it adds)"
    );
}

/// Case 19 of seed 7: registered 0.95 px off with the search over +-2 degrees of the whole-map
/// placements, answered 8.1 px off without it (`cargo xtask eval --suites overlap --only
/// "disaster, overlap 0.3" --seed S`, S = 7, 8, 9, with and without `--turn-search 0`,
/// 2026-12-04 with the sweep's peaks apart, `SweepConfig::peak_radius`): one of 9 such pairs of
/// those 60, none going the other way. (Case 19 of seed 4 showed it until the sweep's peaks
/// were set apart, which answers it 8.2 px off; case 10 of seed 3 until the local search's
/// kernel was widened.)
#[test]
fn a_disaster_pair_at_30_percent_overlap_is_registered_after_the_turn_search() {
    registered_only_with(&disaster_30(7_000_019), "the turn search", |c| {
        c.pair.turn_search = None;
        one_way(c);
    });
}

/// Case 17 of seed 8: declined when the sweep kept one translation per angle, eight placements
/// per ranking and screened none, registered 1.3 px off by the present sweep. With only the best
/// placements of each whole-map search refined (`PairConfig::refined_placements`, 2026-12-04)
/// the present sweep registers 5 pairs of the disaster 30 % rows of seeds 7, 8 and 9 that the
/// former does not (7_000_005, 7_000_013, 8_000_005, this one and 9_000_008) and loses none
/// (`cargo xtask eval --suites overlap --only "disaster, overlap 0.3" --seed S`, with and
/// without `--sweep-peaks 1 --sweep-keep-normalized 8 --sweep-screen 0`). (Case 11 of seed 3
/// showed it until then, case 13 of seed 4 until the kernel was widened, and case 14 of seed 7
/// until the frames.)
#[test]
fn a_disaster_pair_at_30_percent_overlap_is_registered_from_a_lesser_sweep_peak() {
    registered_only_with(
        &disaster_30(8_000_017),
        "the sweep's lesser peaks and screen",
        |c| {
            with_former_sweep(c);
            one_way(c);
        },
    );
}

/// Case 16 of seed 4: without the screen (the 24 best of the sweep's normalised ranking refined
/// as ranked) the pair is declined; the screen passes on a placement that leads to 2.85 px (with
/// the local search's kernel at 3.5 px, `SearchConfig::sigma_px`; 1.7 px before). It is one of
/// two such cases among the disaster 30 % rows of seeds 3, 4, 7, 8 and 9, with 3_000_005, and
/// the screen loses none (`cargo xtask eval --suites overlap --only "disaster, overlap 0.3"
/// --seed S`, with and without `--sweep-screen 0`); case 18 of seed 3 showed it before the
/// frames (`PairConfig::frame_margin`), and now registers either way. Since the deep screen
/// (`SweepConfig::deep_screened`), which then screens the same placements when nothing passed,
/// it registers without the screen too; the test turns the deep screen off.
#[test]
fn a_disaster_pair_at_30_percent_overlap_is_registered_after_the_screen() {
    registered_only_from(&disaster_30(4_000_016), deep_off(), "the screen", |c| {
        c.pair.sweep.as_mut().unwrap().screened = 0;
    });
}

/// The default settings without the deep screen (`SweepConfig::deep_screened`), for the tests
/// of what the stages before it add.
fn deep_off() -> RegisterConfig {
    let mut config = RegisterConfig::default();
    config.pair.sweep.as_mut().unwrap().deep_screened = 0;
    config
}

/// The default settings with the deep screen on, 1000 placements deep (it is off by default).
fn deep_on() -> RegisterConfig {
    let mut config = RegisterConfig::default();
    config.pair.sweep.as_mut().unwrap().deep_screened = 1000;
    config
}

/// Case 14 of seed 7: declined when the sweep's translations of one angle were the local
/// maxima among their eight neighbours (`SweepConfig::peak_radius` 1), registered 1.4 px off
/// with them at least 3 coarse cells apart (the default): the truth's translation then ranks
/// among its angle's 10 (`cargo xtask eval --suites overlap --only "overlap 0.3" --seed S`, S = 7, 8, 9,
/// with and without `--sweep-peak-radius 1`: 3 disaster and 1 indoor pair of the default
/// mapper's 120 registered, none lost; see docs/EVALUATION.md).
#[test]
fn a_disaster_pair_at_30_percent_overlap_is_registered_from_peaks_apart() {
    registered_only_with(&disaster_30(7_000_014), "peaks apart", |c| {
        c.pair.sweep.as_mut().unwrap().peak_radius = 1;
        one_way(c);
    });
}

/// Case 19 of seed 8 of the disaster 30 % row mapped with hector's model (`cargo xtask eval
/// --suites overlap --only "overlap 0.3" --mapper hector --seed 8`): ICP settles 3.5 px off,
/// where its few wall pairs that carry weight balance, while the verification score rises all
/// the way to the truth; the ascent (`PairConfig::ascent`) climbs it to 0.5 px. Over that row
/// and the indoor one at seeds 7-9 it registered 7 such pairs and lost 2 (answers 2.5-2.6 px off
/// that it moved to 3.1-3.3 px); at seeds 10-12, 12 and 1 (docs/EVALUATION.md, "The score
/// ascent").
#[test]
fn a_hector_pair_at_30_percent_overlap_is_registered_after_the_ascent() {
    let case = disaster_case(8_000_019, 0.3, 0.1, InverseSensorModel::hector());
    registered_only_with(&case, "the ascent", |c| c.pair.ascent = None);
}

/// Case 15 of seed 10 of the disaster 30 % row mapped with hector's model (`cargo xtask eval
/// --suites overlap --only "overlap 0.3" --mapper hector --seed 10`): the plain score climbs to
/// a pose 5.4 px off that compares 2,861 wall cells and puts 7.7 % of them in the other map's
/// free space, over the truth's basin (2,334 cells, 0.5 %); counted against the pose
/// (`AscentConfig::contradiction_weight`), those walls keep the climb at 1.1 px. Over hector's
/// 30 % rows at seeds 7-12 the weight registered 7 such pairs and lost 1 (docs/EVALUATION.md,
/// "Walls in free space weigh against the ascent").
#[test]
fn a_hector_pair_at_30_percent_overlap_is_registered_when_walls_in_free_space_weigh() {
    let case = disaster_case(10_000_015, 0.3, 0.1, InverseSensorModel::hector());
    registered_only_with(&case, "the contradiction weight", |c| {
        c.pair.ascent.as_mut().unwrap().contradiction_weight = 0.0;
    });
}

/// Case 2 of seed 12 of the disaster 30 % row mapped with hector's model (`cargo xtask eval
/// --suites overlap --only "overlap 0.3" --mapper hector --seed 12`): the rotation sweep's
/// first placement lies 4 px and 0.7 degrees from the truth, and the local search, scoring
/// only walls that meet walls, slid it 8.8 px away towards more overlap, where it failed;
/// nothing else passed and the pair was declined. With walls in the other map's free space
/// costing the search (`SearchConfig::free_penalty`) it stays near and registers 1.9 px off.
#[test]
fn a_hector_pair_at_30_percent_overlap_is_registered_when_walls_in_free_space_cost_the_search() {
    let case = disaster_case(12_000_002, 0.3, 0.1, InverseSensorModel::hector());
    registered_only_with(&case, "the search's free penalty", without_free_penalty);
}

/// Case 19 of seed 8: nothing the sweep proposes passes, and the pair was declined; the
/// sweep the other way round (B's field, A's walls turned over it, `SweepConfig::reverse`)
/// proposes a placement that registers 0.9 px off. Over the 30 % rows of seeds 7-12 it
/// registered 4 more of the default mapper's 240 pairs, hector's as many as before
/// (docs/EVALUATION.md, "The sweep the other way round"). The deep screen, down both
/// rankings, registers it without the reverse sweep too; the test turns the deep screen off.
#[test]
fn a_disaster_pair_at_30_percent_overlap_is_registered_by_the_reverse_sweep() {
    registered_only_from(
        &disaster_30(8_000_019),
        deep_off(),
        "the reverse sweep",
        |c| {
            c.pair.sweep.as_mut().unwrap().reverse = false;
        },
    );
}

/// Case 8 of seed 8 (the default mapper, whose walls are one cell thick and pushed behind the
/// obstacle faces by range noise): registered 2.9 px off, climbed to 4.3 px by the ascent when
/// it is not held back by the walls' thickness (`AscentConfig::min_wall_thickness`). Without
/// that gate the ascent registered 15 fewer of the default mapper's 120 pairs at 30 % overlap
/// over seeds 7-9, 3 gained, 18 lost (docs/EVALUATION.md, "The score ascent").
#[test]
fn thin_walls_pushed_by_range_noise_are_not_climbed() {
    registered_only_with(&disaster_30(8_000_008), "the thickness gate", |c| {
        c.pair.ascent.as_mut().unwrap().min_wall_thickness = 0.0;
    });
}

/// Case 7_000_004 of the disaster 30 % overlap row (`cargo xtask eval --suites overlap --seed
/// 7`), both robots at 10 % range noise, drawn with lidars of three ranges (`--max-range`):
/// the farther the sensor reads, the farther each map's walls are pushed behind the obstacle
/// faces, and the farther apart the answer puts the maps (docs/EVALUATION.md, "The sensor's
/// range decides the push"). The answers lie 0.55, 2.70 and 8.24 px off, B's known cells
/// -0.1, +2.7 and +8.2 px farther from A's than at the truth: within 1 px at 40 cells, within
/// 3 px at the suites' 80, and at 150 accepted well off, pushed apart.
#[test]
fn the_push_grows_with_the_sensors_range() {
    let mut pushes = Vec::new();
    for (range, most_px) in [(40.0, 1.0), (80.0, 3.0), (150.0, f64::INFINITY)] {
        let robot = RobotConfig {
            max_range: range,
            noise_bound: 0.1,
            ..RobotConfig::default()
        };
        let case = robots_case(
            WorldKind::Disaster,
            7_000_004,
            0.3,
            robot,
            InverseSensorModel::default(),
        );
        let (r, error) = registered(&case, &RegisterConfig::default());
        let error = error.unwrap_or_else(|| panic!("range {range}: declined: {:?}", r.reason));
        assert!(error <= most_px, "range {range}: {error} px off");
        pushes.push((range, error, push(&case, &r.accepted.unwrap().transform)));
    }
    let [(_, e40, p40), (_, e80, p80), (_, e150, p150)] = pushes[..] else {
        unreachable!()
    };
    assert!(e40 < e80 && e80 < e150, "{pushes:?}");
    assert!(p40.abs() < 1.0 && p80 > 1.5 && p150 > 6.0, "{pushes:?}");
}

/// How much farther from A's known cells `answer` puts B's than the truth of `case` does.
fn push(case: &Case, answer: &grid_core::Rigid2) -> f64 {
    let (a, b) = (&case.robots[0].map, &case.robots[1].map);
    let (ca, cb) = (a.known_centroid().unwrap(), b.known_centroid().unwrap());
    (answer.apply(cb) - ca).length() - (case.truth(0, 1).apply(cb) - ca).length()
}

/// Case 7_000_016 of the disaster 30 % overlap row (`cargo xtask eval --suites overlap --only
/// "overlap 0.3" --seed 7`) with its beams folded by slam_toolbox's hit counts (`--mapper
/// slam-toolbox`), which keep a cell occupied where a tenth of the beams that reached it ended
/// in it: a noisy wall stays as a band over its faces. The answer lies 0.65 px off and puts
/// B's known cells 0.42 px farther from A's than the truth does. Folded by mapsim's default,
/// whose passes clear a noisy wall down to the far end of its band, the same beams are
/// answered 3.58 px off, pushed apart by 2.68 px (docs/EVALUATION.md, "The maps of GMapping
/// and slam_toolbox").
#[test]
fn walls_kept_as_bands_are_not_pushed_apart() {
    let counted = disaster_case(7_000_016, 0.3, 0.1, HitRatioModel::slam_toolbox());
    let cleared = disaster_case(7_000_016, 0.3, 0.1, InverseSensorModel::default());
    // The mapper does not move the robots: the truth is the same.
    assert_eq!(counted.truth(0, 1), cleared.truth(0, 1));
    let (r, error) = registered(&counted, &RegisterConfig::default());
    let error = error.unwrap_or_else(|| panic!("declined: {:?}", r.reason));
    let pushed = push(&counted, &r.accepted.unwrap().transform);
    assert!(
        error < 1.0 && pushed.abs() < 1.0,
        "{error} px off, pushed {pushed} px"
    );
}

/// Case 9003013 of `cargo xtask eval --suites overlap --only "indoor, overlap 0.3" --seed 9
/// --mapper hector --noise 0.02`: clean maps (a lidar's 2 % range noise) of rooms that repeat.
/// The best placement lies 1.1 px from the truth and puts none of its walls into the other
/// map's free space; a placement 267 px away fits at wall lift 0.91 and 0.77 of the best's
/// score but puts 3.1 % of its walls there. With the rival's allowance of 0.05 whatever the best
/// (`VerifyConfig::clean_contradiction_excess` at 0.05, the rule before) the pair was declined
/// as ambiguous; against a best this clean 0.02 is allowed, and the best is the answer.
#[test]
fn a_clean_answer_is_not_declined_over_a_rival_that_puts_walls_in_free_space() {
    let case = simulated_case(
        WorldKind::Indoor,
        9_003_013,
        0.3,
        0.02,
        InverseSensorModel::hector(),
    );
    registered_only_with(&case, "the clean allowance", |c| {
        c.pair.verify.clean_contradiction_excess = 0.05;
    });
    let mut before = RegisterConfig::default();
    before.pair.verify.clean_contradiction_excess = 0.05;
    let (r, _) = registered(&case, &before);
    let reason = r.reason.unwrap_or_default();
    assert!(reason.starts_with("ambiguous"), "{reason}");
}

/// Case 9003017 of `cargo xtask eval --suites overlap --only "indoor, overlap 0.3" --seed 9
/// --mapper slam-toolbox`: rooms that repeat. The best-ranked placement lies 420 px from the
/// truth, where it lays more walls on walls (wall lift 0.84) but puts 4.6 % of its compared
/// walls in the other map's free space; a placement 1.1 px from the truth fits almost every
/// wall (wide wall lift 0.98, 0.8 % in free space) at 0.91 of its score. The best was declined
/// as ambiguous over it; the clean placement now succeeds it
/// (`VerifyConfig::clean_successor`).
#[test]
fn a_declined_best_gives_way_to_a_placement_that_fits_cleanly() {
    let case = simulated_case(
        WorldKind::Indoor,
        9_003_017,
        0.3,
        0.1,
        HitRatioModel::slam_toolbox(),
    );
    registered_only_with(&case, "the clean successor", |c| {
        c.pair.verify.clean_successor = None;
    });
    let mut before = RegisterConfig::default();
    before.pair.verify.clean_successor = None;
    let (r, _) = registered(&case, &before);
    let reason = r.reason.unwrap_or_default();
    assert!(reason.starts_with("ambiguous"), "{reason}");
}

/// Case 41000014 of `cargo xtask eval --suites overlap --only "disaster, overlap 0.3" --seed 41
/// --mapper gmapping`, a seed no setting was chosen on: the best placement of the first sweep
/// passes the bars but would be declined, and the sweep the other way round, which ran only
/// where nothing passed, now runs there too (`SweepConfig::reverse`). Answered 4.76 px off
/// before, registered within 3 px now.
#[test]
fn the_sweep_runs_the_other_way_round_when_the_best_that_passed_would_be_declined() {
    let case = disaster_case(41_000_014, 0.3, 0.1, HitRatioModel::gmapping());
    registered_only_with(&case, "the reverse sweep", |c| {
        c.pair.sweep.as_mut().unwrap().reverse = false;
    });
}

/// Case 8001019 of `cargo xtask eval --suites paper --only "overlap 0.3" --seed 8` (the
/// paper's setting: 16-beam infrared rings, range 30 cells, noise 10 % and 15 %). Its walls are
/// as thin as the default mapper's lidar walls above, but both maps have many frontier cells
/// (frontier ratios 1.38 and more, where the lidar maps of the 30 % rows have at most 1.04)
/// and ICP's answer fits loosely (wall lift 0.48), so the ascent runs
/// (`AscentConfig::short_range`) and climbs that answer, 5.8 px and 3.7 degrees off, to
/// within 2 px.
#[test]
fn a_short_range_sensors_thin_walls_are_climbed() {
    let mut config = CaseConfig::paper();
    config.overlap = 0.3;
    config.overlap_tolerance = 0.05;
    let case = generate_case(&config, 8_001_019).unwrap();
    let (a, b) = (&case.robots[0].map, &case.robots[1].map);
    let (fa, fb) = (
        mapmerge::ascent::frontier_ratio(a),
        mapmerge::ascent::frontier_ratio(b),
    );
    assert!(fa.min(fb) >= 1.2, "frontier ratios {fa}, {fb}");
    registered_only_with(&case, "the frontier gate", |c| {
        c.pair.ascent.as_mut().unwrap().short_range = None;
    });
}

/// The basin rule and the stand-out rule were pinned on their cases below with walls compared
/// on known cells only; with the shadow of the walls compared too (`VerifyConfig::shadow_px`,
/// the default since 2026-12-03) those cases no longer need them. Checks that the default
/// registers `case` within 3 px, and returns the configuration without the shadow, where each
/// rule is shown (and without the sweep the other way round, see [`one_way`]: for 8_001_004 it
/// finds a placement that passes the bars without standing out). `base` is the default, or
/// the default with something a later change added taken out again (see the pins).
fn shadowless_after(case: &Case, base: RegisterConfig) -> RegisterConfig {
    let (default, error) = registered(case, &base);
    assert!(
        error.is_some_and(|e| e <= 3.0),
        "default: {error:?} px ({:?})",
        default.reason
    );
    let mut config = base;
    config.pair.verify.shadow_px = 0.0;
    one_way(&mut config);
    config
}

/// Case 2 of the 30 %/30 % noise row of `cargo xtask eval --suites noise --mapper hector --seed
/// 8` (overlap 0.5, 30 % range noise, mapped with hector's gentle clearing, so the walls are
/// bands of speckle 10-20 px wide). Without the shadow the placement 2.1 px from the truth is
/// accepted only with the basin rule: without it the pair is declined as ambiguous, a rival
/// scoring almost as well as the best placement from within the best one's broad optimum (the
/// placements between them score as well: one optimum, not two answers). Since ICP stops once
/// converged (`RefineConfig::tolerance_px`, 2026-12-04) it is the one such case of that row at
/// seeds 7 and 8 (the same command with `--shadow 0`, with and without `--basin-ratio 0`);
/// case 8_001_006 showed it before (then answered 7.0 px off), and 7_001_019 before the local
/// search's kernel was widened, a rival 11 px off and turned 3 degrees scoring 0.88 of the
/// best. With the shadow the rival no longer scores as well: see [`shadowless_after`]. Since
/// walls in free space cost the local search (`SearchConfig::free_penalty`, 2026-12-05) the
/// default answers this pair 4.1 px off (that row at seeds 7-9 lost one pair, 30 -> 29 of 60),
/// so the pin runs with the search as it was (no penalty).
#[test]
fn a_rival_in_the_best_placements_basin_does_not_make_the_pair_ambiguous() {
    let case = disaster_case(8_001_002, 0.5, 0.3, InverseSensorModel::hector());
    let mut base = RegisterConfig::default();
    without_free_penalty(&mut base);
    let config = shadowless_after(&case, base);
    let (with, error) = registered(&case, &config);
    assert!(
        error.is_some_and(|e| e <= 3.0),
        "with the basin rule: {error:?} px ({:?})",
        with.reason
    );

    let mut without = config;
    without.pair.verify.basin_ratio = 0.0;
    let reason = registered(&case, &without).0.reason.unwrap_or_default();
    assert!(
        reason.starts_with("ambiguous: two different placements fit almost equally well"),
        "without the basin rule the pair should be declined as ambiguous: {reason:?}"
    );
}

/// Case 8_001_004 of the 30 %/30 % noise row of `cargo xtask eval --suites noise --mapper
/// hector --seed 8` (overlap 0.5): the walls are speckle, and without the shadow no placement
/// reaches the wall lift bars, but the one nearest the truth stands out from every placement
/// more than 20 px from it. The stand-out rule (`VerifyConfig::stand_out`) accepts it; without
/// the rule the pair is declined. With the shadow the placement passes the bars by itself: see
/// [`shadowless_after`]. (Case 7_003_000 of `--suites zero,noise` showed it until the
/// frames, `PairConfig::frame_margin`; found again with the eval's `--shadow 0` and
/// `--no-stand-out`.)
#[test]
fn a_placement_that_stands_out_on_speckled_walls_is_accepted() {
    let case = disaster_case(8_001_004, 0.5, 0.3, InverseSensorModel::hector());
    let config = shadowless_after(&case, RegisterConfig::default());
    let (with, error) = registered(&case, &config);
    assert!(
        error.is_some_and(|e| e <= 3.0) && with.accepted.is_some_and(|c| c.stands_out),
        "with the stand-out rule: {error:?} px ({:?})",
        with.reason
    );

    let mut without = config;
    without.pair.verify.stand_out = None;
    let reason = registered(&case, &without).0.reason.unwrap_or_default();
    assert!(
        reason.starts_with("no hypothesis passed verification"),
        "without the stand-out rule the pair should be declined: {reason:?}"
    );
}

/// Case 7_001_006 of the disaster 50 % overlap row of `cargo xtask eval --suites overlap
/// --noise 0.2 --seed 7`: both robots at 20 % range noise, the default mapper. The walls are
/// speckle (16.3 % and 14.6 % lone wall cells), no placement reaches the bars, and the
/// decline says so.
#[test]
fn a_pair_whose_walls_are_both_speckle_is_declined_saying_so() {
    let case = disaster_case(7_001_006, 0.5, 0.2, InverseSensorModel::default());
    let (r, _) = registered(&case, &RegisterConfig::default());
    let reason = r.reason.unwrap_or_default();
    assert!(
        r.accepted.is_none()
            && reason.starts_with("no hypothesis passed verification")
            && reason.contains("both maps' walls are speckle (lone wall cells 16.3 % and 14.6 %)"),
        "{reason}"
    );
}

/// Case 18 of seed 7 of the indoor 30 % row at 20 % range noise mapped with hector's model
/// (`cargo xtask eval --suites overlap --only "indoor, overlap 0.3" --noise 0.2 --mapper
/// hector --seed 7`): walls kept as bands of speckle disagree cell by cell with the other
/// map's free space, and the right answer (0.86 px off) scores an acceptance index of 0.871,
/// under the bar of 0.88 that was the default until 2026-12-06 (`VerifyConfig::
/// min_acceptance_index`).
#[test]
fn a_speckled_indoor_pair_is_accepted_below_the_former_acceptance_index_bar() {
    let case = simulated_case(
        WorldKind::Indoor,
        7_003_018,
        0.3,
        0.2,
        InverseSensorModel::hector(),
    );
    registered_only_with(&case, "the acceptance index bar at 0.82", |c| {
        c.pair.verify.min_acceptance_index = 0.88
    });
}

/// Case `seed` of the intel_lab row of `cargo xtask eval --suites real` (the intel lab floor of
/// `fixtures/maps` explored by two lidar robots with 10 % and 20 % range noise, half of each
/// map shared; seeds 7_003_000 + k come from `--suites real --seed 7`).
fn intel_lab_case(seed: u64) -> Case {
    intel_lab_pair(seed, 0.5, &[0.1, 0.2])
}

/// Two lidar robots with range noise `noise` exploring the intel lab floor of `fixtures/maps`,
/// sharing `overlap` of each map.
fn intel_lab_pair(seed: u64, overlap: f64, noise: &[f64]) -> Case {
    let floor = fixture_floor("intel_lab");
    let config = CaseConfig {
        overlap,
        overlap_tolerance: f64::INFINITY,
        ..CaseConfig::floor(floor, noise)
    };
    generate_case(&config, seed).unwrap()
}

/// Case 8 of the intel_lab row of `cargo xtask eval --suites floors --seed 7` (30 % overlap,
/// 10 % range noise on both robots): ICP and the searches leave the answer 0.87 degrees off
/// (4.3 px on B's far cells), since they turn B about the centre of all its walls, far from
/// the shared ones; the angle scanned about the overlap (`mapmerge::TurnScan`) finds the
/// truth's basin, which scores higher (0.7 px).
#[test]
fn an_intel_lab_pair_at_30_percent_overlap_is_registered_after_the_turn_scan() {
    let case = intel_lab_pair(7_003_008, 0.3, &[0.1, 0.1]);
    registered_only_with(&case, "the turn scan", |c| c.pair.turn_scan = None);
}

/// The intel lab's partial maps share walls spread over a long lever, where ICP's angle beats
/// the walls' Hough spectra, which two maps of different parts of an irregular building skew
/// (`SpectrumRotation::max_lever_px`). Taking the spectrum angle on every answer, this pair's
/// answer lands 5.3 px off; with the lever rule within 3 px (1.4 px).
#[test]
fn an_intel_lab_pair_keeps_icps_angle_on_a_long_lever() {
    let case = intel_lab_case(7_003_008);
    let mut always = RegisterConfig::default();
    always.pair.spectrum_rotation.as_mut().unwrap().max_lever_px = f64::INFINITY;
    let before = registered(&case, &always).1.expect("accepted");
    assert!(before > 3.0, "{before} px off with the spectrum angle");
    let after = registered(&case, &RegisterConfig::default())
        .1
        .expect("accepted");
    assert!(after <= 3.0, "{after} px off");
}

/// The answer does not depend on the unknown border the maps come with
/// (`PairConfig::frame_margin`): the same pair, each map cut tight to its known cells or
/// padded unevenly with unknown cells, gives the same candidates, the same decision and the
/// same transform (in each input's own pixels), up to the rounding of the frames' offsets.
/// Before the frames, a border one pixel wider turned the scale space's sampling and the
/// whole-map searches' grids, and such a pair (the bench's partial maps) was answered on one
/// canvas and declined on another.
#[test]
fn the_answer_does_not_depend_on_the_maps_unknown_border() {
    // Disaster 30 % case 12: keypoints, the global search (off by default, on here so that
    // it is compared too), the sweep and the symmetry probes all take part.
    let case = disaster_case(7_000_012, 0.3, 0.1, InverseSensorModel::default());
    let (a, b) = (&case.robots[0].map, &case.robots[1].map);
    let mut config = RegisterConfig::default();
    config.pair.global = Some(mapmerge::global::GlobalConfig::default());
    let given = register(a, b, &config).unwrap();
    // Map `m`'s region from `(x0, y0)` to `width x height` (negative corners pad), and where
    // the map's own pixel (0, 0) lies in it.
    let moved = |m: &OccupancyGrid, x0: i64, y0: i64, w: usize, h: usize| {
        let r = m.region(x0, y0, w, h).unwrap();
        (r, DVec2::new(-x0 as f64, -y0 as f64))
    };
    let tight = |m: &OccupancyGrid| {
        let (x0, y0, w, h) = m.known_bounds(0).unwrap();
        moved(m, x0 as i64, y0 as i64, w, h)
    };
    let padded = |m: &OccupancyGrid, left: i64, top: i64, extra: usize| {
        moved(
            m,
            -left,
            -top,
            m.width() + left as usize + extra,
            m.height() + top as usize + extra,
        )
    };
    for ((a2, oa), (b2, ob)) in [
        (tight(a), tight(b)),
        (padded(a, 37, 5, 120), padded(b, 1, 90, 3)),
        (tight(a), padded(b, 200, 200, 200)),
    ] {
        let r = register(&a2, &b2, &config).unwrap();
        assert_eq!(r.accepted.is_some(), given.accepted.is_some());
        assert_eq!(r.reason, given.reason);
        assert_eq!(r.candidates.len(), given.candidates.len());
        for (c, g) in r.candidates.iter().zip(&given.candidates) {
            assert_eq!(
                (c.origin, c.accepted, c.verification),
                (g.origin, g.accepted, g.verification)
            );
            // The candidate in the given maps' pixels: p -> t(p + ob) - oa.
            let t = c.transform;
            let back = t.apply(ob) - oa;
            let g = g.transform;
            assert!(
                (t.theta - g.theta).abs() < 1e-9
                    && (back.x - g.tx).abs() < 1e-6
                    && (back.y - g.ty).abs() < 1e-6,
                "{t:?} (offsets {oa}, {ob}) against {g:?}"
            );
        }
    }
    // The case is answered, so the comparison covers an accepted transform, and every kind
    // of candidate was compared.
    assert!(given.accepted.is_some(), "{:?}", given.reason);
    for origin in [
        Origin::Ransac,
        Origin::Global,
        Origin::Sweep,
        Origin::Symmetry,
    ] {
        assert!(
            given.candidates.iter().any(|c| c.origin == origin),
            "no {origin} candidate"
        );
    }
}

/// Case 5 of the noise suite's 10 % row at half overlap, mapped with OctoMap's model, which no
/// setting was chosen on (`cargo xtask eval --suites noise --only "overlap 0.5" --mapper
/// octomap --seed 7`; 58 of the 60 pairs of that row at seeds 7-9 are registered, see
/// docs/EVALUATION.md, "A mapper never tuned on"): registered 0.4 px off.
#[test]
fn a_pair_drawn_by_octomaps_mapper_is_registered() {
    let case = disaster_case(7_000_005, 0.5, 0.1, InverseSensorModel::octomap());
    let (r, error) = registered(&case, &RegisterConfig::default());
    assert!(
        error.is_some_and(|e| e < 1.5),
        "error {error:?}, reason {:?}",
        r.reason
    );
}

/// Case 7 of `cargo xtask gen --world fixtures/maps/nav2_depot/nav2_depot.yaml --overlap 0.3
/// --seed 11 --count 8` (the paper preset's robots in the nav2 depot, a warehouse whose shelf
/// rows repeat): the best placement is a quarter turn off, laying twice the truth's walls (wall
/// lift 0.77, wide 0.86, 12 % in free space), and a placement 2.5 px from the truth passes
/// too (0.67, 0.97, 2.5 %) but scores half as much. A best that fits that imperfectly is
/// rivalled by every other placement that passes (`VerifyConfig::trusted_wide_wall_lift`):
/// declined rather than answered 300 px off.
#[test]
fn a_warehouse_pair_whose_best_placement_is_a_quarter_turn_off_is_declined() {
    let depot = depot();
    let mut config = CaseConfig::paper();
    config.world.resolution = depot.resolution();
    config.world.kind = WorldKind::Grid(depot);
    config.overlap = 0.3;
    let case = generate_case(&config, 18).unwrap();
    declined_for(&case, "the best placement fits imperfectly");
    answered_far_off_without(&case, |verify| {
        verify.trusted_wide_wall_lift = 0.0;
        // The best would fail the crisp-walls bar too (lift 0.77, 12 % of walls in free space).
        verify.crisp_wall_lift = 2.0;
    });
}

/// The nav2 depot of `fixtures/maps`, a warehouse whose shelf rows repeat.
fn depot() -> OccupancyGrid {
    fixture_floor("nav2_depot")
}

/// `case`'s pair is declined with a reason that contains `why`.
fn declined_for(case: &Case, why: &str) {
    let (r, error) = registered(case, &RegisterConfig::default());
    assert!(
        r.reason
            .as_deref()
            .is_some_and(|reason| reason.contains(why)),
        "error {error:?}, reason {:?}",
        r.reason
    );
}

/// With the verification changed by `without`, `case`'s pair is answered more than 200 px off.
fn answered_far_off_without(
    case: &Case,
    without: impl FnOnce(&mut mapmerge::verify::VerifyConfig),
) {
    let mut config = RegisterConfig::default();
    without(&mut config.pair.verify);
    let (r, error) = registered(case, &config);
    assert!(
        error.is_some_and(|e| e > 200.0),
        "without the rule: {error:?}, reason {:?}",
        r.reason
    );
}

/// Case 7004003 of the warehouse row of `cargo xtask eval --suites real --seed 7` (two lidar
/// robots with 10 % range noise in the nav2 depot at 30 % overlap): the best placement is the
/// truth turned by a quarter, laying B's long wall precisely on A's end wall (wall lift 0.86)
/// while each map puts 5.6 % of its compared walls in the other's free space, and no
/// placement near the truth is found to rival it. Walls that fit that crisply may leave at
/// most 0.25 of their misfit in free space both ways (`VerifyConfig::crisp_wall_lift`):
/// declined rather than answered 310 px off.
#[test]
fn a_warehouse_pair_matched_by_crisp_walls_a_quarter_turn_off_is_declined() {
    let case = floor_case(depot(), 7_004_003);
    declined_for(&case, "lays walls on walls crisply");
    answered_far_off_without(&case, |verify| verify.crisp_wall_lift = 2.0);
}

/// Case 7000001 of `cargo xtask eval --suites large --seed 7`: two robots in the nav2
/// warehouse (1006 x 1674 cells), maps overlapping by 30 %. Without the Manhattan angle the
/// answer is 0.34 degrees off (3.54 px on average over B's cells): the overlap's walls, tilted
/// in each map its own way, do not pin the angle over B's far cells. The two maps' dominant
/// wall directions do (`mapmerge::ManhattanRotation`): 0.10 degrees, 0.95 px. Case 7000005
/// showed it until the edge test of the keypoints stopped favouring turned edges (2026-12-05,
/// docs/EVALUATION.md, "An edge test that does not depend on the edge's direction"): since,
/// its answer has the angle within 0.03 degrees but the translation 3.07 px off.
#[test]
fn a_large_warehouse_pair_takes_its_angle_from_the_walls_at_right_angles() {
    let case = floor_case(fixture_floor("nav2_warehouse"), 7_000_001);
    answered_off_without(&case, 1.5, "the Manhattan angle", |c| {
        c.pair.manhattan_rotation = None;
    });
}

/// `case` is registered less than `within_px` off with the default configuration, and
/// answered more than 3 px off without `what` (the default with `less` applied).
fn answered_off_without(
    case: &Case,
    within_px: f64,
    what: &str,
    less: impl FnOnce(&mut RegisterConfig),
) {
    let with = RegisterConfig::default();
    let (_, error) = registered(case, &with);
    assert!(error.is_some_and(|e| e < within_px), "{error:?}");
    let mut without = with;
    less(&mut without);
    let (_, error) = registered(case, &without);
    assert!(error.is_some_and(|e| e > 3.0), "without {what}: {error:?}");
}

/// Case 23024000 of `cargo xtask eval --suites overlap,zero,paper,real,noise,floors,floorzero,
/// crops --seed 23` (held out: no setting was chosen on that seed): two robots with 10 % range
/// noise on the uos_avz floor at 30 % overlap. The answer lies 0.62 px from the truth at wall
/// lift 0.84; the two maps' dominant wall directions turn it by 0.8 degrees, to 3.3 px off at
/// lift 0.68. An angle that costs that much of the fit is not the overlap's
/// (`ManhattanRotation::max_lift_drop`): the answer keeps its own.
#[test]
fn a_floor_pair_keeps_its_angle_when_the_walls_at_right_angles_cost_the_fit() {
    let case = floor_case(fixture_floor("uos_avz"), 23_024_000);
    answered_off_without(
        &case,
        1.0,
        "the lift bar (the angle whatever it costs)",
        |c| {
            c.pair.manhattan_rotation.as_mut().unwrap().max_lift_drop = f64::INFINITY;
        },
    );
}

/// Case 23022013 of `cargo xtask eval --suites overlap,zero,paper,real,noise,floors,floorzero,
/// crops --seed 23` (held out): two robots with 10 % range noise on the uos_cic floor, whose
/// maps (1466 x 694 and 1175 x 576 px once framed) share 30 % of a large hall. With the
/// sweep's 96 coarse cells those are 14 px wide, and the placement near the truth ranked 139th
/// by the normalised correlation, after the 100 screened: declined. With cells of at most
/// 12 px (`SweepConfig::max_cell_px`) it ranks 78th and the pair is registered 1.44 px off.
/// (Since 2026-12-07 the deep screen finds it with the wide cells too; the test turns it off.)
#[test]
fn a_large_floor_pair_is_registered_on_finer_sweep_cells() {
    let case = floor_case(fixture_floor("uos_cic"), 23_022_013);
    registered_only_from(&case, deep_off(), "the finer sweep cells", |c| {
        c.pair.sweep.as_mut().unwrap().max_cell_px = f64::INFINITY;
    });
}

/// Case 9003016 of `cargo xtask eval --suites overlap --only "overlap 0.3" --seed 9 --mapper
/// hector`: an open hall, where nothing the sweeps screen passes. The deep screen
/// (`SweepConfig::deep_screened`) finds a placement 412 px off that passes at wall lift 0.68,
/// and a sliver (19.5 % shared) 248 px off that fits at 0.81. The sliver may not be the answer
/// (too little shared for a placement found that deep) but it is a rival: the pair is declined
/// as ambiguous. Proposed without the slivers, the deep screen answered it 412 px off. (With
/// the deep screen on; it is off by default.)
#[test]
fn a_deep_screens_sliver_keeps_a_wrong_placement_out_as_a_rival() {
    let case = simulated_case(
        WorldKind::Indoor,
        9_003_016,
        0.3,
        0.1,
        InverseSensorModel::hector(),
    );
    let (r, error) = registered(&case, &deep_on());
    let reason = r.reason.unwrap_or_default();
    assert!(
        error.is_none() && reason.starts_with("ambiguous: "),
        "{error:?} px, {reason}"
    );
    let (b, truth) = (&case.robots[1].map, case.truth(0, 1));
    let off = |c: &mapmerge::Candidate| displacement_error(b, &c.transform, &truth).unwrap();
    let passing: Vec<&mapmerge::Candidate> = r.candidates.iter().filter(|c| c.accepted).collect();
    assert!(
        passing.iter().all(|c| off(c) > 100.0),
        "{:?}",
        passing.iter().map(|c| off(c)).collect::<Vec<_>>()
    );
    assert!(
        passing
            .iter()
            .any(|c| c.verification.overlap_fraction < 0.25),
        "no sliver among the passing placements"
    );
}

/// Case 7002009 of `cargo xtask eval --suites floors --only "uos_cic world, overlap 0.3" --seed
/// 7`: two robots with 10 % range noise on the uos_cic floor. The truth, refined, fits at wall
/// lift 0.70, but no placement of the 100 screened of either sweep comes near it and none
/// passes: declined. The deep screen (`SweepConfig::deep_screened`) finds one that passes
/// further down the sweep the other way round, and the pair is registered 2.41 px off. (The
/// deep screen is off by default: see its documentation.)
#[test]
fn a_large_floor_pair_is_registered_from_deep_down_the_sweeps_ranking() {
    let case = floor_case(fixture_floor("uos_cic"), 7_002_009);
    registered_only_from(&case, deep_on(), "the deep screen", |c| {
        c.pair.sweep.as_mut().unwrap().deep_screened = 0;
    });
}
