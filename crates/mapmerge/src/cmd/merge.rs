//! `mapmerge merge MAP MAP... -o OUT.yaml`: register every pair of maps, solve one pose per map
//! in the reference map's frame (the first, or `--reference`), fuse the maps into one, and
//! report every map's pose.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use fusion::{EdgeStatus, FusedMap, FusionConfig, FusionRule};
use grid_core::io::{LoadedMap, image_path_for, save_map, write_atomic};
use grid_core::{CellState, GridGeometry, OccupancyGrid, Rigid2};
use mapmerge::team::{TeamConfig, TeamPair, merge_team};
use serde_json::{Value, json};

use super::{
    BareImageArgs, RegistrationArgs, UsageError, deep_screen_hint, load, refuse_overwriting,
    require_directory,
};

const AFTER: &str = "\
How it works: every pair of maps is registered as `mapmerge estimate` does (n maps: n(n-1)/2
pairs, in parallel). The pairs accepted at wall lift --min-lift or more form a graph; a
spanning tree of the answers that rest on the most agreeing walls (large overlaps first)
places every map it reaches in the reference map's frame (the first map, or --reference),
and the answers that close loops refine those poses by least squares (an answer that
disagrees with the tree by more than 3 degrees or 8 px is dropped as wrong). The placed maps
are then fused: where one map alone is known it keeps its cell; where several are, the cell
takes their occupancy probabilities' mean weighted by --weights (the paper's alpha * M1 +
beta * M2, alpha + beta = 1), or with --rule occupied-wins the wall any map saw.

Output:
  OUT.yaml + OUT.pgm  the merged map, as map_saver writes it (0 occupied, 254 free, 205
                      unknown), in the reference map's world frame: a point has the same
                      world coordinates in the merged map as in the reference map
  OUT.json            the report (also printed by --json):
    maps              per input: merged (true/false), weight, resolution, transform {theta,
                      tx, ty, scale} from its pixels to the merged map's pixels (x = column,
                      y = row from the top; x_out = scale R(theta) x + t, scale 1 unless the
                      map was resampled), world {x, y, yaw}: its map frame in the merged map's
                      frame (metres, yaw counter-clockwise), ready to publish as a TF; reason
                      when not merged
    pairs             per pair a < b: accepted, transform (b's pixels onto a's, both as
                      resampled to the merged map's resolution), confidence, status (tree,
                      loop, dropped, weak: accepted below --min-lift, declined, unreached),
                      residual of the final poses against the pair's answer (rotation_deg,
                      translation_px); reason when declined or weak, and hint when declined
                      with no placement passing, without --deep-screen
    acceptance_index  agree / (agree + disagree) over every two maps known at the same cell
    overlap_cells, output, timings_ms

The merged map has the reference map's resolution, or --output-resolution's. Maps of another
resolution are resampled to it (a note on stderr says so): a coarser cell takes the highest
occupancy of the cells it covers, a finer one repeats its cell.

A map that no such pair links to the reference map is left out (a warning on stderr says
so, naming its pair accepted below --min-lift with a placed map and the --min-lift that uses
it, or the chain of such pairs through other maps and the --min-lift that places it, or the
maps it does link to and the --reference that merges those) and the others are merged. When
no map links to the reference, nothing is written, and the reason gives the --min-lift that
would place every map the accepted pairs link to it.

Exit codes: 0 merged map written, 3 no map could be placed in the reference map's frame
(nothing written), 2 bad usage or bad input, 1 internal error.

Examples:
  mapmerge merge fixtures/maps/sunil_pair_a/sunil_pair_a.yaml fixtures/maps/sunil_pair_b/sunil_pair_b.yaml -o merged.yaml
  mapmerge merge robot1.yaml robot2.yaml robot3.yaml -o team.yaml --weights 1,1,0.5 --debug-png team.png
  mapmerge merge robot1.yaml robot2.yaml base.yaml -o team.yaml --reference base.yaml";

