//! Registration of one pair: correspondences → RANSAC hypotheses → refinement → verification.
//!
//! `pair.rs` runs the stages, each a method of its `PairRun`; `config.rs` holds the settings;
//! this file the types of the answer and the helpers the stages share.

use std::time::Instant;

use rayon::prelude::*;

use blob_features::{BlobCorrespondences, Blobs};
use grid_core::{
    CellState, Correspondence, CorrespondenceSource, DVec2, EvidenceKind, OccupancyGrid, Rigid2,
};
use sift_desc::SiftCorrespondences;

use crate::Error;
use crate::global::manhattan_direction;
use crate::refine::{RefineConfig, refine_with_bias};
use crate::search::local_search;
use crate::verify::{
    PreparedMap, StandOut, Verification, VerifyConfig, strided, verify, verify_with_offsets,
};

mod config;
mod pair;

use pair::register_as_given;

pub use config::{
    ManhattanRotation, Method, PairConfig, PolishConfig, RegisterConfig, SpectrumRotation, TurnScan,
};

/// The rotation of B onto A nearest to `theta` that the maps' dominant wall directions give
/// (see [`ManhattanRotation`]), if it lies within `config.max_delta_deg` of it and both maps
/// have a clear dominant direction.
fn manhattan_rotation_near(
    a: &PreparedMap,
    b: &PreparedMap,
    theta: f64,
    config: &ManhattanRotation,
) -> Option<f64> {
    let (da, db) = rayon::join(
        || manhattan_direction(&strided(&a.wall_samples, config.max_points)),
        || manhattan_direction(&strided(&b.wall_samples, config.max_points)),
    );
    let (da, db) = (da?, db?);
    if da.contrast.min(db.contrast) < config.min_contrast {
        return None;
    }
    let quarter = std::f64::consts::FRAC_PI_2;
    let d = (da.angle - db.angle - theta).rem_euclid(quarter);
    let d = if d > quarter / 2.0 { d - quarter } else { d };
    (d.abs() <= config.max_delta_deg.to_radians()).then_some(theta + d)
}

/// The centroid (in A's frame) of B's walls that `b_to_a` puts on known cells of A, and that
/// of all B's walls; `None` if none lands on A's known cells.
fn wall_centres(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
) -> Option<(grid_core::DVec2, grid_core::DVec2)> {
    let zero = grid_core::DVec2::ZERO;
    let (mut shared, mut n, mut all) = (zero, 0usize, zero);
    for q in b.wall_samples.iter().map(|p| b_to_a.apply(*p)) {
        all += q;
        if crate::verify::cell_of(a.grid, q)
            .is_some_and(|(x, y)| a.grid.state(x, y) != grid_core::CellState::Unknown)
        {
            shared += q;
            n += 1;
        }
    }
    (n > 0).then(|| (shared / n as f64, all / b.wall_samples.len() as f64))
}

/// `b_to_a` turned to angle `theta` about the centre of B's walls that it puts on known cells
/// of A (so that the shared part stays in place); `None` if none lands there.
fn turned_about_overlap(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    theta: f64,
) -> Option<Rigid2> {
    let (shared, _) = wall_centres(a, b, b_to_a)?;
    Some(Rigid2::rotation_about(theta - b_to_a.theta, shared).compose(b_to_a))
}

/// `b_to_a` turned to angle `theta` about its walls on A's known cells
/// ([`turned_about_overlap`]), its translation and range-bias offsets then refined by ICP with
/// the angle held (`config.refine`), and verified with those offsets: the answer at an angle
/// taken from elsewhere (the spectra, the dominant wall directions). `None` if none of B's
/// walls lands on A's known cells.
fn at_angle(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    theta: f64,
    config: &PairConfig,
) -> Option<(Rigid2, Verification)> {
    let start = turned_about_overlap(a, b, b_to_a, theta)?;
    let locked = RefineConfig {
        lock_rotation: true,
        ..config.refine
    };
    let (t, offsets) = refine_with_bias(a, b, &start, &locked);
    let v = verify_with_offsets(a, b, &t, offsets, &config.verify);
    Some((t, v))
}

