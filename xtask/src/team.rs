//! `cargo xtask team`: how well `mapmerge merge` places every map of a simulated robot team.
//!
//! Each case is a mapsim team of 3 or 4 lidar robots (mapsim's default sensor: 360 beams,
//! range 80 cells, 2 % range noise unless `--noise` says otherwise) whose consecutive robots'
//! explored areas overlap by the requested fraction (robots further apart in the tour may share
//! little or nothing). Every map is merged into the first map's frame with
//! `mapmerge::team::merge_team`, and each map's pose is judged against the truth as a pair's
//! answer is: placed within 3 px (mean displacement over its known cells) or not. Two ways of
//! placing the maps are reported from the same registrations: the pose graph (`merge_team`'s
//! answer) and the star a pairwise tool gives, each map registered onto the first alone.

use std::time::Instant;

use anyhow::Result;
use grid_core::metrics::displacement_error;
use grid_core::{OccupancyGrid, Rigid2};
use indicatif::{ProgressBar, ProgressStyle};
use mapmerge::team::{TeamConfig, merge_team};
use mapsim::{CaseConfig, RobotConfig, WorldConfig, WorldKind, generate_case};

/// Arguments of `cargo xtask team`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Cases per row
    #[arg(long, default_value_t = 10)]
    pub cases: usize,
    /// Seed of the first case (case k of the team of n robots in world w, 0 disaster or 1
    /// indoor, uses seed * 1000000 + (10 w + n) * 1000 + k: a row's cases do not depend on
    /// which other rows run)
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Overlap of consecutive robots' explored areas, as a fraction of the smaller
    #[arg(long, default_value_t = 0.5, value_parser = crate::eval::fraction::<f64>)]
    pub overlap: f64,
    /// Team sizes, comma separated
    #[arg(long, value_delimiter = ',', default_value = "3,4")]
    pub robots: Vec<usize>,
    /// World size in cells
    #[arg(long, default_value_t = 400)]
    pub size: usize,
    /// Use the spanning tree's poses only, without the least-squares refinement over loops
    #[arg(long)]
    pub no_refine: bool,
    /// Use an accepted pair in the pose graph only at this wall lift or more [default: that
    /// of `mapmerge merge`, `TeamConfig::min_edge_lift`, 0.75]
    #[arg(long, value_parser = crate::eval::non_negative::<f64>)]
    pub min_edge_lift: Option<f64>,
    /// After the table, list every map not placed within 3 px, with each pair's outcome: its
    /// error against the truth and what the pose graph made of it
    #[arg(long)]
    pub list: bool,
    /// How each robot folds its beams into its map (see `cargo xtask gen --help`); row labels
    /// name a mapper other than the default
    #[arg(long, value_enum, default_value = "default")]
    pub mapper: crate::r#gen::Mapper,
    /// Every robot's range noise bound, as a fraction (e.g. 0.1) [default: mapsim's lidar's,
    /// 0.02]; row labels name it when set
    #[arg(long, value_parser = crate::eval::noise_value)]
    pub noise: Option<f64>,
}

/// Overlap (of the smaller map) from which a pair counts as linking two maps in the truth.
const LINKED_OVERLAP: f64 = 0.15;

/// Per map, whether a chain of pairs overlapping by [`LINKED_OVERLAP`] or more links it to map
/// 0.
fn linked_to_first(overlaps: &[Vec<f64>]) -> Vec<bool> {
    let n = overlaps.len();
    let mut linked = vec![false; n];
    linked[0] = true;
    let mut grew = true;
    while grew {
        grew = false;
        for a in 0..n {
            for b in 0..n {
                if linked[a] && !linked[b] && overlaps[a][b] >= LINKED_OVERLAP {
                    linked[b] = true;
                    grew = true;
                }
            }
        }
    }
    linked
}