/// Arguments of `mapmerge merge`.
#[derive(Debug, Clone, Args)]
#[command(after_help = AFTER)]
pub struct MergeArgs {
    /// The maps (two or more: map_server YAMLs or bare .pgm/.png images). The first is the
    /// reference unless --reference names another: the merged map is in its frame (and at its
    /// resolution, unless --output-resolution says otherwise)
    #[arg(value_name = "MAP", num_args = 2.., required = true)]
    pub maps: Vec<PathBuf>,
    /// The merged map's YAML (.yaml or .yml); its PGM is written beside it with the same name
    /// and the report as OUT.json
    #[arg(short, long, value_name = "OUT.yaml")]
    pub output: PathBuf,
    /// Reliability of each map, in the order given, e.g. 1,0.5: overlapping cells take the mean
    /// weighted by them [default: all equal]
    #[arg(long, value_name = "W,W,...", value_delimiter = ',', value_parser = super::positive_finite)]
    pub weights: Option<Vec<f64>>,
    /// How overlapping cells are combined: mean (the reliability-weighted mean; a cell one map
    /// sees free and an equally reliable one occupied becomes unknown) or occupied-wins (a wall
    /// any map saw stays)
    #[arg(long, default_value = "mean", value_parser = parse_rule)]
    pub rule: FusionRule,
    /// A pair places maps only when accepted at this wall lift or more: a map placed wrong
    /// spoils the merged map, one left out is reported, with the bar that would place it
    /// when pairs accepted below this one link it; 0 uses every pair `estimate` accepts
    #[arg(long, value_name = "LIFT", default_value_t = 0.75, value_parser = super::probability)]
    pub min_lift: f64,
    /// The map whose frame the merged map is in (and whose resolution it has, unless
    /// --output-resolution says otherwise): one of the MAPs, as given [default: the first]
    #[arg(long, value_name = "MAP")]
    pub reference: Option<PathBuf>,
    /// Metres per cell of the merged map: every map of another resolution is resampled to it
    /// [default: the reference map's]
    #[arg(long, value_name = "M", value_parser = super::positive_finite)]
    pub output_resolution: Option<f64>,
    /// Print the report as one JSON object instead of text
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub registration: RegistrationArgs,
    /// Write a picture of the merged map: free white, unknown grey, walls in the colour of the
    /// one map that saw them (the first blue, then red, green, orange, purple, ...), black where
    /// two maps or more saw them
    #[arg(long, value_name = "FILE")]
    pub debug_png: Option<PathBuf>,
}

fn parse_rule(s: &str) -> Result<FusionRule, String> {
    s.parse()
}

/// The files `mapmerge merge` writes.
struct Outputs {
    yaml: PathBuf,
    image: PathBuf,
    report: PathBuf,
}

impl Outputs {
    fn new(yaml: &Path) -> anyhow::Result<Self> {
        let ext = yaml
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("yaml" | "yml")) {
            return Err(UsageError(format!(
                "{}: the output must be a .yaml or .yml file (its PGM and JSON report are \
                 written beside it)",
                yaml.display()
            ))
            .into());
        }
        Ok(Self {
            yaml: yaml.to_path_buf(),
            image: image_path_for(yaml),
            report: yaml.with_extension("json"),
        })
    }

    /// Every output with the flag that names it.
    fn all<'a>(&'a self, png: Option<&'a PathBuf>) -> Vec<(&'a Path, &'static str)> {
        let mut v = vec![
            (self.yaml.as_path(), "--output"),
            (self.image.as_path(), "--output's PGM"),
            (self.report.as_path(), "--output's JSON report"),
        ];
        if let Some(p) = png {
            v.push((p.as_path(), "--debug-png"));
        }
        v
    }
}