/// One candidate transform after refinement and verification.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Candidate {
    /// B→A transform, pixel convention.
    pub transform: Rigid2,
    /// RANSAC inliers of the hypothesis this candidate came from.
    pub ransac_inliers: usize,
    /// RANSAC's a-contrario confidence of that hypothesis.
    pub ransac_confidence: f64,
    /// The scores on the maps.
    pub verification: Verification,
    /// Whether it passes the verification thresholds.
    pub accepted: bool,
    /// Whether it was accepted because it stands out from every other placement
    /// ([`crate::verify::StandOut`]) rather than by the wall lift bars.
    pub stands_out: bool,
    /// Where the hypothesis came from.
    pub origin: Origin,
    /// Whether ICP refined it. A whole-map placement beyond
    /// [`PairConfig::refined_placements`] is kept where its local search led and scored there;
    /// it is refined only if it comes to be the best candidate, or the one that stands out.
    pub refined: bool,
}

impl Candidate {
    /// A placement from `origin`, refined and scored as `verification`, passing or not as
    /// `accepted` says: no RANSAC support (a whole-map placement), not standing out.
    pub fn scored(
        transform: Rigid2,
        verification: Verification,
        accepted: bool,
        origin: Origin,
    ) -> Self {
        Self {
            transform,
            ransac_inliers: 0,
            ransac_confidence: 0.0,
            verification,
            accepted,
            stands_out: false,
            origin,
            refined: true,
        }
    }
}

/// Which stage proposed a candidate; serialised in lower case (`"ransac"`, ...), as the
/// `hypothesis` field of `mapmerge estimate --json`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Origin {
    /// A RANSAC hypothesis from keypoint and component correspondences.
    Ransac,
    /// The global search (Hough spectrum and correlation), run when no RANSAC candidate passed
    /// and [`PairConfig::global`] is on (off by default).
    Global,
    /// The rotation sweep of coarse correlation images.
    Sweep,
    /// A symmetry probe: the best candidate's angle, or that angle turned by a quarter, half or
    /// three quarters of a turn, with the best correlation translations.
    Symmetry,
}

impl Origin {
    /// The lower-case name, as serialised.
    pub fn as_str(self) -> &'static str {
        match self {
            Origin::Ransac => "ransac",
            Origin::Global => "global",
            Origin::Sweep => "sweep",
            Origin::Symmetry => "symmetry",
        }
    }
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// Wall-clock time of each stage, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Timings {
    /// Feature extraction and matching (runs beside `prepare_ms`: the two overlap).
    pub correspondences_ms: f64,
    /// RANSAC.
    pub ransac_ms: f64,
    /// Precomputation of both maps for verification (runs beside `correspondences_ms`).
    pub prepare_ms: f64,
    /// Refinement and verification of all candidates.
    pub verify_ms: f64,
    /// Global search, when it ran.
    pub global_ms: f64,
    /// Rotation sweep, when it ran (both ways round when the first found nothing that passes,
    /// see `SweepConfig::reverse`, and the deep screen when still nothing passed, see
    /// `SweepConfig::deep_screened`).
    pub sweep_ms: f64,
    /// Symmetry probes of the best accepted candidate, when they ran.
    pub symmetry_ms: f64,
    /// The score ascent of the answer ([`PairConfig::ascent`]) with its gate (both maps'
    /// wall thickness), when they ran.
    pub ascent_ms: f64,
}

/// The answer for one pair.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Registration {
    /// The best verified candidate, if any passed verification.
    pub accepted: Option<Candidate>,
    /// Why the pair was declined, when it was.
    pub reason: Option<String>,
    /// Every candidate, best score first.
    pub candidates: Vec<Candidate>,
    /// Correspondences found, by kind.
    pub correspondences: KindTotals,
    /// RANSAC inliers of the accepted candidate's hypothesis, by kind.
    pub inliers: KindTotals,
    /// Stage timings.
    pub timings: Timings,
    /// The putative correspondences themselves (for drawing), not serialised.
    #[serde(skip)]
    pub matches: Vec<Correspondence>,
}

