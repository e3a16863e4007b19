//! One pair's registration on the maps as given, stage by stage: the correspondences and the
//! maps' preparation, RANSAC's hypotheses, the whole-map searches, the ranking, then the
//! stages that settle the answer (symmetry probes, polish, the spectrum and Manhattan angles,
//! the turn scan, the ascent) and the rules that decline it.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use grid_core::{Correspondence, CorrespondenceSource, DVec2, OccupancyGrid, Rigid2};
use ransac_rigid::estimate_rigid;

use super::{
    APART_POINTS, Candidate, KindTotals, Origin, PairConfig, Placement, Registration, Timings,
    at_angle, contradiction_excess, deep_screen, fits_about_as_well, manhattan_rotation_near,
    mean_apart, ms, one_basin, refine_and_score, rivals, screen, short_of, standing_out,
    stands_out, unverified_reason, wall_centres,
};
use crate::ascent::{ascend, frontier_ratio, lone_wall_share, wall_thickness};
use crate::global::{
    SweepConfig, SweepPlacements, global_hypotheses, spectrum_rotation_near, sweep_placements,
    twins,
};
use crate::refine::{RefineConfig, refine_with_bias};
use crate::search::{SearchConfig, local_search};
use crate::verify::{
    PreparedMap, StandOut, Verification, agreeing_lever, agreeing_wall_spread_px, strided, verify,
    wall_residual_px,
};

/// [`super::register_with`] on the maps as given (no frames).
pub(super) fn register_as_given(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&(dyn CorrespondenceSource + Sync)],
    config: &PairConfig,
) -> Registration {
    let mut timings = Timings::default();
    // The sources, and the maps' preparation for verification, are independent: run them
    // side by side (their times overlap). Sources are concatenated in the given order.
    let ((corrs, correspondences_ms), ((pa, pb), prepare_ms)) = rayon::join(
        || {
            let t0 = Instant::now();
            let parts: Vec<Vec<Correspondence>> = sources
                .par_iter()
                .map(|s| {
                    let mut out = Vec::new();
                    s.correspondences(a, b, &mut out);
                    out
                })
                .collect();
            (parts.concat(), ms(t0))
        },
        || {
            let t0 = Instant::now();
            let maps = rayon::join(
                || PreparedMap::new(a, &config.verify),
                || PreparedMap::new(b, &config.verify),
            );
            (maps, ms(t0))
        },
    );
    timings.correspondences_ms = correspondences_ms;
    timings.prepare_ms = prepare_ms;
    let correspondences = KindTotals::of(&corrs, 0..corrs.len());
    let declined = |reason: String, timings, candidates| Registration {
        accepted: None,
        reason: Some(reason),
        candidates,
        correspondences,
        inliers: KindTotals::default(),
        timings,
        matches: corrs.clone(),
    };
    let run = PairRun::new(pa, pb, config);
    if let Some(reason) = run.unplaceable() {
        return declined(reason, timings, Vec::new());
    }

    let t0 = Instant::now();
    let ransac = estimate_rigid(&corrs, &config.ransac);
    timings.ransac_ms = ms(t0);
    let hypotheses = ransac
        .as_ref()
        .map(|r| r.hypotheses.as_slice())
        .unwrap_or_default();
    let t0 = Instant::now();
    let mut candidates: Vec<Candidate> = hypotheses
        .par_iter()
        .map(|h| Candidate {
            ransac_inliers: h.inliers_count,
            ransac_confidence: h.confidence,
            ..run.check(&h.model, &config.refine, Origin::Ransac)
        })
        .collect();
    timings.verify_ms = ms(t0);
    run.whole_map_searches(&mut candidates, &mut timings);
    run.rank(&mut candidates);
    run.settle_answer(&mut candidates, &mut timings);
    if let Some(reason) = run.declined_answer(&candidates)
        && !run.succeed(&mut candidates, &mut timings)
    {
        return declined(reason, timings, candidates);
    }
    match candidates.first() {
        Some(best) if best.accepted => {
            // Inliers of the final (refined) transform, so the split by kind describes the answer.
            let t = best.transform;
            let close = corrs
                .iter()
                .enumerate()
                .filter(|(_, c)| (c.a - t.apply(c.b)).length() <= config.ransac.threshold_px);
            let inliers = KindTotals::of(&corrs, close.map(|(i, _)| i));
            Registration {
                accepted: Some(best.clone()),
                reason: None,
                candidates,
                correspondences,
                inliers,
                timings,
                matches: corrs,
            }
        }
        Some(best) => {
            let reason = unverified_reason(&best.verification, &config.verify, run.lone_shares());
            declined(reason, timings, candidates)
        }
        None => {
            let why = match &ransac {
                Err(e) => format!("no transform hypothesis: {e}"),
                Ok(_) => "no transform hypothesis".into(),
            };
            declined(why, timings, candidates)
        }
    }
}

