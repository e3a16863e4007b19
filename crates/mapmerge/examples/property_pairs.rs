//! Register many pairs drawn as the property test `overlapping_robot_maps_are_registered`
//! (`tests/properties.rs`) draws them, and count what a property test stops at the first of:
//! the answers within 3 px, those off (each listed), the declines, and what the runner-up
//! (`Registration::runner_up`) says about each.
//!
//! ```sh
//! cargo run --release -p mapmerge --example property_pairs -- 7 100
//! ```
//!
//! Arguments: the proptest seed (default 7) and the number of pairs (default 100). The pairs
//! come from a `TestRunner` with that fixed seed, one after another, not from the
//! `proptest!` macro's runner: the same distribution, other draws than the test's.

use std::process::ExitCode;

use grid_core::metrics::displacement_error;
use grid_core::wrap_angle;
use mapmerge::{RegisterConfig, register};
use mapsim::strategies::{PairParams, Worlds, map_pair};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, RngSeed, TestRunner};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let mut number = |default: u64| -> Option<u64> {
        match args.next() {
            None => Some(default),
            Some(s) => s.parse().ok(),
        }
    };
    let (Some(seed), Some(count)) = (number(7), number(100)) else {
        eprintln!("usage: property_pairs [SEED] [COUNT] (whole numbers)");
        return ExitCode::from(2);
    };
    // The property test's strategy (tests/properties.rs).
    let strategy = map_pair(PairParams {
        size: 250..=320,
        overlap: 0.6..=0.8,
        noise: 0.0..=0.05,
        beams: vec![360],
        worlds: Worlds::Both,
        ..PairParams::default()
    });
    let mut runner = TestRunner::new(Config {
        rng_seed: RngSeed::Fixed(seed),
        ..Config::default()
    });
    let config = RegisterConfig::default();
    let distinct_px = config.pair.verify.distinct_px;
    let (mut right, mut off, mut declined, mut failed) = (0, 0, 0, 0);
    let (mut right_with_up, mut right_with_passing_up) = (0, 0);
    for case in 0..count {
        let Ok(tree) = strategy.new_tree(&mut runner) else {
            failed += 1;
            continue;
        };
        let (a, b, truth) = tree.current();
        let r = match register(&a, &b, &config) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("case {case}: {e}");
                return ExitCode::from(1);
            }
        };
        let Some(answer) = &r.accepted else {
            declined += 1;
            continue;
        };
        let error = displacement_error(&b, &answer.transform, &truth).unwrap_or(f64::INFINITY);
        let up = r.runner_up(&b, distinct_px);
        if error <= 3.0 {
            right += 1;
            if let Some(u) = &up {
                right_with_up += 1;
                right_with_passing_up += usize::from(u.candidate.accepted);
            }
            continue;
        }
        off += 1;
        let v = &answer.verification;
        print!(
            "case {case}: {error:.1} px off, turned {:.1} deg from the truth, wall lift {:.2}, overlap {:.0} % of the smaller map",
            wrap_angle(answer.transform.theta - truth.theta).to_degrees(),
            v.wall_lift,
            100.0 * v.overlap_fraction
        );
        match &up {
            Some(u) => println!(
                "; runner-up {:.1} px from the truth, {} the bars, score {:.2} of the answer's",
                displacement_error(&b, &u.candidate.transform, &truth).unwrap_or(f64::INFINITY),
                if u.candidate.accepted {
                    "passing"
                } else {
                    "below"
                },
                u.score_ratio
            ),
            None => println!("; no runner-up ({} candidates)", r.candidates.len()),
        }
    }
    println!(
        "seed {seed}: {count} pairs, {right} within 3 px ({right_with_up} with a runner-up, \
         {right_with_passing_up} of them passing the bars), {off} off, {declined} declined, \
         {failed} failed to generate"
    );
    ExitCode::SUCCESS
}