/// The runner-up of a registration ([`Registration::runner_up`]): the best-ranked candidate
/// placed clearly apart from the answer.
#[derive(Debug, Clone, PartialEq)]
pub struct RunnerUp {
    /// The candidate, as [`Registration::candidates`] holds it.
    pub candidate: Candidate,
    /// How far apart it and the answer put B's walls: the mean distance, in pixels, over up
    /// to [`APART_POINTS`] of B's wall cells ([`mean_apart`]).
    pub apart_px: f64,
    /// Its [`Verification::score`] over the answer's (0 when the answer scores 0). It can
    /// exceed 1: the ranking puts the placements that pass the bars first, the answer's pose is
    /// refined after the ranking, and a placement that fits cleanly can succeed a best that
    /// scored more but put walls in the other map's free space
    /// ([`VerifyConfig::clean_successor`](crate::verify::VerifyConfig::clean_successor)).
    pub score_ratio: f64,
}

/// Wall cells of B over which [`mean_apart`] measures two placements, at most.
pub const APART_POINTS: usize = 500;

/// How far apart placements `x` and `y` put `points` (B's wall cells): the mean distance, in
/// pixels, between each point's two images; 0 for no point. The ambiguity test's and the
/// runner-up's measure of "different" ([`VerifyConfig::distinct_px`]).
pub fn mean_apart(points: &[DVec2], x: &Rigid2, y: &Rigid2) -> f64 {
    points
        .iter()
        .map(|p| (x.apply(*p) - y.apply(*p)).length())
        .sum::<f64>()
        / points.len().max(1) as f64
}

/// The pixels of `grid`'s occupied cells, row by row.
fn wall_cells(grid: &OccupancyGrid) -> Vec<DVec2> {
    (0..grid.height())
        .flat_map(|y| (0..grid.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| grid.state(x, y) == CellState::Occupied)
        .map(|(x, y)| DVec2::new(x as f64, y as f64))
        .collect()
}

impl Registration {
    /// The best-ranked candidate after the first that places `b` (the map registered onto A,
    /// in its own pixels, as the candidates' transforms are) more than `distinct_px` apart from
    /// it ([`mean_apart`] over up to [`APART_POINTS`] of `b`'s wall cells, evenly strided, as
    /// the ambiguity test measures two placements):
    /// the placement a user would weigh the answer against. The first candidate is the answer
    /// when the pair was accepted and the best rejected one when it was declined. `None` when
    /// no candidate is that far from the first, or `b` has no wall cell.
    ///
    /// A runner-up that passes the bars and fits about as well as the answer is what mostly
    /// makes a pair ambiguous, and declined (the ambiguity test also weighs the walls each puts
    /// in free space and whether the two are one broad optimum).
    pub fn runner_up(&self, b: &OccupancyGrid, distinct_px: f64) -> Option<RunnerUp> {
        let first = self.candidates.first()?;
        let walls = wall_cells(b);
        if walls.is_empty() {
            return None;
        }
        let probe = crate::verify::strided(&walls, APART_POINTS);
        self.candidates.iter().skip(1).find_map(|c| {
            let apart_px = mean_apart(&probe, &first.transform, &c.transform);
            (apart_px > distinct_px).then(|| {
                let best = first.verification.score();
                RunnerUp {
                    candidate: c.clone(),
                    apart_px,
                    score_ratio: if best > 0.0 {
                        c.verification.score() / best
                    } else {
                        0.0
                    },
                }
            })
        })
    }
}

/// A count per evidence kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct KindTotals {
    /// From intensity keypoints (SIFT).
    pub intensity: usize,
    /// From area keypoints (components).
    pub area: usize,
}