/// The highest-scoring of `scored` (the first of equals), if any.
fn highest(scored: Vec<(Rigid2, Verification)>) -> Option<(Rigid2, Verification)> {
    scored.into_iter().reduce(|best, p| {
        if p.1.score() > best.1.score() {
            p
        } else {
            best
        }
    })
}

/// [`highest`] of a non-empty list.
fn best_of(scored: Vec<(Rigid2, Verification)>) -> (Rigid2, Verification) {
    highest(scored).expect("at least one start")
}

/// A pair under registration: both maps prepared, the settings, and what is worked out once
/// and asked by several stages.
struct PairRun<'m> {
    pa: PreparedMap<'m>,
    pb: PreparedMap<'m>,
    config: &'m PairConfig,
    /// B's walls, strided: where [`Self::apart`] measures two placements apart.
    probe: Vec<DVec2>,
    /// Both maps' shares of lone wall cells (the turn scan's gate and the clean-walls bar),
    /// scanned once, when first needed.
    lone: OnceLock<(f64, f64)>,
    /// The sweep's placements, B's walls over A's field and the other way round, swept once,
    /// when first needed, for the screen and for the deep screen.
    sweeps: [OnceLock<SweepPlacements>; 2],
    /// Whether the deep screen ran (nothing passed before it): the answer must then share
    /// no less than a small overlap (see [`Self::declined_answer`]).
    deep_screened: AtomicBool,
}

impl<'m> PairRun<'m> {
    fn new(pa: PreparedMap<'m>, pb: PreparedMap<'m>, config: &'m PairConfig) -> Self {
        let probe = strided(&pb.wall_samples, APART_POINTS);
        Self {
            pa,
            pb,
            config,
            probe,
            lone: OnceLock::new(),
            sweeps: [OnceLock::new(), OnceLock::new()],
            deep_screened: AtomicBool::new(false),
        }
    }

    /// Why the pair cannot be placed whatever the transform, if so: a map with fewer known
    /// cells than an answer must share, or too few walls (walls are what a placement is
    /// judged by). Said at once, rather than through whichever rule declines its placements
    /// or as "no transform hypothesis" after the samplers have drawn in vain.
    fn unplaceable(&self) -> Option<String> {
        let (pa, pb, verify) = (&self.pa, &self.pb, &self.config.verify);
        let (which, smaller) = if pa.known_cells <= pb.known_cells {
            ("A", pa.known_cells)
        } else {
            ("B", pb.known_cells)
        };
        if smaller < verify.min_overlap_cells {
            return Some(format!(
                "too small: map {which} has {smaller} known cells, fewer than the {} an answer must share with the other map",
                verify.min_overlap_cells
            ));
        }
        let (walls_a, walls_b) = (pa.occupied_cells, pb.occupied_cells);
        if walls_a == 0 || walls_b == 0 {
            let which = if walls_a == 0 { "A" } else { "B" };
            return Some(format!(
                "no walls: map {which} has no occupied cell, and walls are what a placement is judged by"
            ));
        }
        if walls_a + walls_b < verify.min_wall_support {
            return Some(format!(
                "too few walls: the maps have {} occupied cells together, fewer than the {} an answer must compare",
                walls_a + walls_b,
                verify.min_wall_support
            ));
        }
        None
    }

    fn lone_shares(&self) -> (f64, f64) {
        *self.lone.get_or_init(|| {
            rayon::join(
                || lone_wall_share(self.pa.grid),
                || lone_wall_share(self.pb.grid),
            )
        })
    }

    /// How far apart two placements put B's walls, on average (the ambiguity test's and the
    /// stand-out rule's measure of "different").
    fn apart(&self, x: &Rigid2, y: &Rigid2) -> f64 {
        mean_apart(&self.probe, x, y)
    }

    /// The poses a hypothesis is refined from (see [`Self::polished`]).
    ///
    /// Each hypothesis is polished by ICP, once from itself and once from the best pose of the
    /// correlative local search around it (keypoints, or a whole-map search's coarse grid, can
    /// put it a few pixels off, outside ICP's narrow basin), and for whole-map placements once
    /// more from the best pose of the turn search; the polished pose the maps agree with most
    /// wins (the first of equals). A whole-map placement is refined from itself only when
    /// neither search moved it, unless `refine_placements_as_proposed`. Global hypotheses
    /// refine with their own, wider-gated configuration.
    fn starts(&self, placement: &Placement, origin: Origin) -> Vec<Rigid2> {
        let config = self.config;
        let model = &placement.pose;
        // Whole-map placements are also searched over rotation.
        let turn_search = if origin == Origin::Ransac {
            None
        } else {
            config.turn_search.as_ref()
        };
        let searched = |sc: Option<&SearchConfig>| {
            let moved = local_search(&self.pa, &self.pb, model, sc?);
            (moved != *model).then_some(moved)
        };
        // The searches are independent: run them side by side.
        let (searched, turned) = rayon::join(
            || match placement.searched {
                Some((moved, _)) => (moved != *model).then_some(moved),
                None => searched(config.search.as_ref()),
            },
            || searched(turn_search),
        );
        let from_itself = turn_search.is_none()
            || config.refine_placements_as_proposed
            || (searched.is_none() && turned.is_none());
        [from_itself.then_some(*model), searched, turned]
            .into_iter()
            .flatten()
            .collect()
    }

