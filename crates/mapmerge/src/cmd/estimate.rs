//! `mapmerge estimate A B [--json]`: the rigid transform mapping map B onto map A.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use grid_core::{CellState, DVec2, OccupancyGrid, Rigid2};
use mapmerge::{Registration, RunnerUp, register};
use serde_json::json;

use super::{
    BareImageArgs, RegistrationArgs, UsageError, deep_screen_hint, load, refuse_overwriting,
    require_directory,
};

const AFTER: &str = "\
Output (--json): one JSON object on stdout.
  transform        {theta, tx, ty}: maps a pixel (x = column, y = row from the top) of B onto A:
                   x_a = cos(theta) x_b - sin(theta) y_b + tx, y_a = sin(theta) x_b + cos(theta) y_b + ty
                   null when the pair is declined (exit code 3), with \"reason\" saying why
  world            {x, y, yaw}: B's map frame in A's map frame (metres, yaw counter-clockwise),
                   ready to publish as a TF from A's map frame to B's
  inliers          correspondences within 3 px of the answer; inliers_by_kind splits them
  confidence       wall lift of the answer (each map's walls moved by the range-bias offset the
                   refinement fitted): 0 is what a random placement scores, 1 is perfect
                   agreement of the walls; pairs are accepted from 0.65 (or 0.8 with walls
                   compared at 4 px), with acceptance index >= 0.82 and an overlap of at
                   least 15 % of the smaller map and 1250 cells
  stands_out       true when no placement reached those bars and this one was accepted
                   because it stands out: lift at 4 px >= 0.7 over an overlap with walls in
                   it (wall_density >= 0.033 wall cells per cell), and every placement more
                   than 20 px from it (mean over B's walls) lower by at least 0.3, each
                   at acceptance index >= 0.88 (speckled walls of a very noisy sensor)
  verification     wall_agreement, wall_lift, wide_wall_lift, wall_contradiction (share of walls
                   landing in the other map's free space), acceptance_index, overlap_cells,
                   overlap_fraction, wall_density
  runner_up        the best-ranked other placement more than 10 px from the answer (mean over
                   B's walls), or null: transform, apart_px, score_ratio (its verification
                   score over the answer's), passes (whether it passes the bars), verification,
                   hypothesis: where else the maps fit, and how well. One that passes and
                   fits about as well as the answer (0.6 of its score or more) mostly makes
                   the pair ambiguous, and declined
  best_rejected    of a declined pair: the best-ranked placement, declined (transform,
                   verification); its runner_up is measured from it
  hint             of a declined pair where no placement passed, without --deep-screen: what
                   --deep-screen might find (absent otherwise)
  method, hypothesis (ransac, global, sweep or symmetry), correspondences, candidates, timings_ms

Exit codes: 0 transform found, 3 no trustworthy match (the pair is declined), 2 bad usage or
bad input, 1 internal error.

Examples:
  mapmerge estimate fixtures/maps/sunil_pair_a/sunil_pair_a.yaml fixtures/maps/sunil_pair_b/sunil_pair_b.yaml
  mapmerge estimate a.yaml b.yaml --json --debug-png matches.png";

/// Arguments of `mapmerge estimate`.
#[derive(Debug, Clone, Args)]
#[command(after_help = AFTER)]
pub struct EstimateArgs {
    /// Map A (the reference): a map_server YAML or a bare .pgm/.png image
    #[arg(value_name = "A")]
    pub a: PathBuf,
    /// Map B (the one being placed into A's frame)
    #[arg(value_name = "B")]
    pub b: PathBuf,
    /// Print one JSON object instead of text
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub registration: RegistrationArgs,
    /// Write a picture of A, B with the matches (green: inliers, red: outliers) and B laid
    /// over A with the answer, both whole (A's walls blue, B's red, agreeing walls black); and
    /// B laid over A with the runner-up, when it passes the bars too
    #[arg(long, value_name = "FILE")]
    pub debug_png: Option<PathBuf>,
}

/// Run `mapmerge estimate`.
pub fn run(args: &EstimateArgs, bare: &BareImageArgs) -> anyhow::Result<ExitCode> {
    if let Some(png) = &args.debug_png {
        refuse_overwriting(png, "--debug-png", [&args.a, &args.b])?;
        // Checked before the registration's work, not after it.
        require_directory(png, "--debug-png")?;
    }
    let a = load(&args.a, bare)?;
    let b = load(&args.b, bare)?;
    if let Some(png) = &args.debug_png {
        // A map given by its YAML is read from the image the YAML names.
        refuse_overwriting(png, "--debug-png", [&a.image_path, &b.image_path])?;
    }
    grid_core::io::require_known_cells(&a.grid, &args.a)?;
    grid_core::io::require_known_cells(&b.grid, &args.b)?;
    let (ra, rb) = (a.grid.resolution(), b.grid.resolution());
    if ((ra - rb) / ra).abs() > 1e-6 {
        return Err(UsageError(format!(
            "{}: resolution {rb} m/cell differs from {}'s {ra} m/cell; a rigid pixel transform \
             needs equal resolutions (`mapmerge merge A B -o OUT.yaml` resamples B to A's and \
             reports B's frame in A's)",
            args.b.display(),
            args.a.display()
        ))
        .into());
    }
    let config = args.registration.config();
    let result = register(&a.grid, &b.grid, &config).context("invalid registration settings")?;
    // Found once, for the report and the picture.
    let runner_up = result.runner_up(&b.grid, config.pair.verify.distinct_px);
    if let Some(png) = &args.debug_png {
        write_debug_png(
            png,
            &a.grid,
            &b.grid,
            &result,
            runner_up.as_ref(),
            config.pair.ransac.threshold_px,
        )?;
    }
    let out = report(args, &a.grid, &b.grid, &result, runner_up.as_ref());
    let mut stdout = std::io::stdout().lock();
    if args.json {
        writeln!(stdout, "{out}").context("cannot write to stdout")?;
    } else {
        human(&mut stdout, &out).context("cannot write to stdout")?;
    }
    Ok(ExitCode::from(if result.accepted.is_some() {
        0
    } else {
        3
    }))
}

fn report(
    args: &EstimateArgs,
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    r: &Registration,
    runner_up: Option<&RunnerUp>,
) -> serde_json::Value {
    let runner_up = runner_up.map(|u| {
        let (c, t) = (&u.candidate, &u.candidate.transform);
        json!({
            "transform": {"theta": t.theta, "tx": t.tx, "ty": t.ty},
            "apart_px": u.apart_px,
            "score_ratio": u.score_ratio,
            "passes": c.accepted,
            "verification": c.verification,
            "hypothesis": c.origin,
        })
    });
    let common = json!({
        "a": args.a.display().to_string(),
        "b": args.b.display().to_string(),
        "method": args.registration.method,
        "seed": args.registration.seed,
        "correspondences": r.correspondences,
        "candidates": r.candidates.len(),
        "runner_up": runner_up,
        "timings_ms": r.timings,
    });
    let mut out = match &r.accepted {
        Some(c) => {
            let w = c.transform.to_world(&a.geometry(), &b.geometry());
            json!({
                "transform": {"theta": c.transform.theta, "tx": c.transform.tx, "ty": c.transform.ty},
                "world": {"x": w.tx, "y": w.ty, "yaw": w.theta},
                "inliers": r.inliers.intensity + r.inliers.area,
                "inliers_by_kind": r.inliers,
                "confidence": c.verification.wall_lift.clamp(0.0, 1.0),
                "verification": c.verification,
                "stands_out": c.stands_out,
                "hypothesis": c.origin,
            })
        }
        None => json!({
            "transform": null,
            "reason": r.reason.clone().unwrap_or_else(|| "no trustworthy match".into()),
            "best_rejected": r.candidates.first().map(|c| json!({
                "transform": {"theta": c.transform.theta, "tx": c.transform.tx, "ty": c.transform.ty},
                "verification": c.verification,
            })),
        }),
    };
    if let (Some(o), Some(hint)) = (out.as_object_mut(), deep_screen_hint(&args.registration, r)) {
        o.insert("hint".into(), hint.into());
    }
    if let (Some(o), Some(c)) = (out.as_object_mut(), common.as_object()) {
        o.extend(c.clone());
    }
    out
}

/// A transform of the JSON report as the text form prints it.
fn placement(t: &serde_json::Value) -> String {
    let v = |k: &str| t[k].as_f64().unwrap_or(0.0);
    format!(
        "theta {:.3} deg, tx {:.2} px, ty {:.2} px",
        v("theta").to_degrees(),
        v("tx"),
        v("ty")
    )
}

fn human(w: &mut impl Write, o: &serde_json::Value) -> std::io::Result<()> {
    let f = |k: &str| o[k].as_f64().unwrap_or(f64::NAN);
    let declined = o["transform"].is_null();
    if declined {
        writeln!(
            w,
            "no trustworthy match: {}",
            o["reason"].as_str().unwrap_or("?")
        )?;
        let best = &o["best_rejected"];
        if !best.is_null() {
            let (t, v) = (&best["transform"], &best["verification"]);
            writeln!(
                w,
                "best placement, declined: {}; wall lift {:.2} (at 4 px {:.2}), acceptance index {:.3}, overlap {:.1}% of the smaller map, {:.1} % of its compared walls in the other map's free space",
                placement(t),
                v["wall_lift"].as_f64().unwrap_or(0.0),
                v["wide_wall_lift"].as_f64().unwrap_or(0.0),
                v["acceptance_index"].as_f64().unwrap_or(0.0),
                100.0 * v["overlap_fraction"].as_f64().unwrap_or(0.0),
                100.0 * v["wall_contradiction"].as_f64().unwrap_or(0.0)
            )?;
        }
        if let Some(hint) = o["hint"].as_str() {
            writeln!(w, "hint: {hint}")?;
        }
    } else {
        let wd = &o["world"];
        writeln!(w, "B -> A (pixels): {}", placement(&o["transform"]))?;
        writeln!(
            w,
            "B's map frame in A's (world): x {:.3} m, y {:.3} m, yaw {:.3} deg",
            wd["x"].as_f64().unwrap_or(0.0),
            wd["y"].as_f64().unwrap_or(0.0),
            wd["yaw"].as_f64().unwrap_or(0.0).to_degrees()
        )?;
        let v = &o["verification"];
        writeln!(
            w,
            "confidence {:.2} (wall lift), acceptance index {:.3}, overlap {:.1}% of the smaller map, {} inliers ({} hypothesis)",
            f("confidence"),
            v["acceptance_index"].as_f64().unwrap_or(0.0),
            100.0 * v["overlap_fraction"].as_f64().unwrap_or(0.0),
            o["inliers"],
            o["hypothesis"].as_str().unwrap_or("?")
        )?;
        if o["stands_out"].as_bool() == Some(true) {
            writeln!(
                w,
                "accepted because it stands out: no placement reached the wall lift bars, and this one (lift {:.2} at 4 px) fits clearly better than every other",
                v["wide_wall_lift"].as_f64().unwrap_or(0.0)
            )?;
        }
    }
    // Where else the maps fit: beside the answer, or beside the declined best (an ambiguous
    // pair's rival, say).
    let u = &o["runner_up"];
    if !u.is_null() {
        let (t, uv) = (&u["transform"], &u["verification"]);
        let (from, of) = if declined {
            ("the best placement", "the best's")
        } else {
            ("the answer", "the answer's")
        };
        writeln!(
            w,
            "runner-up: {}, {:.0} px from {from} (mean over B's walls); wall lift {:.2} (at 4 px {:.2}), score {:.2} of {of}, {}",
            placement(t),
            u["apart_px"].as_f64().unwrap_or(0.0),
            uv["wall_lift"].as_f64().unwrap_or(0.0),
            uv["wide_wall_lift"].as_f64().unwrap_or(0.0),
            u["score_ratio"].as_f64().unwrap_or(0.0),
            if u["passes"].as_bool() == Some(true) {
                "passing the bars"
            } else {
                "below the bars"
            }
        )?;
    }
    let t = &o["timings_ms"];
    let total: f64 = [
        "correspondences_ms",
        "ransac_ms",
        "prepare_ms",
        "verify_ms",
        "global_ms",
        "sweep_ms",
        "symmetry_ms",
        "ascent_ms",
    ]
    .iter()
    .map(|k| t[*k].as_f64().unwrap_or(0.0))
    .sum();
    writeln!(
        w,
        "{} correspondences ({} intensity, {} area), {} candidates checked, {:.0} ms",
        o["correspondences"]["intensity"].as_u64().unwrap_or(0)
            + o["correspondences"]["area"].as_u64().unwrap_or(0),
        o["correspondences"]["intensity"],
        o["correspondences"]["area"],
        o["candidates"],
        total
    )
}

fn shade(s: CellState) -> [u8; 3] {
    match s {
        CellState::Free => [255, 255, 255],
        CellState::Occupied => [0, 0, 0],
        CellState::Unknown => [205, 205, 205],
    }
}

fn line(img: &mut image::RgbImage, p: DVec2, q: DVec2, colour: [u8; 3]) {
    let n = (q - p).abs().max_element().ceil().max(1.0) as usize;
    for i in 0..=n {
        let r = p + (q - p) * (i as f64 / n as f64);
        let (x, y) = (r.x.round(), r.y.round());
        if x >= 0.0 && y >= 0.0 && (x as u32) < img.width() && (y as u32) < img.height() {
            img.put_pixel(x as u32, y as u32, image::Rgb(colour));
        }
    }
}

/// The bounding box `(x0, y0, x1, y1)` (inclusive, pixels of A's frame) of A's known cells
/// and of B's placed by `t`, grown by a few pixels; A's whole canvas when neither map has a
/// known cell.
fn overlay_bounds(a: &OccupancyGrid, b: &OccupancyGrid, t: &Rigid2) -> (i64, i64, i64, i64) {
    const MARGIN: usize = 5;
    let mut corners = Vec::new();
    if let Some((x, y, w, h)) = a.known_bounds(MARGIN) {
        corners.push(DVec2::new(x as f64, y as f64));
        corners.push(DVec2::new((x + w - 1) as f64, (y + h - 1) as f64));
    }
    if let Some((x, y, w, h)) = b.known_bounds(MARGIN) {
        let (x1, y1) = ((x + w - 1) as f64, (y + h - 1) as f64);
        for (cx, cy) in [
            (x as f64, y as f64),
            (x1, y as f64),
            (x as f64, y1),
            (x1, y1),
        ] {
            corners.push(t.apply(DVec2::new(cx, cy)));
        }
    }
    if corners.is_empty() {
        return (0, 0, a.width() as i64 - 1, a.height() as i64 - 1);
    }
    let lo = corners.iter().copied().reduce(DVec2::min).expect("corners");
    let hi = corners.iter().copied().reduce(DVec2::max).expect("corners");
    (
        lo.x.floor() as i64,
        lo.y.floor() as i64,
        hi.x.ceil() as i64,
        hi.y.ceil() as i64,
    )
}

/// An overlay panel: B laid over A by a transform, over `(x0, y0, width, height)` of A's frame
/// (its top left pixel A's pixel `(x0, y0)`).
type Overlay = (Rigid2, i64, i64, usize, usize);

/// The panel of B laid over A by `t`: the bounding box of both maps' known cells, B's placed by
/// `t`. A placement far from A (a declined pair's best candidate can be anywhere) would make a
/// picture of mostly nothing: A's canvas then.
fn overlay(a: &OccupancyGrid, b: &OccupancyGrid, t: Rigid2) -> Overlay {
    let (wa, ha, wb, hb) = (a.width(), a.height(), b.width(), b.height());
    let (mut x0, mut y0, mut x1, mut y1) = overlay_bounds(a, b, &t);
    let area = (x1 - x0 + 1) as f64 * (y1 - y0 + 1) as f64;
    if area > 4.0 * ((wa * ha).max(wb * hb)) as f64 {
        (x0, y0, x1, y1) = (0, 0, wa as i64 - 1, ha as i64 - 1);
    }
    (t, x0, y0, (x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize)
}

/// Draw `overlay` with its left edge at column `ox` of `img`: A's walls blue, B's red, black
/// where both have one, white where either saw free space, grey elsewhere.
fn draw_overlay(
    img: &mut image::RgbImage,
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    overlay: &Overlay,
    ox: usize,
) {
    let &(t, x0, y0, wo, ho) = overlay;
    let inv = t.inverse();
    let state = |grid: &OccupancyGrid, q: DVec2| {
        let q = q.round();
        if q.x >= 0.0 && q.y >= 0.0 && q.x < grid.width() as f64 && q.y < grid.height() as f64 {
            grid.state(q.x as usize, q.y as usize)
        } else {
            CellState::Unknown
        }
    };
    for v in 0..ho {
        for u in 0..wo {
            let p = DVec2::new((x0 + u as i64) as f64, (y0 + v as i64) as f64);
            let (sa, sb) = (state(a, p), state(b, inv.apply(p)));
            let colour = match (sa, sb) {
                (CellState::Occupied, CellState::Occupied) => [0, 0, 0],
                (CellState::Occupied, _) => [40, 80, 230],
                (_, CellState::Occupied) => [230, 40, 40],
                (CellState::Free, _) | (_, CellState::Free) => [255, 255, 255],
                _ => [205, 205, 205],
            };
            img.put_pixel((ox + u) as u32, v as u32, image::Rgb(colour));
        }
    }
}

/// Three panels: A, B (with match lines between them), and B laid over A with the answer, both
/// whole; a fourth, B laid over A with the runner-up ([`Registration::runner_up`]), when there
/// is one that passes the bars too.
fn write_debug_png(
    path: &Path,
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    r: &Registration,
    runner_up: Option<&RunnerUp>,
    threshold: f64,
) -> anyhow::Result<()> {
    const GAP: usize = 10;
    let (wa, ha, wb, hb) = (a.width(), a.height(), b.width(), b.height());
    let t = r
        .accepted
        .as_ref()
        .map(|c| c.transform)
        .or_else(|| r.candidates.first().map(|c| c.transform));
    let answer = t.map(|t| overlay(a, b, t));
    let runner_up = runner_up
        .filter(|u| u.candidate.accepted)
        .map(|u| overlay(a, b, u.candidate.transform));
    let size = |o: &Option<Overlay>| o.map_or((0, 0), |(_, _, _, w, h)| (w, h));
    let ((wo, ho), (wu, hu)) = (size(&answer), size(&runner_up));
    let width = wa + wb + wo + 2 * GAP + if wu > 0 { wu + GAP } else { 0 };
    let height = ha.max(hb).max(ho).max(hu);
    anyhow::ensure!(
        (width as u64) * (height as u64) <= 200_000_000,
        "{}: the debug picture would be {width} x {height} pixels; too large",
        path.display()
    );
    let mut img =
        image::RgbImage::from_pixel(width as u32, height as u32, image::Rgb([90, 90, 90]));
    for y in 0..ha {
        for x in 0..wa {
            img.put_pixel(x as u32, y as u32, image::Rgb(shade(a.state(x, y))));
        }
    }
    let bx = wa + GAP;
    for y in 0..hb {
        for x in 0..wb {
            img.put_pixel((bx + x) as u32, y as u32, image::Rgb(shade(b.state(x, y))));
        }
    }
    for c in &r.matches {
        let inlier = t.is_some_and(|t: Rigid2| (c.a - t.apply(c.b)).length() <= threshold);
        let colour = if inlier { [0, 170, 0] } else { [220, 40, 40] };
        line(&mut img, c.a, c.b + DVec2::new(bx as f64, 0.0), colour);
    }
    // The overlays right of B's panel.
    let ox = bx + wb + GAP;
    if let Some(o) = &answer {
        draw_overlay(&mut img, a, b, o, ox);
    }
    if let Some(o) = &runner_up {
        draw_overlay(&mut img, a, b, o, ox + wo + GAP);
    }
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| anyhow::anyhow!("{}: cannot encode the debug picture: {e}", path.display()))?;
    grid_core::io::write_atomic(path, &png)
        .map_err(|e| anyhow::anyhow!("cannot write the debug picture: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::Pose2;
    use mapmerge::verify::Verification;
    use mapmerge::{Candidate, KindTotals, Origin, Timings};

    /// A room of `w x h` cells: walls on its border, free inside.
    fn room(w: usize, h: usize) -> OccupancyGrid {
        let cells = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if x == 0 || y == 0 || x == w - 1 || y == h - 1 {
                    100
                } else {
                    0
                }
            })
            .collect();
        OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
    }

    fn placed(tx: f64, accepted: bool) -> Candidate {
        let verification = Verification {
            wall_lift: 0.9,
            wall_support: 100,
            acceptance_index: 0.98,
            ..Verification::default()
        };
        Candidate::scored(
            Rigid2::new(0.0, tx, 0.0),
            verification,
            accepted,
            Origin::Sweep,
        )
    }

    #[test]
    fn the_debug_picture_shows_a_runner_up_that_passes_in_a_fourth_panel() {
        let (a, b) = (room(60, 40), room(30, 20));
        let registration = |up: Candidate| Registration {
            accepted: Some(placed(5.0, true)),
            reason: None,
            candidates: vec![placed(5.0, true), up],
            correspondences: KindTotals::default(),
            inliers: KindTotals::default(),
            timings: Timings::default(),
            matches: Vec::new(),
        };
        let dir = tempfile::TempDir::new().unwrap();
        let path = dir.path().join("d.png");
        // Each overlay spans A's known cells (B lies inside them): 60 px, 10 px apart.
        let panels = |r: &Registration| {
            write_debug_png(&path, &a, &b, r, r.runner_up(&b, 10.0).as_ref(), 3.0).unwrap();
            image::open(&path).unwrap().to_rgb8()
        };
        let img = panels(&registration(placed(25.0, true)));
        assert_eq!(img.width(), 60 + 30 + 60 + 60 + 3 * 10);
        // The fourth panel lays B 20 px right of where the third does: B's left wall (x = 0 in
        // B) lands on A's column 25 there, black where it meets A's walls and red between.
        let fourth = 60 + 10 + 30 + 10 + 60 + 10;
        let column = |x: u32| -> Vec<[u8; 3]> { (0..20).map(|y| img.get_pixel(x, y).0).collect() };
        let red = [230, 40, 40];
        assert_eq!(column(fourth + 25)[1..19], vec![red; 18][..]);
        assert_eq!(column(fourth + 25)[0], [0, 0, 0]);
        assert_eq!(column(60 + 10 + 30 + 10 + 5)[1..19], vec![red; 18][..]);
        // Nothing between the third panel and the fourth but the gap.
        assert_eq!(column(fourth - 5), vec![[90, 90, 90]; 20]);
        // A runner-up below the bars gets no panel.
        let img = panels(&registration(placed(25.0, false)));
        assert_eq!(img.width(), 60 + 30 + 60 + 2 * 10);
    }
}