/// Counts of one row.
#[derive(Debug, Default)]
struct Tally {
    cases: usize,
    failed_to_generate: usize,
    /// Maps other than the first, over the generated cases.
    maps: usize,
    /// Of those, the maps the truth links to the first by a chain of pairs that overlap by
    /// [`LINKED_OVERLAP`] or more: the most any merge can place.
    linked: usize,
    /// Of those, placed by the pose graph / within 3 px / more than 3 px off.
    placed: usize,
    right: usize,
    wrong: usize,
    /// Cases whose every map the pose graph placed within 3 px.
    all_right: usize,
    /// The same counts for the star (each map registered onto the first alone).
    star_placed: usize,
    star_right: usize,
    star_all_right: usize,
    errors: Vec<f64>,
    ms: f64,
}

fn pct(n: usize, d: usize) -> String {
    if d == 0 {
        "-".into()
    } else {
        format!("{:.0}%", 100.0 * n as f64 / d as f64)
    }
}

/// Run `cargo xtask team`.
pub fn run(args: Args) -> Result<()> {
    anyhow::ensure!(
        args.robots.iter().all(|&n| (2..=8).contains(&n)),
        "--robots takes team sizes from 2 to 8"
    );
    let mut rows = Vec::new();
    let worlds = [
        ("disaster", WorldKind::Disaster),
        ("indoor", WorldKind::Indoor),
    ];
    for (w, (kind_name, kind)) in worlds.into_iter().enumerate() {
        for &n in &args.robots {
            let mut label = format!("{kind_name}, {n} robots");
            if args.mapper != crate::r#gen::Mapper::Default {
                label.push_str(&format!(", {} mapper", args.mapper.name()));
            }
            if let Some(b) = args.noise {
                label.push_str(&format!(", noise {}%", 100.0 * b));
            }
            rows.push((label, kind.clone(), n, 10 * w + n));
        }
    }
    let robot = RobotConfig {
        noise_bound: args.noise.unwrap_or(RobotConfig::default().noise_bound),
        ..RobotConfig::default()
    };
    let bar = ProgressBar::new((rows.len() * args.cases) as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} teams")
            .expect("static template")
            .progress_chars("=> "),
    );
    let mut config = TeamConfig::default();
    config.poses.refine = !args.no_refine;
    if let Some(lift) = args.min_edge_lift {
        config.min_edge_lift = lift;
    }
    let mut out = String::new();
    let mut listing = String::new();
    let mut totals = Tally::default();
    out.push_str(
        "| team | cases | maps linked to the first in the truth | maps placed | within 3 px | placed > 3 px off | teams all within 3 px | star: within 3 px | star: placed > 3 px off | star: teams all within 3 px | median error (px) | mean time (ms) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (label, kind, n, row_id) in &rows {
        let mut t = Tally::default();
        for k in 0..args.cases {
            let seed = args.seed * 1_000_000 + *row_id as u64 * 1000 + k as u64;
            let case_config = CaseConfig {
                world: WorldConfig {
                    kind: kind.clone(),
                    width: args.size,
                    height: args.size,
                    ..WorldConfig::default()
                },
                robots: vec![robot.clone(); *n],
                overlap: args.overlap,
                overlap_tolerance: f64::INFINITY,
                mapper: args.mapper.model(),
                ..CaseConfig::default()
            };
            bar.inc(1);
            let Ok(case) = generate_case(&case_config, seed) else {
                t.failed_to_generate += 1;
                continue;
            };
            t.cases += 1;
            let grids: Vec<&OccupancyGrid> = case.robots.iter().map(|r| &r.map).collect();
            let weights = vec![1.0; grids.len()];
            let start = Instant::now();
            let merged = merge_team(&grids, &weights, &config, &|| {})?;
            t.ms += start.elapsed().as_secs_f64() * 1e3;
            let error = |j: usize, pose: &Rigid2| {
                displacement_error(grids[j], pose, &case.truth(0, j)).unwrap_or(f64::INFINITY)
            };
            let (mut all, mut star_all) = (true, true);
            t.linked += linked_to_first(&case.overlaps)[1..]
                .iter()
                .filter(|&&l| l)
                .count();
            for j in 1..*n {
                t.maps += 1;
                match merged.poses.poses[j] {
                    Some(p) => {
                        t.placed += 1;
                        let e = error(j, &p);
                        t.errors.push(e);
                        if e <= 3.0 {
                            t.right += 1;
                        } else {
                            t.wrong += 1;
                            all = false;
                        }
                    }
                    None => all = false,
                }
                // The star: pair (0, j) alone.
                let star = merged
                    .pairs
                    .iter()
                    .find(|p| p.a == 0 && p.b == j)
                    .and_then(|p| p.registration.accepted.as_ref())
                    .map(|c| c.transform);
                match star {
                    Some(p) => {
                        t.star_placed += 1;
                        if error(j, &p) <= 3.0 {
                            t.star_right += 1;
                        } else {
                            star_all = false;
                        }
                    }
                    None => star_all = false,
                }
            }
            if args.list && !all {
                listing.push_str(&format!("{label}, case {seed}:"));
                for j in 1..*n {
                    let e = merged.poses.poses[j].map(|p| error(j, &p));
                    listing.push_str(&format!(
                        " map {j} {};",
                        e.map_or("not placed".into(), |e| format!("{e:.2} px"))
                    ));
                }
                listing.push('\n');
                for p in &merged.pairs {
                    let what = match (&p.registration.accepted, p.edge) {
                        (Some(c), Some(e)) => format!(
                            "{:?}, lift {:.2}, {:.2} px off",
                            merged.poses.status[e],
                            c.verification.wall_lift,
                            displacement_error(grids[p.b], &c.transform, &case.truth(p.a, p.b))
                                .unwrap_or(f64::INFINITY)
                        ),
                        (Some(c), None) => format!(
                            "weak (lift {:.2}, below the bar), {:.2} px off",
                            c.verification.wall_lift,
                            displacement_error(grids[p.b], &c.transform, &case.truth(p.a, p.b))
                                .unwrap_or(f64::INFINITY)
                        ),
                        (None, _) => "declined".into(),
                    };
                    listing.push_str(&format!(
                        "    pair ({}, {}), overlap {:.2}: {what}\n",
                        p.a, p.b, case.overlaps[p.a][p.b]
                    ));
                }
            }
            t.all_right += usize::from(all);
            t.star_all_right += usize::from(star_all);
        }
        totals.maps += t.maps;
        totals.right += t.right;
        totals.wrong += t.wrong;
        totals.star_right += t.star_right;
        totals.star_placed += t.star_placed;
        t.errors.sort_by(f64::total_cmp);
        let median = t
            .errors
            .get(t.errors.len() / 2)
            .map_or("-".into(), |e| format!("{e:.2}"));
        let cases = if t.failed_to_generate > 0 {
            format!("{} ({} failed to generate)", t.cases, t.failed_to_generate)
        } else {
            t.cases.to_string()
        };
        out.push_str(&format!(
            "| {label}, overlap {} | {cases} | {} | {} | {} | {} | {} | {} | {} | {} | {median} | {:.0} |\n",
            args.overlap,
            pct(t.linked, t.maps),
            pct(t.placed, t.maps),
            pct(t.right, t.maps),
            pct(t.wrong, t.maps),
            pct(t.all_right, t.cases),
            pct(t.star_right, t.maps),
            pct(t.star_placed - t.star_right, t.maps),
            pct(t.star_all_right, t.cases),
            t.ms / t.cases.max(1) as f64,
        ));
    }
    bar.finish_and_clear();
    out.push_str(&format!(
        "\nAll rows: {} maps besides the first ones; {} placed within 3 px, {} placed more than 3 px off (the star: {} and {}).\n",
        totals.maps,
        totals.right,
        totals.wrong,
        totals.star_right,
        totals.star_placed - totals.star_right
    ));
    crate::emit(&format!("{out}{listing}"))
}