    fn candidate(
        &self,
        (transform, verification): (Rigid2, Verification),
        origin: Origin,
    ) -> Candidate {
        let accepted = verification.accepted(&self.config.verify);
        Candidate::scored(transform, verification, accepted, origin)
    }

    /// Each of `starts` refined and scored, the best kept.
    fn polished(&self, starts: &[Rigid2], refine: &RefineConfig, origin: Origin) -> Candidate {
        // Side by side: the refinements are independent.
        let scored: Vec<(Rigid2, Verification)> = starts
            .par_iter()
            .map(|s| refine_and_score(&self.pa, &self.pb, s, refine, self.config))
            .collect();
        self.candidate(best_of(scored), origin)
    }

    fn check(&self, model: &Rigid2, refine: &RefineConfig, origin: Origin) -> Candidate {
        self.polished(
            &self.starts(&Placement::unsearched(*model), origin),
            refine,
            origin,
        )
    }

    /// The placements of one whole-map search: every placement is searched, and when there are
    /// more than `refined_placements`, only those whose best start the maps agree with most
    /// are refined; the others are kept at that start, as verified there.
    fn check_placements(&self, models: &[Placement], origin: Origin) -> Vec<Candidate> {
        let config = self.config;
        let starts: Vec<Vec<Rigid2>> = models.par_iter().map(|m| self.starts(m, origin)).collect();
        let refined_all = config.refined_placements.is_none_or(|k| models.len() <= k);
        if refined_all {
            return starts
                .par_iter()
                .map(|s| self.polished(s, &config.global_refine, origin))
                .collect();
        }
        // A start the screen verified is not verified again.
        let at_start: Vec<(Rigid2, Verification)> = starts
            .par_iter()
            .zip(models)
            .map(|(s, m)| {
                best_of(
                    s.iter()
                        .map(|p| match m.searched {
                            Some((q, v)) if q == *p => (*p, v),
                            _ => (*p, verify(&self.pa, &self.pb, p, &config.verify)),
                        })
                        .collect(),
                )
            })
            .collect();
        let mut order: Vec<usize> = (0..models.len()).collect();
        order.sort_by(|&i, &j| at_start[j].1.score().total_cmp(&at_start[i].1.score()));
        let mut refine = vec![false; models.len()];
        for &i in order
            .iter()
            .take(config.refined_placements.unwrap_or(usize::MAX))
        {
            refine[i] = true;
        }
        (0..models.len())
            .into_par_iter()
            .map(|i| {
                if refine[i] {
                    self.polished(&starts[i], &config.global_refine, origin)
                } else {
                    Candidate {
                        refined: false,
                        ..self.candidate(at_start[i], origin)
                    }
                }
            })
            .collect()
    }

    /// The placements `generate` gives, checked like the feature-based ones with the global
    /// refinement (they come from a coarse grid), and the milliseconds it took.
    fn search(
        &self,
        generate: &dyn Fn(&mut Vec<Placement>),
        origin: Origin,
    ) -> (Vec<Candidate>, f64) {
        let t0 = Instant::now();
        let mut models = Vec::new();
        generate(&mut models);
        (self.check_placements(&models, origin), ms(t0))
    }

    /// A feature-based candidate that passed with at least `bar` of wall lift.
    fn confident(c: &Candidate, bar: f64) -> bool {
        c.accepted && c.origin == Origin::Ransac && c.verification.wall_lift >= bar
    }

    /// The sweep's placements as swept, B's walls turned over A's field or, with `reverse`, A's
    /// over B's: the normalised ranking as deep as the deep screen reaches, so that one sweep
    /// serves both screens (the first placements of a ranking do not depend on how many are
    /// taken).
    fn sweep(&self, sweep: &SweepConfig, reverse: bool) -> &SweepPlacements {
        self.sweeps[usize::from(reverse)].get_or_init(|| {
            let (field, moving) = if reverse {
                (&self.pb, &self.pa)
            } else {
                (&self.pa, &self.pb)
            };
            let count = sweep.screen_depth().max(sweep.deep_screened);
            sweep_placements(field, moving, sweep, count)
        })
    }

