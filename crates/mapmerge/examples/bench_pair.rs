//! Register one of the bench pairs of `benches/register.rs` a few times, each run's time and
//! stage timings on its own line: one process per pair, for a profiler.
//!
//! ```sh
//! cargo run --release -p mapmerge --example bench_pair -- partial 5
//! valgrind --tool=callgrind target/release/examples/bench_pair warehouse 1
//! ```
//!
//! Pairs: `cic` (`end_to_end`), `warehouse`, `crops` (`end_to_end_overlapping_crops`),
//! `partial` (`end_to_end_partial_maps`, the hard pair), `declined`
//! (`end_to_end_partial_maps_declined`) and `declined-deep` (the same with the deep screen on,
//! `end_to_end_partial_maps_declined_deep_screen`). The count of runs defaults to 5. Set
//! `RAYON_NUM_THREADS=1` for a profile of one thread. Instruction counts (callgrind) do not
//! depend on the machine's load, unlike times: the way to compare two builds on a shared
//! machine. Building the pair (loading, warping, simulating the partial maps) is outside the
//! runs but inside a profile of the whole process: compare whole-process counts only
//! between builds whose pair building did not change.

#[path = "../benches/pairs/mod.rs"]
mod pairs;

use std::process::ExitCode;
use std::time::Instant;

use mapmerge::{RegisterConfig, register};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_default();
    let (a, b) = match name.as_str() {
        "cic" => pairs::pair(),
        "warehouse" => pairs::warehouse_pair(),
        "crops" => pairs::overlapping_crops(),
        "partial" => pairs::partial_pair(0.5),
        "declined" | "declined-deep" => pairs::partial_pair(0.0),
        _ => {
            eprintln!(
                "usage: bench_pair cic|warehouse|crops|partial|declined|declined-deep [RUNS]"
            );
            return ExitCode::from(2);
        }
    };
    let runs = match args.next().map(|n| n.parse::<usize>()) {
        None => 5,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("RUNS must be a whole number above 0");
            return ExitCode::from(2);
        }
    };
    let mut config = RegisterConfig::default();
    if name == "declined-deep"
        && let Some(sweep) = config.pair.sweep.as_mut()
    {
        // As `mapmerge --deep-screen` sets it.
        sweep.deep_screened = 1000;
    }
    for _ in 0..runs {
        let t = Instant::now();
        let answer = register(&a, &b, &config).expect("the default settings are valid");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let s = &answer.timings;
        let placed = answer.accepted.map_or_else(
            || "declined".to_string(),
            |c| {
                let t = c.transform;
                format!("theta {:.6} tx {:.3} ty {:.3}", t.theta, t.tx, t.ty)
            },
        );
        println!(
            "{ms:.1} ms: correspondences {:.1} | prepare {:.1}, ransac {:.1}, verify {:.1}, \
             sweep {:.1}, symmetry {:.1}, ascent {:.1}; {placed}",
            s.correspondences_ms,
            s.prepare_ms,
            s.ransac_ms,
            s.verify_ms,
            s.sweep_ms,
            s.symmetry_ms,
            s.ascent_ms,
        );
    }
    ExitCode::SUCCESS
}
