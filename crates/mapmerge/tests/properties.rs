//! Property tests of the registration on simulated maps (mapsim strategies).

use grid_core::Rigid2;
use grid_core::metrics::{displacement_error, rotation_error_deg};
use mapmerge::{RegisterConfig, register};
use mapsim::strategies::{PairParams, Worlds, map_pair};
use proptest::prelude::*;

/// The proptest seed: `MAPMERGE_PROPTEST_SEED` if set to a number, else `default`.
fn seed_from_env(default: u64) -> u64 {
    env_number("MAPMERGE_PROPTEST_SEED").unwrap_or(default)
}

/// The number of cases: `PROPTEST_CASES` if set to a number, else `default`.
fn cases_from_env(default: u32) -> u32 {
    env_number("PROPTEST_CASES").map_or(default, |n| n.min(u32::MAX as u64) as u32)
}

fn env_number(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|s| s.trim().parse().ok())
}

proptest! {
    // A fixed seed makes every run, CI's included, try the same cases, so a red run can be
    // reproduced. `MAPMERGE_PROPTEST_SEED=N` explores other cases (proptest's own
    // PROPTEST_RNG_SEED is ignored while the config fixes the seed), `PROPTEST_CASES=N` more
    // of them.
    #![proptest_config(ProptestConfig {
        cases: cases_from_env(8),
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed_from_env(7)),
        ..ProptestConfig::default()
    })]

    /// A simulated robot's map and a copy moved by a random rigid transform (any angle,
    /// sub-pixel translation) are registered within 1 px and 0.5 degrees.
    ///
    /// The angle bound is close to what the copy keeps: the copy is resampled cell by cell,
    /// so a map about 100 cells across turned by less than about 0.5 degrees from a quarter
    /// turn is, cell for cell, that quarter turn with a step or two. At 100 cases per seed
    /// (`MAPMERGE_PROPTEST_SEED=S PROPTEST_CASES=100`), seeds 1-20 pass; before the polish
    /// of clean answers and the higher probe bar (2026-12-01) seeds 5, 11 and 14 failed, and
    /// with the polish's narrower kernel of that afternoon (0.5 px) seed 14 still did (one
    /// copy 0.52 degrees off).
    #[test]
    fn random_rigid_copies_are_recovered(
        (map, _, _) in map_pair(PairParams { size: 200..=280, noise: 0.0..=0.1, beams: vec![360], ..PairParams::default() }),
        theta in -std::f64::consts::PI..std::f64::consts::PI,
        tx in 0.0..1.0f64,
        ty in 0.0..1.0f64,
    ) {
        // B = A turned about its centre by theta and shifted by a sub-pixel amount, on a canvas
        // large enough to hold it.
        let (w, h) = (map.width() as f64, map.height() as f64);
        let side = (w * w + h * h).sqrt().ceil() as usize + 4;
        let c_a = grid_core::DVec2::new(w / 2.0, h / 2.0);
        let c_b = grid_core::DVec2::splat(side as f64 / 2.0) + grid_core::DVec2::new(tx, ty);
        // truth maps B onto A: rotate by theta about B's centre, land on A's centre.
        let t = c_a - grid_core::DVec2::from_angle(theta).rotate(c_b);
        let truth = Rigid2::new(theta, t.x, t.y);
        let b = map.warp(&truth.inverse(), side, side).unwrap();
        let r = register(&map, &b, &RegisterConfig::default()).unwrap();
        let est = r.accepted.as_ref().map(|c| c.transform);
        prop_assert!(est.is_some(), "declined: {:?}", r.reason);
        let est = est.unwrap();
        let rot_err = rotation_error_deg(&est, &truth);
        let disp = displacement_error(&b, &est, &truth).unwrap();
        prop_assert!(rot_err < 0.5, "rotation error {rot_err}");
        prop_assert!(disp < 1.0, "displacement error {disp}");
    }

    /// Two robots' partial maps with a large overlap and mild noise: an accepted answer is
    /// within the success bound of the conventions (3 px). Small sparse worlds may be declined
    /// as ambiguous (success rates are measured by `cargo xtask eval`); a confident wrong
    /// answer is the failure this property rules out.
    ///
    /// Known to fail: proptest finds small indoor maps (about 120 x 190 cells) with repeated
    /// rooms where a placement tens of pixels off fits the walls as well as the truth (wall lift
    /// 0.80-0.88, acceptance index 0.97-0.99, overlap 0.86-0.95) and is accepted. The case of
    /// 2026-12-01 that was the truth turned by 180 degrees (83 px off, from the global search)
    /// no longer fails: the symmetry probes propose the turned twin. Proptest then found
    /// others, 52 and 85 px off, RANSAC answers at wall lift 0.80-0.83, above the bar that
    /// skipped the sweep and the probes. Since the probes run up to wall lift 0.9
    /// (`PairConfig::symmetry_confident_wall_lift`, eab2248), the first failure is a sweep
    /// answer 74 px off at wall lift 0.93: the truth turned by half a turn, B being a bare
    /// room with a small notch. The truth fits better (wall lift 0.95) but overlaps less (61 %
    /// of the smaller map against 83 %, so it scores 155 against 351), and the probe at its
    /// angle refines to placements 42-57 px off that overlap more, so no rival near the truth
    /// is found (docs/EVALUATION.md, "Tried on 2026-12-01, night").
    /// On 2026-12-02 the failure proptest shrinks to (from the regressions file) is a
    /// square room: the answer is the truth turned by half a turn (91 px off, wall lift 0.88,
    /// contradiction 0.04, 86 % overlap) and the truth fits worse (wall lift 0.78,
    /// contradiction 0.14, 61 % overlap), so no rule that prefers the better fit can pick it
    /// (docs/EVALUATION.md, "Tried on 2026-12-02, 05:00-07:10 UTC").
    /// Since the sweep keeps lesser peaks (4b67d94) it shrinks to a 194 x 187 and a 200 x 244
    /// map instead: again the answer is the truth turned by half a turn (115.7 px off, wall
    /// lift 0.83, contradiction 0.10, 93 % overlap), and no candidate at the truth's angle
    /// comes within 40 px of it.
    /// On 2026-12-02 afternoon (2799128, and as well with `VerifyConfig::basin_ratio` 0, so
    /// not from the basin rule) the first failure is a 154 x 187 and a 182 x 165 map, the
    /// answer again the truth turned by half a turn (76.1 px off, wall lift 0.82,
    /// contradiction 0.04, acceptance index 0.98, 77 % overlap). With the walls' shadow compared
    /// (`VerifyConfig::shadow_px`, 2026-12-03) the first failure is an answer 78.0 px off at
    /// wall lift 0.86.
    /// Those failing cases are kept in `properties.proptest-regressions`, which proptest runs
    /// first, and all three pass since; so do the 8 cases of the fixed seed, and this test,
    /// ignored until 2026-12-05, runs with the others. It still fails elsewhere (measured
    /// 2026-12-05 evening, 13809db): at 40 cases (`MAPMERGE_PROPTEST_SEED=S PROPTEST_CASES=40
    /// cargo test -p mapmerge --test properties overlapping`) seeds 1, 2, 3, 5 and 7 pass and
    /// seed 6 fails with an answer 5.3 px off; at 100 cases seed 4 fails on a 157 x 141 room
    /// whose answer is the truth's half-turn twin, 91 px off (wall lift 0.87, contradiction
    /// 0.03). There the truth fits better (refined: wall lift 0.89, contradiction 0), so as a
    /// candidate it would have made the pair ambiguous and declined; but no candidate came
    /// within 10 px of it: the sweep's and the probes' placements at its angle sit 11-14 px
    /// away and refine to a poorer fit (wall lift 0.64), and the local search, even over
    /// +-24 px instead of 8 (scratch code), stays at the probe's placement, whose walls it
    /// scores higher than the truth's: that placement overlaps more.
    /// How often, measured 2026-12-07 (registration code of a33b381; `cargo run --release -p
    /// mapmerge --example property_pairs -- S 100`, which draws this strategy's pairs at
    /// proptest seed S, for S = 1, 3 and 7): 259 of 300 accepted, 5 of them wrong (73-127 px
    /// off at wall lift 0.90-0.96), 41 declined. All five are the truth
    /// turned by a half turn (four) or a quarter turn (one), laying B over 81-99 % of the
    /// smaller map where the truth overlaps 60-76 %: the truth, refined, fits at wall lift
    /// 0.85-0.96 but compares a third to three fifths as many walls, so it scores 0.3-0.6 of
    /// the answer (scratch code from here on). In four of them no candidate came within 14 px
    /// of the truth; in the fifth
    /// a probe's twin 1.0 px from it fitted at wide lift 1.00 against the answer's 0.96, yet
    /// scored 0.58 of it, under the ambiguity test's bar (`VerifyConfig::max_ambiguity`, 0.6).
    /// The quarter-turn answer was the only candidate: a RANSAC answer at wall lift 0.96,
    /// above the lift from which neither the sweep nor the symmetry probes run. Probing every
    /// answer (`PairConfig::symmetry_confident_wall_lift` 1.01, a local build of the example)
    /// declined it and one right answer, and left the four half turns as they were.
    /// With `MAPMERGE_PROPTEST_SEED=S PROPTEST_CASES=100` the test fails at seeds 1, 3, 4, 6,
    /// 7, 8 and 9 and passes at 2 and 5 (the macro draws other cases than the count above).
    /// A run that fails adds its case to the regressions file; keep it out of a commit
    /// unless the case passes.
    #[test]
    fn overlapping_robot_maps_are_registered(
        (a, b, truth) in map_pair(PairParams { size: 250..=320, overlap: 0.6..=0.8, noise: 0.0..=0.05, beams: vec![360], worlds: Worlds::Both, ..PairParams::default() }),
    ) {
        let r = register(&a, &b, &RegisterConfig::default()).unwrap();
        if let Some(c) = &r.accepted {
            let disp = displacement_error(&b, &c.transform, &truth).unwrap();
            prop_assert!(disp <= 3.0, "displacement error {disp}: {:?}", r.candidates);
        }
    }
}