    /// `placements` of the sweep with `reverse`, as maps of B onto A.
    fn onto_a(placements: &[Rigid2], reverse: bool) -> Vec<Rigid2> {
        if reverse {
            placements
                .iter()
                .map(|t| t.inverse().normalized())
                .collect()
        } else {
            placements.to_vec()
        }
    }

    /// The sweep's placements, as maps of B onto A: B's walls turned over A's field, or with
    /// `reverse` A's over B's, the placements then inverted.
    fn swept(&self, reverse: bool) -> Vec<Placement> {
        let Some(sweep) = &self.config.sweep else {
            return Vec::new();
        };
        let found = self.sweep(sweep, reverse);
        let screened = sweep.screen_depth();
        let normalized = &found.normalized[..found.normalized.len().min(screened)];
        let mut out: Vec<Placement> = Self::onto_a(&found.plain, reverse)
            .into_iter()
            .map(Placement::unsearched)
            .collect();
        out.extend(screen(
            &self.pa,
            &self.pb,
            Self::onto_a(normalized, reverse),
            sweep.keep_normalized,
            self.config,
        ));
        out
    }

    /// The deep screen (see [`SweepConfig::deep_screened`]): the placements of both sweeps'
    /// normalised rankings after the screened ones, searched and verified, and of those that
    /// pass the `keep_normalized` the maps agree with most.
    fn deep_swept(&self) -> Vec<Placement> {
        let Some(sweep) = &self.config.sweep else {
            return Vec::new();
        };
        let screened = sweep.screen_depth();
        let deeper: Vec<Rigid2> = [false, true]
            .into_iter()
            .flat_map(|reverse| {
                let normalized = &self.sweep(sweep, reverse).normalized;
                let end = normalized.len().min(sweep.deep_screened);
                Self::onto_a(normalized.get(screened..end).unwrap_or(&[]), reverse)
            })
            .collect();
        deep_screen(
            &self.pa,
            &self.pb,
            deeper,
            sweep.keep_normalized,
            self.config,
        )
    }

    /// The whole-map searches, their candidates added to `candidates`: the global search
    /// when nothing passed, and the sweep unless a feature-based candidate passed with a good
    /// fit. Keypoint matches that agree and walls that agree are two kinds of evidence; one
    /// kind alone (a Hough-spectrum placement, or a weak fit) can be a wrong placement on
    /// repetitive walls, or a poorer local optimum near the right one. The sweep then proposes
    /// the better fit (which wins) or a rival (and the pair is declined as ambiguous).
    fn whole_map_searches(&self, candidates: &mut Vec<Candidate>, timings: &mut Timings) {
        let config = self.config;
        if let Some(global) = &config.global
            && !candidates.iter().any(|c| c.accepted)
        {
            let (found, t) = self.search(
                &|out| {
                    let mut found = Vec::new();
                    global_hypotheses(&self.pa, &self.pb, global, &mut found);
                    out.extend(found.into_iter().map(Placement::unsearched));
                },
                Origin::Global,
            );
            candidates.extend(found);
            timings.global_ms = t;
        }
        if let Some(sweep) = &config.sweep
            && !candidates
                .iter()
                .any(|c| Self::confident(c, sweep.confident_wall_lift))
        {
            let (found, t) = self.search(&|out| out.extend(self.swept(false)), Origin::Sweep);
            candidates.extend(found);
            timings.sweep_ms = t;
            // Nothing passed, or the best that passed would be declined (walls in the other
            // map's free space, a misfit, a rival): the other way round (see
            // `SweepConfig::reverse`).
            if sweep.reverse && {
                self.rank(candidates);
                !candidates.first().is_some_and(|c| c.accepted)
                    || self.declined_answer(candidates).is_some()
            } {
                let (found, t) = self.search(&|out| out.extend(self.swept(true)), Origin::Sweep);
                candidates.extend(found);
                timings.sweep_ms += t;
            }
            // Still nothing passed: deeper down both rankings (see
            // `SweepConfig::deep_screened`).
            if sweep.deep_screened > sweep.screen_depth() && {
                self.rank(candidates);
                !candidates.first().is_some_and(|c| c.accepted)
            } {
                self.deep_screened.store(true, Ordering::Relaxed);
                let (found, t) = self.search(&|out| out.extend(self.deep_swept()), Origin::Sweep);
                candidates.extend(found);
                timings.sweep_ms += t;
            }
        }
    }