impl KindTotals {
    /// Count the correspondences `indices` of `corrs` by kind.
    pub fn of(corrs: &[Correspondence], indices: impl Iterator<Item = usize>) -> Self {
        let mut t = Self::default();
        for i in indices {
            match corrs[i].kind {
                EvidenceKind::Intensity => t.intensity += 1,
                EvidenceKind::Area => t.area += 1,
            }
        }
        t
    }
}

/// Whether candidate `c`, placed clearly apart from the best (`best` its scores), is a rival
/// that makes the pair ambiguous ([`VerifyConfig::max_ambiguity`]): it passes, scores almost
/// as well or fits its (smaller) overlap at least as well, or the best itself fits below
/// [`VerifyConfig::trusted_wide_wall_lift`], and it does not put clearly more walls into the
/// other map's free space ([`VerifyConfig::max_contradiction_excess`]; less is clearly more
/// when the best puts few there, [`VerifyConfig::clean_contradiction_excess`]).
///
/// A twin from the symmetry probes is judged by the same rule. At 9c48d15 every twin that
/// passed was a rival, which declined exact copies of small rooms whose quarter-turned twin
/// fits worse (wall lift 0.90 against 1.00, score 257 against 621).
fn rivals(best: &Verification, c: &Candidate, config: &VerifyConfig) -> bool {
    let v = &c.verification;
    c.accepted
        && (fits_about_as_well(best, v, config)
            || best.wide_wall_lift < config.trusted_wide_wall_lift)
        && v.wall_contradiction <= best.wall_contradiction + contradiction_excess(best, config)
}

/// How much more of its walls than `best` a placement may put into the other map's free space
/// and still rival it: [`VerifyConfig::clean_contradiction_excess`] plus the best's own
/// share, at most [`VerifyConfig::max_contradiction_excess`].
fn contradiction_excess(best: &Verification, config: &VerifyConfig) -> f64 {
    (config.clean_contradiction_excess + best.wall_contradiction)
        .min(config.max_contradiction_excess)
}

/// Whether `v` scores almost as well as `best` ([`VerifyConfig::max_ambiguity`]) or fits its
/// walls at least as well (wall lift as high).
fn fits_about_as_well(best: &Verification, v: &Verification, config: &VerifyConfig) -> bool {
    v.score() >= config.max_ambiguity * best.score() || v.wall_lift >= best.wall_lift
}

/// Whether placements `x` and `y` are one broad optimum rather than two answers: the placement
/// halfway between them fits at least [`VerifyConfig::basin_ratio`] as well as the poorer of
/// the two (all three scored by [`verify`], without range-bias offsets). Between two genuine
/// answers (a quarter turn, the next bay of a repetitive floor) the walls pass through free
/// space and the score falls; across a wall band that a noisy sensor smeared over 10-20 px,
/// it does not.
fn one_basin(
    a: &PreparedMap,
    b: &PreparedMap,
    x: &Rigid2,
    y: &Rigid2,
    config: &VerifyConfig,
) -> bool {
    if config.basin_ratio <= 0.0 {
        return false;
    }
    let half = grid_core::wrap_angle(y.theta - x.theta) / 2.0;
    let mid = Rigid2::new(x.theta + half, (x.tx + y.tx) / 2.0, (x.ty + y.ty) / 2.0);
    let score = |t: &Rigid2| verify(a, b, t, config).score();
    score(&mid) >= config.basin_ratio * score(x).min(score(y))
}

/// The candidate [`StandOut`] accepts when none passed the wall lift bars: of those the rule
/// admits ([`StandOut::admits`]), the best scoring, if it [`stands_out`].
/// `apart` measures how far apart two placements put B's walls.
fn standing_out(
    candidates: &[Candidate],
    rule: &StandOut,
    config: &VerifyConfig,
    apart: &dyn Fn(&Rigid2, &Rigid2) -> f64,
) -> Option<usize> {
    let (i, c) = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| rule.admits(&c.verification, config))
        .max_by(|(_, x), (_, y)| x.verification.score().total_cmp(&y.verification.score()))?;
    stands_out(candidates, c, rule, config, apart).then_some(i)
}