/// Run `mapmerge merge`.
pub fn run(args: &MergeArgs, bare: &BareImageArgs) -> anyhow::Result<ExitCode> {
    let start = Instant::now();
    let outputs = Outputs::new(&args.output)?;
    let written = outputs.all(args.debug_png.as_ref());
    for (out, flag) in &written {
        refuse_overwriting(out, flag, &args.maps)?;
        require_directory(out, flag)?;
    }
    if let Some(png) = &args.debug_png {
        // Compared as absolute paths, so that `./out.pgm` is seen to be `out.pgm`.
        let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        if written[..3]
            .iter()
            .any(|(out, _)| absolute(out) == absolute(png))
        {
            return Err(UsageError(format!(
                "{}: --debug-png names one of the merged map's own files; choose another",
                png.display()
            ))
            .into());
        }
    }
    let weights = match &args.weights {
        Some(w) if w.len() != args.maps.len() => {
            return Err(UsageError(format!(
                "--weights gives {} values for {} maps; give one per map, in the order of the maps",
                w.len(),
                args.maps.len()
            ))
            .into());
        }
        Some(w) => w.clone(),
        None => vec![1.0; args.maps.len()],
    };
    let reference = reference_index(args)?;
    let reference_path = &args.maps[reference];
    let (maps, own) = load_all(&args.maps, bare, reference, args.output_resolution)?;
    let resolution = maps[reference].grid.resolution();
    for (k, g) in own.iter().enumerate() {
        if !same_resolution(g.resolution, resolution) {
            let whose = match args.output_resolution {
                Some(_) => "the --output-resolution".to_string(),
                None => format!("the resolution of {}", reference_path.display()),
            };
            eprintln!(
                "mapmerge: note: {}: resampled from {} to {resolution} m/cell, {whose}",
                args.maps[k].display(),
                g.resolution,
            );
        }
    }
    for (out, flag) in &written {
        // A map given by its YAML is read from the image the YAML names.
        refuse_overwriting(out, flag, maps.iter().map(|m| &m.image_path))?;
    }

    let team = TeamConfig {
        register: args.registration.config(),
        fusion: FusionConfig {
            rule: args.rule,
            ..FusionConfig::default()
        },
        min_edge_lift: args.min_lift,
        reference,
        ..TeamConfig::default()
    };
    let grids: Vec<&OccupancyGrid> = maps.iter().map(|m| &m.grid).collect();
    let n_pairs = grids.len() * (grids.len() - 1) / 2;
    // Drawn on stderr, and only when it is a terminal: scripts and pipes see nothing.
    let bar = indicatif::ProgressBar::new(n_pairs as u64).with_style(
        indicatif::ProgressStyle::with_template(
            "registering pairs [{bar:30}] {pos}/{len} ({elapsed})",
        )
        .expect("a valid template")
        .progress_chars("=> "),
    );
    let merged = merge_team(&grids, &weights, &team, &|| bar.inc(1));
    bar.finish_and_clear();
    let merged = match merged {
        Ok(m) => m,
        Err(mapmerge::Error::Fusion(e)) => {
            return Err(UsageError(format!(
                "{}: cannot merge the maps: {e}",
                args.output.display()
            ))
            .into());
        }
        Err(e) => return Err(anyhow::Error::from(e).context("cannot merge the maps")),
    };
    let solution = &merged.poses;

    let mut report = json!({
        "reference": reference_path.display().to_string(),
        "rule": match args.rule {
            FusionRule::WeightedMean => "mean",
            FusionRule::OccupiedWins => "occupied-wins",
        },
        "method": args.registration.method,
        "seed": args.registration.seed,
        "pairs": merged.pairs.iter().map(|p| {
            pair_report(&args.maps, p, p.edge.map(|e| (solution.status[e], solution.residuals[e])), args)
        }).collect::<Vec<_>>(),
    });
    // Maps that the pairs link to each other but not to the reference: the user can merge
    // them by naming one of them the reference.
    let groups = linked_groups(args.maps.len(), &merged.pairs, &solution.status);
    let elsewhere = |k: usize| -> Option<String> {
        let group = &groups[k];
        (group.len() > 1 && !group.contains(&reference)).then(|| {
            format!(
                "{} link to each other: --reference {} merges them",
                names(&args.maps, group),
                args.maps[group[0]].display()
            )
        })
    };
    // The lowest bar that would link a map to the reference's maps, through pairs accepted
    // below --min-lift.
    let lifts: Vec<(usize, usize, f64)> = merged
        .pairs
        .iter()
        .filter_map(|p| {
            let lift = p.registration.accepted.as_ref()?.verification.wall_lift;
            Some((p.a, p.b, lift))
        })
        .collect();
    let chains = widest_chains(args.maps.len(), &lifts, &groups[reference]);
    let weak_way_in = |k: usize| -> Option<String> {
        let (lift, via) = chains[k]?;
        let bar = bar_at(lift);
        if groups[reference].contains(&via) {
            return Some(format!(
                "its pair with {} was accepted at wall lift {lift:.3}, below --min-lift {}: \
                 --min-lift {bar} uses it",
                args.maps[via].display(),
                args.min_lift,
            ));
        }
        // The maps between it and the reference's, nearest first.
        let mut between = Vec::new();
        let mut m = via;
        while !groups[reference].contains(&m) && between.len() < args.maps.len() {
            between.push(m);
            m = chains[m]?.1;
        }
        Some(format!(
            "pairs accepted at wall lift {lift:.3} or more link it to {} through {}: \
             --min-lift {bar} places it",
            args.maps[m].display(),
            names(&args.maps, &between),
        ))
    };
    let mut map_reports: Vec<Value> = args
        .maps
        .iter()
        .zip(&weights)
        .zip(&own)
        .enumerate()
        .map(|(k, ((path, w), g))| {
            let mut reason = if k == reference {
                "the reference map: no other map could be placed in its frame".to_string()
            } else {
                format!(
                    "no pair accepted at wall lift {} or more links it to {}",
                    args.min_lift,
                    reference_path.display()
                )
            };
            for hint in [weak_way_in(k), elsewhere(k)].into_iter().flatten() {
                reason.push_str(&format!("; {hint}"));
            }
            json!({
                "map": path.display().to_string(),
                "merged": false,
                "weight": w,
                "resolution": g.resolution,
                "transform": null,
                "world": null,
                "reason": reason,
            })
        })
        .collect();

    let Some(fused) = &merged.fused else {
        report["output"] = Value::Null;
        let weak = merged
            .pairs
            .iter()
            .any(|p| (p.a == reference || p.b == reference) && p.registration.accepted.is_some());
        let mut reason = format!(
            "no map could be placed in {}'s frame: {}",
            reference_path.display(),
            if weak {
                format!(
                    "no pair with it was accepted at wall lift {} or more",
                    args.min_lift
                )
            } else {
                "every pair with it was declined".to_string()
            }
        );
        // The bar that would place every map that accepted pairs link to the reference.
        let reached: Vec<f64> = chains.iter().flatten().map(|&(lift, _)| lift).collect();
        if let Some(lowest) = reached.iter().copied().reduce(f64::min) {
            let bar = bar_at(lowest);
            reason.push_str(&match reached.len() {
                1 => format!("; --min-lift {bar} places the map that accepted pairs link to it"),
                n => {
                    format!("; --min-lift {bar} places the {n} maps that accepted pairs link to it")
                }
            });
        }
        // The largest group of maps linked to each other, the earliest first on a tie.
        if let Some(hint) = (0..args.maps.len())
            .filter(|&k| groups[k][0] == k)
            .max_by_key(|&k| (groups[k].len(), std::cmp::Reverse(k)))
            .and_then(elsewhere)
        {
            reason.push_str(&format!("; {hint}"));
        }
        report["reason"] = json!(reason);
        report["maps"] = json!(map_reports);
        report["timings_ms"] = json!({"total": start.elapsed().as_secs_f64() * 1e3});
        print_report(args, &report)?;
        return Ok(ExitCode::from(3));
    };

    let out_geometry = fused.grid.geometry();
    for (slot, &k) in merged.placed.iter().enumerate() {
        let pose = fused.poses[slot];
        // Resampling keeps a map's origin, so its frame's pose is the resampled map's.
        let world = pose.to_world(&out_geometry, &maps[k].grid.geometry());
        let (t, scale) = own_pixels_transform(
            &pose,
            own[k].resolution,
            own[k].height,
            fused.grid.resolution(),
            maps[k].grid.height(),
        );
        map_reports[k] = json!({
            "map": args.maps[k].display().to_string(),
            "merged": true,
            "weight": weights[k],
            "resolution": own[k].resolution,
            "transform": {"theta": t.theta, "tx": t.tx, "ty": t.ty, "scale": scale},
            "world": {"x": world.tx, "y": world.ty, "yaw": world.theta},
        });
    }
    let counts = fused.grid.counts();
    let origin = fused.grid.origin();
    report["output"] = json!({
        "yaml": outputs.yaml.display().to_string(),
        "image": outputs.image.display().to_string(),
        "report": outputs.report.display().to_string(),
        "width": fused.grid.width(),
        "height": fused.grid.height(),
        "resolution": fused.grid.resolution(),
        "origin": [origin.x, origin.y, origin.yaw],
        "free": counts.free,
        "occupied": counts.occupied,
        "unknown": counts.unknown,
    });
    report["maps"] = json!(map_reports);
    report["acceptance_index"] = json!(fused.agreement.acceptance_index());
    report["overlap_cells"] = json!(fused.overlap_cells);
    report["timings_ms"] = json!({"total": start.elapsed().as_secs_f64() * 1e3});

    write_outputs(&outputs, fused, &report)?;
    if let Some(png) = &args.debug_png {
        write_picture(png, fused)?;
    }
    for (k, r) in map_reports.iter().enumerate() {
        if r["merged"] == false {
            eprintln!(
                "mapmerge: warning: {}: not merged: {}",
                args.maps[k].display(),
                r["reason"].as_str().unwrap_or("?")
            );
        }
    }
    print_report(args, &report)?;
    Ok(ExitCode::SUCCESS)
}