    /// A whole-map placement kept where its search led, refined now that it matters.
    fn settle(&self, c: &mut Candidate) {
        if !c.refined {
            let scored = refine_and_score(
                &self.pa,
                &self.pb,
                &c.transform,
                &self.config.global_refine,
                self.config,
            );
            *c = self.candidate(scored, c.origin);
        }
    }

    /// Best first; the best is always a refined candidate.
    fn rank(&self, candidates: &mut [Candidate]) {
        loop {
            candidates.sort_by(|x, y| {
                y.accepted
                    .cmp(&x.accepted)
                    .then(y.verification.score().total_cmp(&x.verification.score()))
            });
            match candidates.first_mut() {
                Some(best) if !best.refined => self.settle(best),
                _ => break,
            }
        }
    }

    /// The candidate that stands out from every other under `rule`, refined, if any (see
    /// [`StandOut`]).
    fn refined_standing_out(&self, candidates: &mut [Candidate], rule: &StandOut) -> Option<usize> {
        loop {
            let i = standing_out(candidates, rule, &self.config.verify, &|x, y| {
                self.apart(x, y)
            })?;
            if candidates[i].refined {
                return Some(i);
            }
            self.settle(&mut candidates[i]);
        }
    }

    /// Whether a candidate's walls agree almost everywhere: the polish's case, which the
    /// spectrum angle and the ascent (made for noisy walls) leave alone.
    fn clean(&self, c: &Candidate) -> bool {
        self.config
            .polish
            .is_some_and(|p| c.verification.wall_lift >= p.min_wall_lift)
    }

    /// The stages that settle the ranked candidates' answer, in order: a placement that stands
    /// out, the symmetry probes, the polish of a clean answer, its angle from the spectra or
    /// from the dominant wall directions, the turn scan and the ascent.
    fn settle_answer(&self, candidates: &mut Vec<Candidate>, timings: &mut Timings) {
        let config = self.config;
        let apart = |x: &Rigid2, y: &Rigid2| self.apart(x, y);
        // Nothing passed the bars: a placement may still stand out from every other (speckled
        // walls of a very noisy sensor). It is then probed for twins like any accepted answer.
        if let Some(rule) = &config.verify.stand_out
            && candidates.first().is_some_and(|c| !c.accepted)
            && let Some(i) = self.refined_standing_out(candidates, rule)
        {
            candidates[i].accepted = true;
            candidates[i].stands_out = true;
            self.rank(candidates);
        }
        if config.symmetry_probes
            && let Some(best) = candidates
                .first()
                .filter(|c| c.accepted && !Self::confident(c, config.symmetry_confident_wall_lift))
        {
            let t0 = Instant::now();
            let mut probes = Vec::new();
            twins(
                &self.pa,
                &self.pb,
                &best.transform,
                &config.global.unwrap_or_default(),
                &mut probes,
            );
            let probes: Vec<Placement> = probes.into_iter().map(Placement::unsearched).collect();
            candidates.extend(self.check_placements(&probes, Origin::Symmetry));
            self.rank(candidates);
            timings.symmetry_ms = ms(t0);
        }
        // A placement that stood out must still stand out from the twins the probes found.
        if let Some(rule) = &config.verify.stand_out
            && let Some(best) = candidates.first()
            && best.stands_out
            && !stands_out(candidates, best, rule, &config.verify, &apart)
        {
            candidates[0].accepted = false;
            candidates[0].stands_out = false;
            self.rank(candidates);
        }
        self.refine_answer(candidates, timings);
    }

    /// The stages that settle the answer's pose: the polish of a clean answer, its angle from
    /// the spectra or from the dominant wall directions, the turn scan and the ascent.
    fn refine_answer(&self, candidates: &mut [Candidate], timings: &mut Timings) {
        self.polish(candidates);
        self.spectrum_angle(candidates);
        let angle_from_walls = self.manhattan_angle(candidates);
        self.turn_scan(candidates, angle_from_walls);
        self.climb(candidates, timings);
    }

    /// The best-ranked candidate that may succeed the declined best (see
    /// [`crate::verify::CleanSuccessor`]), refined if it was not; its index.
    fn successor(&self, candidates: &mut [Candidate]) -> Option<usize> {
        let best = candidates.first().filter(|b| b.accepted)?.clone();
        for (i, c) in candidates.iter_mut().enumerate().skip(1) {
            if !self.succeeds(c, &best) {
                continue;
            }
            if !c.refined {
                self.settle(c);
                if !self.succeeds(c, &best) {
                    continue;
                }
            }
            return Some(i);
        }
        None
    }