/// Whether every candidate that passes all but the wall tests and lies more than
/// `rule.distance_px` from `c` has a wide lift at least `rule.margin` below `c`'s.
fn stands_out(
    candidates: &[Candidate],
    c: &Candidate,
    rule: &StandOut,
    config: &VerifyConfig,
    apart: &dyn Fn(&Rigid2, &Rigid2) -> f64,
) -> bool {
    let bar = c.verification.wide_wall_lift - rule.margin;
    candidates
        .iter()
        .filter(|o| {
            rule.passes_all_but_walls(&o.verification, config)
                && apart(&o.transform, &c.transform) > rule.distance_px
        })
        .all(|o| o.verification.wide_wall_lift <= bar)
}

/// The share of lone wall cells ([`lone_wall_share`](crate::ascent::lone_wall_share)) from which a map's walls count as
/// speckle in a decline's reason. With `mapsim`'s default mapper each map of `cargo xtask eval
/// --out` holds 0.03-0.08 at 10 % range noise, 0.09-0.21 at 20 %, 0.16-0.30 at 30 % and
/// 0.28-0.46 at 50 % (docs/EVALUATION.md, "Equal noise of 20 %"): from 20 % on, right
/// placements fit about as poorly as wrong ones, and pairs are declined that do overlap.
pub const SPECKLED_LONE_SHARE: f64 = 0.1;

/// Why no placement passed: the best one's fit against the bars it missed and, where both
/// maps' walls are speckle (lone wall cell shares `lone`), that this is what a range sensor
/// with strong noise leaves.
fn unverified_reason(v: &Verification, config: &VerifyConfig, lone: (f64, f64)) -> String {
    let mut reason = format!(
        "no hypothesis passed verification (best: wall lift {} where {:.2} passes, or {} at {} px where {:.2} passes; acceptance index {:.2}; overlap {:.1}% of the smaller map)",
        short_of(v.wall_lift, config.min_wall_lift),
        config.min_wall_lift,
        short_of(v.wide_wall_lift, config.min_wide_wall_lift),
        config.wide_tolerance_px,
        config.min_wide_wall_lift,
        v.acceptance_index,
        100.0 * v.overlap_fraction
    );
    if lone.0.min(lone.1) >= SPECKLED_LONE_SHARE {
        reason += &format!(
            "; both maps' walls are speckle (lone wall cells {:.1} % and {:.1} %), as a range sensor with strong noise leaves them: there a right placement fits about as poorly as a wrong one",
            100.0 * lone.0,
            100.0 * lone.1
        );
    }
    reason
}

/// `value`, measured against a `bar` it may fall short of, for a decline's reason: to two
/// decimals as the bars are printed, or to as many more (up to five) as it takes not to read
/// as the bar itself when it falls short of it (0.8774 against 0.88 is "0.877", not "0.88").
pub(crate) fn short_of(value: f64, bar: f64) -> String {
    let shown = |d: usize| format!("{value:.d$}");
    (2..=5)
        .map(shown)
        .find(|s| value >= bar || s.parse::<f64>().is_ok_and(|v| v < bar))
        .unwrap_or_else(|| shown(5))
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// A pose as every hypothesis is polished and scored: refined from `start` by ICP with
/// `refine` (range-bias offsets included), then verified with `config.verify`, with those
/// offsets applied when `config.offsets_in_verification`. Public so that evaluations score
/// other poses (the truth, say) exactly as the pipeline scores its candidates.
pub fn refine_and_score(
    a: &PreparedMap,
    b: &PreparedMap,
    start: &Rigid2,
    refine: &RefineConfig,
    config: &PairConfig,
) -> (Rigid2, Verification) {
    let (transform, offsets) = refine_with_bias(a, b, start, refine);
    let transform = transform.normalized();
    let v = if config.offsets_in_verification {
        verify_with_offsets(a, b, &transform, offsets, &config.verify)
    } else {
        verify(a, b, &transform, &config.verify)
    };
    (transform, v)
}

/// A whole-map placement, and where the translation-only local search (`PairConfig::search`)
/// moved it and how that pose verified, when that is already known (the screen searched and
/// verified it), so that it is not searched and verified twice.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Placement {
    pose: Rigid2,
    searched: Option<(Rigid2, Verification)>,
}

