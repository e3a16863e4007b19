//! Where the rotation sweep ranks the placement near the truth: for each case that `cargo
//! xtask eval --export DIR` (or `cargo xtask gen`) wrote, the rank of the first placement
//! within 15 px and 4 degrees of the truth in each of the sweep's four rankings (plain and
//! normalised, B's walls over A's field and A's over B's), that placement once searched as
//! the screens search it (how far from the truth, its wall lift, whether it passes), and how
//! many placements of the normalised rankings pass once searched down to the depth asked.
//!
//! ```sh
//! cargo xtask eval --suites floors --only "uos_cic world, overlap 0.3" --seed 7 --export /tmp/cic
//! cargo run --release -p mapmerge --example sweep_ranks -- 1000 /tmp/cic/*/case_7002004
//! ```
//!
//! Arguments: the depth of the normalised rankings (how many placements are taken from each,
//! as `SweepConfig::deep_screened` takes them; the plain rankings keep their
//! `SweepConfig::keep`), then one or more case folders (`robot_0.yaml`, `robot_1.yaml` and
//! `truth.json`; the pair is robot 1 onto robot 0). The maps are framed, prepared, swept and
//! searched with the default settings, as `mapmerge::register` does; "near" is measured at
//! the centre of B's known cells, the error of a searched placement over all of them (the
//! displacement error of `../shared/CONVENTIONS.md`).

use std::path::Path;
use std::process::ExitCode;

use grid_core::io::{LoadOptions, load_map};
use grid_core::metrics::displacement_error;
use grid_core::{DVec2, OccupancyGrid, Rigid2, wrap_angle};
use mapmerge::RegisterConfig;
use mapmerge::global::sweep_placements;
use mapmerge::search::local_search;
use mapmerge::verify::{PreparedMap, verify};

/// A placement "near" the truth: B's known centre within this many pixels of where the truth
/// puts it, and the angle within [`NEAR_DEG`].
const NEAR_PX: f64 = 15.0;
/// See [`NEAR_PX`].
const NEAR_DEG: f64 = 4.0;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let depth = args.first().and_then(|s| s.parse::<usize>().ok());
    let (Some(depth), true) = (depth, args.len() >= 2) else {
        eprintln!("usage: sweep_ranks DEPTH CASE_DIR... (DEPTH a whole number, e.g. 1000)");
        return ExitCode::from(2);
    };
    let mut status = ExitCode::SUCCESS;
    for dir in &args[1..] {
        if let Err(e) = report(Path::new(dir), depth) {
            eprintln!("{dir}: {e}");
            status = ExitCode::FAILURE;
        }
    }
    status
}

/// The truth of a case folder's pair 0 -> 1 (robot 1's pixels onto robot 0's).
fn truth(dir: &Path) -> Result<Rigid2, String> {
    let path = dir.join("truth.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let pair = json["pairs"]
        .as_array()
        .and_then(|pairs| pairs.iter().find(|p| p["a"] == 0 && p["b"] == 1))
        .ok_or_else(|| format!("{}: no pair with a 0 and b 1", path.display()))?;
    serde_json::from_value(pair["transform"].clone())
        .map_err(|e| format!("{}: the pair's transform: {e}", path.display()))
}

fn report(dir: &Path, depth: usize) -> Result<(), String> {
    let load = |name: &str| {
        let path = dir.join(name);
        load_map(&path, &LoadOptions::default()).map_err(|e| format!("{}: {e}", path.display()))
    };
    let (a, b) = (load("robot_0.yaml")?, load("robot_1.yaml")?);
    let truth = truth(dir)?;
    let config = RegisterConfig::default().pair;
    let sweep = config.sweep.ok_or("the default settings sweep")?;
    // Framed as `register` frames them; placements are found between the frames and
    // reported between the maps.
    let frame = |g: &OccupancyGrid| config.frame(g).unwrap_or_else(|| (g.clone(), DVec2::ZERO));
    let ((fa, oa), (fb, ob)) = (frame(&a), frame(&b));
    let (pa, pb) = (
        PreparedMap::new(&fa, &config.verify),
        PreparedMap::new(&fb, &config.verify),
    );
    let unframed = |t: &Rigid2| mapmerge::unframed(t, oa, ob);
    // Where the screens' local search moves a placement, and how that pose verifies (as
    // `register`'s screens do).
    let searched = |t: &Rigid2| {
        let moved = config
            .search
            .as_ref()
            .map_or(*t, |sc| local_search(&pa, &pb, t, sc));
        (moved, verify(&pa, &pb, &moved, &config.verify))
    };
    let centre = b.known_centroid().ok_or("map B has no known cell")?;
    let near = |t: &Rigid2| {
        wrap_angle(t.theta - truth.theta).abs() <= NEAR_DEG.to_radians()
            && (t.apply(centre) - truth.apply(centre)).length() <= NEAR_PX
    };
    println!("{}", dir.display());
    for reverse in [false, true] {
        let (field, moving) = if reverse { (&pb, &pa) } else { (&pa, &pb) };
        let found = sweep_placements(field, moving, &sweep, depth);
        // As maps of B's frame onto A's.
        let onto_a = |ts: &[Rigid2]| -> Vec<Rigid2> {
            ts.iter()
                .map(|t| {
                    if reverse {
                        t.inverse().normalized()
                    } else {
                        *t
                    }
                })
                .collect()
        };
        let way = if reverse { "A over B" } else { "B over A" };
        for (ranking, placements) in [
            ("plain", onto_a(&found.plain)),
            ("normalised", onto_a(&found.normalized)),
        ] {
            let first = placements.iter().position(|t| near(&unframed(t)));
            let Some(i) = first else {
                println!(
                    "  {way}, {ranking}: none near the truth among {}",
                    placements.len()
                );
                continue;
            };
            let (moved, v) = searched(&placements[i]);
            let error = displacement_error(&b, &unframed(&moved), &truth).unwrap_or(f64::NAN);
            println!(
                "  {way}, {ranking}: near the truth {} of {}; searched {error:.2} px off, \
                 wall lift {:.3}, {}",
                i + 1,
                placements.len(),
                v.wall_lift,
                if v.accepted(&config.verify) {
                    "passes"
                } else {
                    "fails"
                },
            );
        }
        let passing = onto_a(&found.normalized)
            .iter()
            .filter(|t| searched(t).1.accepted(&config.verify))
            .count();
        println!(
            "  {way}: {passing} of the normalised ranking's {} pass once searched",
            found.normalized.len()
        );
    }
    Ok(())
}