    /// Whether `c` may succeed the declined `best` as it stands (see
    /// [`crate::verify::CleanSuccessor`]); never without the rule.
    fn succeeds(&self, c: &Candidate, best: &Candidate) -> bool {
        let verify = &self.config.verify;
        let Some(rule) = &verify.clean_successor else {
            return false;
        };
        let v = &c.verification;
        c.accepted
            && rule.fits_cleanly(v)
            && v.score() >= verify.max_ambiguity * best.verification.score()
            && best.verification.wall_contradiction
                > v.wall_contradiction + contradiction_excess(v, verify)
            && self.apart(&c.transform, &best.transform) > verify.distinct_px
    }

    /// The declined best succeeded by a clean placement, if one may succeed it (see
    /// [`crate::verify::CleanSuccessor`]): it is put first, its pose settled by the answer's
    /// stages, and it must pass the answer's bars. Whether it did; if not, `candidates` are
    /// left as they were.
    fn succeed(&self, candidates: &mut Vec<Candidate>, timings: &mut Timings) -> bool {
        // Only a candidate that may succeed before it is settled is settled (`successor`), so
        // where none may, nothing changes and nothing need be kept to restore.
        let Some(best) = candidates.first().filter(|b| b.accepted) else {
            return false;
        };
        if !candidates[1..].iter().any(|c| self.succeeds(c, best)) {
            return false;
        }
        let before = candidates.clone();
        let Some(i) = self.successor(candidates) else {
            *candidates = before;
            return false;
        };
        let successor = candidates.remove(i);
        candidates.insert(0, successor);
        self.refine_answer(candidates, timings);
        if self.declined_answer(candidates).is_some() {
            *candidates = before;
            return false;
        }
        true
    }

    /// The best candidate, when clean, is polished (only the best: on the 2048 bench pair
    /// polishing every RANSAC candidate cost about 35 ms).
    fn polish(&self, candidates: &mut [Candidate]) {
        let (pa, pb, config) = (&self.pa, &self.pb, self.config);
        if let Some(polish) = &config.polish
            && let Some(best) = candidates
                .first_mut()
                .filter(|c| c.accepted && self.clean(c))
        {
            let t = refine_with_bias(pa, pb, &best.transform, &polish.refine)
                .0
                .normalized();
            let v = verify(pa, pb, &t, &config.verify);
            if v.wall_lift >= polish.min_wall_lift && v.accepted(&config.verify) {
                (best.transform, best.verification) = (t, v);
            }
        }
    }

    /// The best candidate's angle from the walls' Hough spectra (see `SpectrumRotation`).
    fn spectrum_angle(&self, candidates: &mut [Candidate]) {
        let (pa, pb, config) = (&self.pa, &self.pb, self.config);
        if let Some(sr) = &config.spectrum_rotation
            && let Some(best) = candidates
                .first_mut()
                .filter(|c| c.accepted && !self.clean(c))
            && wall_residual_px(pa, pb, &best.transform, 3.0, sr.max_points)
                .is_some_and(|r| r >= sr.min_wall_residual_px)
            && agreeing_wall_spread_px(pa, pb, &best.transform, 3.0)
                .is_some_and(|spread| spread < sr.max_lever_px)
            && let Some(theta) = spectrum_rotation_near(
                pa,
                pb,
                best.transform.theta,
                sr.bins,
                sr.max_points,
                sr.max_delta_deg.to_radians(),
            )
            && let Some((t, v)) = at_angle(pa, pb, &best.transform, theta, config)
        {
            // A placement that stood out keeps the angle if it stays above the rule's bars.
            let still_out = best.stands_out
                && config
                    .verify
                    .stand_out
                    .is_some_and(|r| r.admits(&v, &config.verify));
            if v.accepted(&config.verify) || still_out {
                (best.transform, best.verification) = (t.normalized(), v);
            }
        }
    }

    /// The best candidate's angle from the maps' dominant wall directions (see
    /// `ManhattanRotation`); whether it was taken.
    fn manhattan_angle(&self, candidates: &mut [Candidate]) -> bool {
        let (pa, pb, config) = (&self.pa, &self.pb, self.config);
        if let Some(mr) = &config.manhattan_rotation
            && let Some(best) = candidates
                .first_mut()
                .filter(|c| c.accepted && !self.clean(c))
            && wall_residual_px(pa, pb, &best.transform, 3.0, mr.max_points)
                .is_some_and(|r| r >= mr.min_wall_residual_px)
            && agreeing_lever(pa, pb, &best.transform, 3.0).is_some_and(|(spread, ratio)| {
                spread >= mr.min_lever_px && ratio >= mr.min_reach_ratio
            })
            && let Some(theta) = manhattan_rotation_near(pa, pb, best.transform.theta, mr)
            && let Some((t, v)) = at_angle(pa, pb, &best.transform, theta, config)
            && v.accepted(&config.verify)
            && v.wall_lift >= best.verification.wall_lift - mr.max_lift_drop
        {
            (best.transform, best.verification) = (t.normalized(), v);
            return true;
        }
        false
    }