/// Per map, the maps that the pose graph's usable edges (every accepted pair at `--min-lift`
/// or more but those dropped as wrong) link it to, itself included, in index order.
fn linked_groups(n: usize, pairs: &[TeamPair], status: &[EdgeStatus]) -> Vec<Vec<usize>> {
    // Union-find, each group's root its smallest map.
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut k: usize) -> usize {
        while root[k] != k {
            root[k] = root[root[k]];
            k = root[k];
        }
        k
    }
    for p in pairs {
        if p.edge.is_some_and(|e| status[e] != EdgeStatus::Dropped) {
            let (ra, rb) = (find(&mut root, p.a), find(&mut root, p.b));
            root[ra.max(rb)] = ra.min(rb);
        }
    }
    let roots: Vec<usize> = (0..n).map(|k| find(&mut root, k)).collect();
    (0..n)
        .map(|k| (0..n).filter(|&j| roots[j] == roots[k]).collect())
        .collect()
}

/// The `--min-lift` that uses a pair accepted at wall lift `lift`: the lift rounded down to
/// hundredths, at least 0 (the flag's range).
fn bar_at(lift: f64) -> f64 {
    ((lift * 100.0).floor() / 100.0).max(0.0)
}

/// Per map outside `linked` (the maps placed with the reference), the highest `--min-lift` at
/// which accepted pairs would link it to them, and the map before it on that chain. Of every
/// chain of accepted pairs from a map of `linked` to it, the one whose lowest wall lift is
/// highest (the widest path) gives that lowest lift. `None` for the maps of `linked` and for
/// those that no chain of accepted pairs reaches.
///
/// `lifts` holds each accepted pair as `(a, b, wall lift)`.
fn widest_chains(
    n: usize,
    lifts: &[(usize, usize, f64)],
    linked: &[usize],
) -> Vec<Option<(f64, usize)>> {
    let mut best: Vec<Option<(f64, usize)>> = (0..n)
        .map(|k| linked.contains(&k).then_some((f64::INFINITY, k)))
        .collect();
    // Each pass can only raise a map's lowest lift, to one of the pairs' lifts: at most n
    // passes change anything.
    for _ in 0..n {
        let mut changed = false;
        for &(a, b, lift) in lifts {
            for (from, to) in [(a, b), (b, a)] {
                let Some((reach, _)) = best[from] else {
                    continue;
                };
                let reach = reach.min(lift);
                if best[to].is_none_or(|(old, _)| reach > old) {
                    best[to] = Some((reach, from));
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    for &k in linked {
        best[k] = None;
    }
    best
}

/// The maps `group` as a list in words: `a`, `a and b`, `a, b and c`.
fn names(paths: &[PathBuf], group: &[usize]) -> String {
    let all: Vec<String> = group
        .iter()
        .map(|&k| paths[k].display().to_string())
        .collect();
    match all.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => all.join(""),
    }
}

/// The index of `--reference` among the maps (0 without it): the map given by the same path,
/// or by another path to the same file.
fn reference_index(args: &MergeArgs) -> anyhow::Result<usize> {
    let Some(reference) = &args.reference else {
        return Ok(0);
    };
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    args.maps
        .iter()
        .position(|m| m == reference || absolute(m) == absolute(reference))
        .ok_or_else(|| {
            UsageError(format!(
                "{}: --reference must be one of the maps given",
                reference.display()
            ))
            .into()
        })
}

/// Load every map and check each has known cells. A map of another resolution than `output`
/// (by default that of map `reference`) is resampled to it ([`OccupancyGrid::resample`]); the
/// second value is each map's own geometry, as read.
fn load_all(
    paths: &[PathBuf],
    bare: &BareImageArgs,
    reference: usize,
    output: Option<f64>,
) -> anyhow::Result<(Vec<LoadedMap>, Vec<GridGeometry>)> {
    let mut maps = paths
        .iter()
        .map(|p| {
            let m = load(p, bare)?;
            grid_core::io::require_known_cells(&m.grid, p)?;
            Ok(m)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let own: Vec<GridGeometry> = maps.iter().map(|m| m.grid.geometry()).collect();
    let r0 = output.unwrap_or(own[reference].resolution);
    for (m, p) in maps.iter_mut().zip(paths) {
        if !same_resolution(m.grid.resolution(), r0) {
            m.grid = m
                .grid
                .resample(r0)
                .with_context(|| format!("{}: cannot resample it to {r0} m/cell", p.display()))?;
        }
    }
    Ok((maps, own))
}

/// Whether two resolutions are the same up to the rounding of a YAML's decimals.
fn same_resolution(r: f64, r0: f64) -> bool {
    ((r - r0) / r0).abs() <= 1e-6
}

/// The transform from the pixels of a map of `own` resolution and `height` rows to the merged
/// map's, given `pose` from the pixels of the map resampled to the merged map's resolution
/// (`resampled_height` rows): `x_out = scale R(theta) x + t`, with `scale` 1 when the map was
/// not resampled. Resampling keeps the lower-left corner, so the map's pixel `p` is the
/// resampled map's `s p + c` with `s = own / merged resolution`.
fn own_pixels_transform(
    pose: &Rigid2,
    own: f64,
    height: usize,
    merged: f64,
    resampled_height: usize,
) -> (Rigid2, f64) {
    if same_resolution(own, merged) {
        return (*pose, 1.0);
    }
    let s = own / merged;
    let c = grid_core::DVec2::new(
        0.5 * s - 0.5,
        resampled_height as f64 - 0.5 - (height as f64 - 0.5) * s,
    );
    let t = pose.apply(c);
    (Rigid2::new(pose.theta, t.x, t.y), s)
}

fn transform_json(t: &Rigid2) -> Value {
    json!({"theta": t.theta, "tx": t.tx, "ty": t.ty})
}

fn pair_report(
    paths: &[PathBuf],
    p: &TeamPair,
    edge: Option<(EdgeStatus, fusion::EdgeResidual)>,
    args: &MergeArgs,
) -> Value {
    let (r, min_lift) = (&p.registration, args.min_lift);
    let mut v = json!({
        "a": paths[p.a].display().to_string(),
        "b": paths[p.b].display().to_string(),
        "accepted": r.accepted.is_some(),
    });
    match (&r.accepted, edge) {
        (Some(c), None) => {
            v["transform"] = transform_json(&c.transform);
            v["confidence"] = json!(c.verification.wall_lift.clamp(0.0, 1.0));
            v["status"] = json!("weak");
            v["reason"] = json!(format!(
                "accepted at wall lift {:.2}, below --min-lift {min_lift}: not used to place maps",
                c.verification.wall_lift
            ));
        }
        (Some(c), Some((status, residual))) => {
            v["transform"] = transform_json(&c.transform);
            v["confidence"] = json!(c.verification.wall_lift.clamp(0.0, 1.0));
            v["status"] = json!(match status {
                EdgeStatus::Tree => "tree",
                EdgeStatus::Loop => "loop",
                EdgeStatus::Dropped => "dropped",
                EdgeStatus::Unreached => "unreached",
            });
            v["residual"] = json!({
                "rotation_deg": residual.rotation_deg,
                "translation_px": residual.translation_px,
            });
        }
        _ => {
            v["transform"] = Value::Null;
            v["status"] = json!("declined");
            v["reason"] = json!(
                r.reason
                    .clone()
                    .unwrap_or_else(|| "no trustworthy match".into())
            );
            if let Some(hint) = deep_screen_hint(&args.registration, r) {
                v["hint"] = json!(hint);
            }
        }
    }
    v
}

/// Write the merged map (PGM + YAML) and the report, each atomically. If the report cannot be
/// written, the map just written is removed, so that no half of a result is left behind.
fn write_outputs(outputs: &Outputs, fused: &FusedMap, report: &Value) -> anyhow::Result<()> {
    save_map(&fused.grid, &outputs.yaml).context("cannot write the merged map")?;
    let text = serde_json::to_string_pretty(report).context("cannot encode the report")?;
    if let Err(e) = write_atomic(&outputs.report, format!("{text}\n").as_bytes()) {
        let _ = std::fs::remove_file(&outputs.yaml);
        let _ = std::fs::remove_file(&outputs.image);
        return Err(e).context("cannot write the merge report");
    }
    Ok(())
}

fn print_report(args: &MergeArgs, report: &Value) -> anyhow::Result<()> {
    let mut stdout = std::io::stdout().lock();
    if args.json {
        writeln!(stdout, "{report}").context("cannot write to stdout")?;
    } else {
        human(&mut stdout, report).context("cannot write to stdout")?;
    }
    Ok(())
}

fn human(w: &mut impl Write, r: &Value) -> std::io::Result<()> {
    let maps = r["maps"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    let merged = maps.iter().filter(|m| m["merged"] == true).count();
    let o = &r["output"];
    if o.is_null() {
        writeln!(w, "nothing merged: {}", r["reason"].as_str().unwrap_or("?"))?;
    } else {
        writeln!(
            w,
            "merged {merged} of {} maps into {} ({}, {} x {} cells at {} m/cell); report {}",
            maps.len(),
            o["yaml"].as_str().unwrap_or("?"),
            o["image"].as_str().unwrap_or("?"),
            o["width"],
            o["height"],
            o["resolution"],
            o["report"].as_str().unwrap_or("?"),
        )?;
    }
    for m in maps {
        let name = m["map"].as_str().unwrap_or("?");
        if m["merged"] != true {
            writeln!(
                w,
                "  {name}: not merged: {}",
                m["reason"].as_str().unwrap_or("?")
            )?;
            continue;
        }
        let (t, wd) = (&m["transform"], &m["world"]);
        let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
        let scale = match t["scale"].as_f64() {
            Some(s) if s != 1.0 => format!(", scale {s}"),
            _ => String::new(),
        };
        writeln!(
            w,
            "  {name}{}: frame at x {:.3} m, y {:.3} m, yaw {:.3} deg (pixels: theta {:.3} deg, tx {:.2}, ty {:.2}{scale}), weight {}",
            if m["map"] == r["reference"] {
                " (reference)"
            } else {
                ""
            },
            f(&wd["x"]),
            f(&wd["y"]),
            f(&wd["yaw"]).to_degrees(),
            f(&t["theta"]).to_degrees(),
            f(&t["tx"]),
            f(&t["ty"]),
            m["weight"],
        )?;
    }
    for p in r["pairs"].as_array().map(Vec::as_slice).unwrap_or(&[]) {
        let (a, b) = (
            p["a"].as_str().unwrap_or("?"),
            p["b"].as_str().unwrap_or("?"),
        );
        if p["status"] == "weak" {
            writeln!(
                w,
                "  pair {a} + {b}: {}",
                p["reason"].as_str().unwrap_or("?")
            )?;
        } else if p["accepted"] == true {
            writeln!(
                w,
                "  pair {a} + {b}: accepted, confidence {:.2}, {} (residual {:.2} deg, {:.2} px)",
                p["confidence"].as_f64().unwrap_or(0.0),
                p["status"].as_str().unwrap_or("?"),
                p["residual"]["rotation_deg"].as_f64().unwrap_or(0.0),
                p["residual"]["translation_px"].as_f64().unwrap_or(0.0),
            )?;
        } else {
            writeln!(
                w,
                "  pair {a} + {b}: declined: {}",
                p["reason"].as_str().unwrap_or("?")
            )?;
        }
    }
    // One line for every pair that `--deep-screen` might answer (they share the text).
    let pairs = r["pairs"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    let hinted: Vec<&str> = pairs.iter().filter_map(|p| p["hint"].as_str()).collect();
    if let Some(hint) = hinted.first() {
        let n = hinted.len();
        writeln!(
            w,
            "hint ({n} declined pair{}): {hint}",
            if n == 1 { "" } else { "s" }
        )?;
    }
    if !o.is_null() {
        match r["acceptance_index"].as_f64() {
            Some(ai) => writeln!(
                w,
                "acceptance index {ai:.3} over {} cells known in two maps or more",
                r["overlap_cells"]
            )?,
            None => writeln!(w, "no cell is known in two maps")?,
        }
    }
    writeln!(
        w,
        "{:.0} ms",
        r["timings_ms"]["total"].as_f64().unwrap_or(0.0)
    )
}

/// Colours of the maps' walls in the picture, by input order (cycled past eight maps).
const PALETTE: [[u8; 3]; 8] = [
    [40, 80, 230],
    [230, 40, 40],
    [20, 160, 60],
    [240, 150, 20],
    [150, 60, 200],
    [20, 170, 190],
    [200, 60, 150],
    [130, 110, 40],
];

/// The merged map with each wall cell coloured by the maps that saw it.
fn write_picture(path: &Path, fused: &FusedMap) -> anyhow::Result<()> {
    let (w, h) = (fused.grid.width(), fused.grid.height());
    let mut img = image::RgbImage::new(w as u32, h as u32);
    for y in 0..h {
        for x in 0..w {
            let mut seen_by = fused
                .layers
                .iter()
                .enumerate()
                .filter(|(_, l)| l.state(x, y) == CellState::Occupied)
                .map(|(k, _)| k);
            let colour = match (seen_by.next(), seen_by.next()) {
                (Some(_), Some(_)) => [0, 0, 0],
                (Some(k), None) => PALETTE[k % PALETTE.len()],
                _ => match fused.grid.state(x, y) {
                    CellState::Free => [255, 255, 255],
                    CellState::Occupied => [0, 0, 0],
                    CellState::Unknown => [205, 205, 205],
                },
            };
            img.put_pixel(x as u32, y as u32, image::Rgb(colour));
        }
    }
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| anyhow::anyhow!("{}: cannot encode the picture: {e}", path.display()))?;
    write_atomic(path, &png).context("cannot write the picture")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_map_is_reached_by_the_chain_whose_lowest_lift_is_highest() {
        // 0 is linked. 3 is reached through 1 (lowest lift 0.5) or through 2 (0.6): 2 wins.
        // 4 is reached only through 3. 5 has no accepted pair.
        let lifts = [
            (0, 1, 0.7),
            (1, 3, 0.5),
            (0, 2, 0.6),
            (2, 3, 0.65),
            (3, 4, 0.9),
        ];
        let chains = widest_chains(6, &lifts, &[0]);
        assert_eq!(
            chains,
            [
                None,
                Some((0.7, 0)),
                Some((0.6, 0)),
                Some((0.6, 2)),
                Some((0.6, 3)),
                None
            ]
        );
        // Maps already linked get no chain; a pair between two of them changes nothing.
        let chains = widest_chains(6, &lifts, &[0, 1, 2]);
        assert_eq!(chains[..3], [None, None, None]);
        assert_eq!(chains[3], Some((0.65, 2)));
        assert_eq!(chains[4], Some((0.65, 3)));
    }
}