impl Placement {
    /// A placement not searched yet.
    fn unsearched(pose: Rigid2) -> Self {
        Self {
            pose,
            searched: None,
        }
    }
}

/// The `keep` of `placements` that pass verification, or else that the maps agree with most,
/// once the correlative local search (`config.search`, if any) has moved them
/// ([`screen_order`]): a cheap screen before the full refinement, for a coarse ranking that
/// puts the truth too far down (see [`SweepConfig::screened`](crate::global::SweepConfig::screened)). Returns
/// the placements themselves with where the search moved them, best screened first; all of
/// them, in order and unsearched, when there are no more than `keep`. Deterministic: ties
/// keep the given order.
fn screen(
    a: &PreparedMap,
    b: &PreparedMap,
    placements: Vec<Rigid2>,
    keep: usize,
    config: &PairConfig,
) -> Vec<Placement> {
    if placements.len() <= keep {
        return placements.into_iter().map(Placement::unsearched).collect();
    }
    let scored: Vec<(Rigid2, Verification)> = placements
        .par_iter()
        .map(|p| searched(a, b, p, config))
        .collect();
    let verifications: Vec<Verification> = scored.iter().map(|s| s.1).collect();
    screen_order(&verifications, &config.verify)
        .into_iter()
        .take(keep)
        .map(|i| Placement {
            pose: placements[i],
            searched: Some(scored[i]),
        })
        .collect()
}

/// Where the correlative local search (`config.search`, if any) moves `placement`, and how
/// that pose verifies: what both screens look at.
fn searched(
    a: &PreparedMap,
    b: &PreparedMap,
    placement: &Rigid2,
    config: &PairConfig,
) -> (Rigid2, Verification) {
    let moved = config
        .search
        .as_ref()
        .map_or(*placement, |sc| local_search(a, b, placement, sc));
    (moved, verify(a, b, &moved, &config.verify))
}

/// The `keep` of `placements` that pass verification once searched (as [`screen`] searches
/// them), those the maps agree with most ([`Verification::score`]) first; none that fails.
/// Unlike the screen's, these placements are proposed only when nothing else passed, so one
/// that fails would only be declined again.
fn deep_screen(
    a: &PreparedMap,
    b: &PreparedMap,
    placements: Vec<Rigid2>,
    keep: usize,
    config: &PairConfig,
) -> Vec<Placement> {
    let mut passing: Vec<Placement> = placements
        .par_iter()
        .filter_map(|p| {
            let (moved, v) = searched(a, b, p, config);
            v.accepted(&config.verify).then_some(Placement {
                pose: *p,
                searched: Some((moved, v)),
            })
        })
        .collect();
    // Stable: ties keep the rankings' order.
    passing.sort_by(|x, y| {
        let score = |p: &Placement| p.searched.map_or(0.0, |(_, v)| v.score());
        score(y).total_cmp(&score(x))
    });
    passing.truncate(keep);
    passing
}

/// The order in which the screen keeps placements verified as `verifications`: those that pass
/// `config` first, then by [`Verification::score`], best first; ties keep the given order.
///
/// Passing comes first because the score grows with the compared walls: at 30 % overlap a
/// wrong placement laying most of B over A (wall lift 0.2-0.5, far from passing) outscores
/// the truth's small overlap (lift 0.6-0.85, passing) several times over, and the screen
/// dropped the truth for it (docs/EVALUATION.md, "The screen keeps passing placements").
fn screen_order(verifications: &[Verification], config: &VerifyConfig) -> Vec<usize> {
    let mut order: Vec<usize> = (0..verifications.len()).collect();
    order.sort_by(|&i, &j| {
        let (vi, vj) = (&verifications[i], &verifications[j]);
        vj.accepted(config)
            .cmp(&vi.accepted(config))
            .then(vj.score().total_cmp(&vi.score()))
    });
    order
}