    /// Why the bars for maps with clean walls decline a placement verified as `v`, if they do
    /// (`VerifyConfig::clean_walls`, then `clean_fit`): the rescue of the turn scan asks it,
    /// and the answer is declined for it.
    fn clean_walls_misfit(&self, v: &Verification) -> Option<String> {
        let config = self.config;
        if let Some(clean) = &config.verify.clean_walls {
            let (sa, sb) = self.lone_shares();
            let bar = clean.bar(sa, sb);
            if v.mutual_contradiction > bar {
                return Some(format!(
                    "contradicted: each map puts {:.1} % or more of its compared walls in the other's free space, where maps with walls this clean (lone wall cells {:.1} % and {:.1} %) allow {:.1} %",
                    100.0 * v.mutual_contradiction,
                    100.0 * sa,
                    100.0 * sb,
                    100.0 * bar
                ));
            }
        }
        if let Some(fit) = &config.verify.clean_fit {
            let (sa, sb) = self.lone_shares();
            if fit.falls_short(v.wide_wall_lift, sa, sb) {
                return Some(format!(
                    "misfit: both maps draw their walls cleanly (lone wall cells {:.1} % and {:.1} %), where a right placement fits its walls at wide lift {:.2} or more; the best fits at {}",
                    100.0 * sa,
                    100.0 * sb,
                    fit.min_wide_wall_lift,
                    short_of(v.wide_wall_lift, fit.min_wide_wall_lift)
                ));
            }
        }
        None
    }

    /// The answer's angle scanned about its overlap (see `TurnScan`), unless it was polished or
    /// stood out, as the ascent below, or took the Manhattan angle.
    fn turn_scan(&self, candidates: &mut [Candidate], angle_from_walls: bool) {
        let (pa, pb, config) = (&self.pa, &self.pb, self.config);
        if let Some(scan) = &config.turn_scan
            && !(angle_from_walls && scan.keep_manhattan_angle)
            && let Some(best) = candidates
                .first_mut()
                .filter(|c| c.accepted && !c.stands_out && !self.clean(c))
        {
            let from = best.transform;
            let lever =
                wall_centres(pa, pb, &from).map_or(0.0, |(shared, all)| (shared - all).length());
            let alike = || {
                let (sa, sb) = self.lone_shares();
                sa.max(sb) <= scan.max_speckle_ratio * sa.min(sb)
            };
            let rescue =
                scan.rescue_misfits && self.clean_walls_misfit(&best.verification).is_some();
            let turns = if rescue || (lever >= scan.min_lever_px && alike()) {
                scan.turns()
            } else {
                Vec::new()
            };
            let passing: Vec<(Rigid2, Verification)> = turns
                .par_iter()
                .filter_map(|d| {
                    at_angle(pa, pb, &from, from.theta + d, config)
                        .filter(|(_, v)| v.accepted(&config.verify))
                })
                .collect();
            if let Some((t, v)) = highest(passing)
                && v.score() > best.verification.score()
            {
                if rescue {
                    // The turn found the basin; ICP finds the pose in it (see
                    // `TurnScan::rescue_misfits`).
                    let polished = config.polish.map(|polish| {
                        let p = refine_with_bias(pa, pb, &t, &polish.refine).0.normalized();
                        (p, verify(pa, pb, &p, &config.verify))
                    });
                    let clears = |v: &Verification| {
                        v.accepted(&config.verify)
                            && v.score() > best.verification.score()
                            && self.clean_walls_misfit(v).is_none()
                    };
                    if let Some((p, pv)) = polished.filter(|(_, pv)| clears(pv)) {
                        (best.transform, best.verification) = (p, pv);
                    } else if clears(&v) {
                        (best.transform, best.verification) = (t.normalized(), v);
                    }
                } else {
                    (best.transform, best.verification) = (t.normalized(), v);
                }
            }
        }
    }

    /// The answer climbs the verification score (see `crate::ascent`), unless it was polished
    /// (walls that agree almost everywhere: ICP's pose is then sub-pixel, the score's counts at
    /// whole cells are not) or stood out (the bars it passed are not those the score ranks).
    fn climb(&self, candidates: &mut [Candidate], timings: &mut Timings) {
        let (pa, pb, config) = (&self.pa, &self.pb, self.config);
        if let Some(ascent) = &config.ascent
            && let Some(best) = candidates
                .first_mut()
                .filter(|c| c.accepted && !c.stands_out && !self.clean(c))
        {
            let t0 = Instant::now();
            let (ta, tb) = rayon::join(|| wall_thickness(pa.grid), || wall_thickness(pb.grid));
            let short_range = || {
                ascent.short_range.is_some_and(|sr| {
                    best.verification.wall_lift < sr.max_wall_lift && {
                        let (fa, fb) =
                            rayon::join(|| frontier_ratio(pa.grid), || frontier_ratio(pb.grid));
                        fa.min(fb) >= sr.min_frontier_ratio
                    }
                })
            };
            if ta.min(tb) >= ascent.min_wall_thickness || short_range() {
                let (t, v) = ascend(pa, pb, &best.transform, ascent, &config.verify);
                if t != best.transform && v.accepted(&config.verify) {
                    (best.transform, best.verification) = (t, v);
                }
            }
            timings.ascent_ms += ms(t0);
        }
    }

    /// Why the answer (the first candidate, if accepted) is declined after all, if it is: a
    /// rival placement (ambiguity), or walls in the other map's free space, or too little
    /// overlap.
    fn declined_answer(&self, candidates: &[Candidate]) -> Option<String> {
        let config = self.config;
        let best = candidates.first().filter(|b| b.accepted)?;
        // Ambiguity: another accepted, clearly different placement that scores almost as
        // well. "Different" is measured where it matters: how far apart the two put B's walls.
        let rival = candidates.iter().skip(1).find(|c| {
            rivals(&best.verification, c, &config.verify)
                && self.apart(&c.transform, &best.transform) > config.verify.distinct_px
                && !one_basin(
                    &self.pa,
                    &self.pb,
                    &best.transform,
                    &c.transform,
                    &config.verify,
                )
        });
        if let Some(rival) = rival {
            let (b, r) = (&best.verification, &rival.verification);
            return Some(if fits_about_as_well(b, r, &config.verify) {
                format!(
                    "ambiguous: two different placements fit almost equally well (scores {:.0} and {:.0}); the maps share too little distinctive structure",
                    b.score(),
                    r.score()
                )
            } else {
                format!(
                    "ambiguous: the best placement fits imperfectly (wide wall lift {:.2}, score {:.0}) and a clearly different one passes too (wide wall lift {:.2}, score {:.0}); repeated structure fits more than one way",
                    b.wide_wall_lift,
                    b.score(),
                    r.wide_wall_lift,
                    r.score()
                )
            });
        }
        // An answer that leaves much of its wall in the other map's free space is declined
        // (see `VerifyConfig::max_wall_contradiction` and `crisp_wall_lift`); it has served as
        // a rival above.
        let v = &best.verification;
        if v.wall_contradiction > config.verify.max_wall_contradiction {
            return Some(format!(
                "contradicted: {:.0} % of the best placement's compared walls lie in the other map's free space (at most {:.0} % accepted)",
                100.0 * v.wall_contradiction,
                100.0 * config.verify.max_wall_contradiction
            ));
        }
        if let Some(reason) = self.clean_walls_misfit(v) {
            return Some(reason);
        }
        if let Some(bar) = v.crisp_contradiction_bar(&config.verify)
            && v.mutual_contradiction > bar
        {
            return Some(format!(
                "contradicted: the best placement lays walls on walls crisply (wall lift {:.2}) yet each map puts {:.1} % or more of its compared walls in the other's free space (at most {:.1} % accepted at that fit); it matches part of a layout that repeats, not the overlap",
                v.wall_lift,
                100.0 * v.mutual_contradiction,
                100.0 * bar
            ));
        }
        if let Some(small) = &config.verify.small_overlap
            && small.falls_short(v)
        {
            return Some(format!(
                "sliver: the best placement shares {:.0} % of the smaller map's known cells, and an overlap under {:.0} % is accepted only where the walls fit almost everywhere (wide wall lift {:.2} or more; this one {})",
                100.0 * v.overlap_fraction,
                100.0 * small.below,
                small.min_wide_wall_lift,
                short_of(v.wide_wall_lift, small.min_wide_wall_lift)
            ));
        }
        // Found only deep down the sweeps' rankings, where thousands of placements were tried,
        // a sliver is what chance gives, however well its walls fit (see
        // `SweepConfig::deep_screened`).
        if let Some(small) = &config.verify.small_overlap
            && self.deep_screened.load(Ordering::Relaxed)
            && v.overlap_fraction < small.below
        {
            return Some(format!(
                "sliver: nothing passed until the deep screen, and the placement it found shares {:.0} % of the smaller map's known cells; found that deep, a placement must share {:.0} %",
                100.0 * v.overlap_fraction,
                100.0 * small.below
            ));
        }
        if v.too_small(&config.verify) {
            return Some(format!(
                "too small: the best placement shares {} cells known in both maps, and at least {} are needed (it covers {:.0} % of the smaller map, which fits inside the other almost anywhere)",
                v.overlap_cells,
                config.verify.min_overlap_cells,
                100.0 * v.overlap_fraction
            ));
        }
        None
    }
}