/// `grid` on the bounding box of its known cells grown by `margin` cells on every side (see
/// [`PairConfig::frame_margin`]), and the position in `grid` of the frame's cell `(0, 0)`;
/// `grid` itself, at offset zero, when it has no known cell.
pub fn framed(grid: &OccupancyGrid, margin: usize) -> (OccupancyGrid, DVec2) {
    let Some((x0, y0, w, h)) = grid.known_bounds(0) else {
        return (grid.clone(), DVec2::ZERO);
    };
    let (fx, fy) = (x0 as i64 - margin as i64, y0 as i64 - margin as i64);
    let frame = grid
        .region(fx, fy, w + 2 * margin, h + 2 * margin)
        .expect("a known cell gives a non-empty frame");
    (frame, DVec2::new(fx as f64, fy as f64))
}

/// `t`, which maps pixels of B's frame onto A's frame, as a map of B's pixels onto A's, the
/// frames' cells `(0, 0)` lying at `oa` in A and `ob` in B (as [`framed`] gives them):
/// `p -> t(p - ob) + oa`.
pub fn unframed(t: &Rigid2, oa: DVec2, ob: DVec2) -> Rigid2 {
    let moved = t.apply(-ob) + oa;
    Rigid2::new(t.theta, moved.x, moved.y)
}

/// Register `b` onto `a` using the correspondences of `sources`.
///
/// Fails only for invalid settings ([`PairConfig::validate`]), before any work: a pair
/// without a trustworthy answer comes back with `accepted: None` and a reason, which the
/// binary turns into exit code 3.
pub fn register_with(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&(dyn CorrespondenceSource + Sync)],
    config: &PairConfig,
) -> Result<Registration, Error> {
    config.validate()?;
    Ok(register_framed(a, b, sources, config))
}

/// [`register_with`] for settings already checked: each map cut to its frame
/// ([`PairConfig::frame`]), registered, and the answer given in the maps' own pixels.
fn register_framed(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&(dyn CorrespondenceSource + Sync)],
    config: &PairConfig,
) -> Registration {
    let (Some((fa, oa)), Some((fb, ob))) = rayon::join(|| config.frame(a), || config.frame(b))
    else {
        return register_as_given(a, b, sources, config);
    };
    let mut r = register_as_given(&fa, &fb, sources, config);
    for c in r.accepted.iter_mut().chain(r.candidates.iter_mut()) {
        c.transform = unframed(&c.transform, oa, ob);
    }
    for m in &mut r.matches {
        (m.a, m.b) = (m.a + oa, m.b + ob);
    }
    r
}

/// Register `b` onto `a` with the method of `config`.
///
/// Fails only for invalid settings ([`RegisterConfig::validate`]), before any work; a pair
/// without a trustworthy answer comes back with `accepted: None` and a reason.
pub fn register(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    config: &RegisterConfig,
) -> Result<Registration, Error> {
    config.validate()?;
    let sift = SiftCorrespondences::new(config.sift.clone())?;
    let blobs = BlobCorrespondences {
        blobs: Blobs::new(config.blobs),
        matching: config.blob_matching,
    };
    let sources: Vec<&(dyn CorrespondenceSource + Sync)> = match config.method {
        Method::Sift => vec![&sift],
        Method::Blobs => vec![&blobs],
        Method::Hybrid => vec![&sift, &blobs],
    };
    // `config.validate` checked the pair settings too (under their `pair.` paths).
    Ok(register_framed(a, b, &sources, &config.pair))
}

#[cfg(test)]
mod tests;
