//! Range checks of every number in the settings, run before any work
//! ([`RegisterConfig::validate`], [`PairConfig::validate`], [`TeamConfig::validate`]).
//!
//! Without them a NaN bar makes every comparison false and every pair is declined without a
//! word, and a step of 0 asks for an endless grid. The checks are loose on purpose: a bar
//! may be any number but NaN (an infinite bar switches its test off, as the docs of several
//! bars say), a step or a kernel width must be finite and positive, a count that sizes a grid
//! at least 1.

use std::fmt;

use crate::global::{GlobalConfig, SweepConfig};
use crate::refine::RefineConfig;
use crate::search::SearchConfig;
use crate::team::TeamConfig;
use crate::verify::VerifyConfig;
use crate::{Error, PairConfig, RegisterConfig};

/// What a setting must be (named in [`Error::Setting`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    /// Any number but NaN: a bar, where an infinity switches the test off.
    NotNan,
    /// A finite number.
    Finite,
    /// `>= 0`; infinity allowed.
    NonNegative,
    /// `>= 0` and finite.
    FiniteNonNegative,
    /// `> 0` and finite: a step, a kernel width, a gate.
    FinitePositive,
    /// At least 1: a count that sizes a grid or a sample.
    AtLeastOne,
}

impl Rule {
    /// Whether `value` obeys the rule.
    pub fn holds(self, value: f64) -> bool {
        match self {
            Rule::NotNan => !value.is_nan(),
            Rule::Finite => value.is_finite(),
            Rule::NonNegative => value >= 0.0,
            Rule::FiniteNonNegative => value.is_finite() && value >= 0.0,
            Rule::FinitePositive => value.is_finite() && value > 0.0,
            Rule::AtLeastOne => value >= 1.0,
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Rule::NotNan => "a number (not NaN)",
            Rule::Finite => "a finite number",
            Rule::NonNegative => "0 or more",
            Rule::FiniteNonNegative => "a finite number, 0 or more",
            Rule::FinitePositive => "a finite number above 0",
            Rule::AtLeastOne => "at least 1",
        })
    }
}

/// The settings under one path (`pair.verify`, ...), checked field by field.
struct Fields<'p>(&'p str);

impl Fields<'_> {
    /// `Err` naming `path.name` unless `value` obeys `rule`.
    fn check(&self, name: &str, value: f64, rule: Rule) -> Result<(), Error> {
        if rule.holds(value) {
            return Ok(());
        }
        Err(Error::Setting {
            name: self.path(name),
            value,
            rule,
        })
    }

    /// Every `(name, value)` of `values` against `rule`.
    fn all(&self, rule: Rule, values: &[(&str, f64)]) -> Result<(), Error> {
        values
            .iter()
            .try_for_each(|&(name, value)| self.check(name, value, rule))
    }

    /// `name` under this path (alone at the top level, whose path is empty).
    fn path(&self, name: &str) -> String {
        if self.0.is_empty() {
            name.to_string()
        } else {
            format!("{}.{name}", self.0)
        }
    }
}

impl RegisterConfig {
    /// Checks every setting ([`crate::settings`]): the SIFT settings by
    /// [`sift_desc::SiftConfig::validate`], the component settings here, the pair settings by
    /// [`PairConfig::validate`]. [`crate::register`] calls it first.
    pub fn validate(&self) -> Result<(), Error> {
        self.validate_at("")
    }

    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let here = Fields(path);
        self.sift.validate()?;
        // The rules of `blob_features::BlobConfig::validate` and `MatchConfig::validate`,
        // here to name the setting's path.
        let blobs = Fields(&here.path("blobs"));
        blobs.check("round_ratio", self.blobs.round_ratio, Rule::NotNan)?;
        if let blob_features::UnknownPolicy::Drop(max) = self.blobs.unknown {
            blobs.check("unknown", max, Rule::NotNan)?;
        }
        // Compared squared: a negative bar would act as its absolute value.
        Fields(&here.path("blob_matching")).all(
            Rule::NonNegative,
            &[
                ("ratio", self.blob_matching.ratio),
                ("max_distance", self.blob_matching.max_distance),
            ],
        )?;
        self.pair.validate_at(&here.path("pair"))
    }
}

impl PairConfig {
    /// Checks every number of these settings ([`crate::settings`]); the error names the first
    /// one out of range by its path (`verify.min_wall_lift`, ...). [`crate::register_with`]
    /// calls it first.
    pub fn validate(&self) -> Result<(), Error> {
        self.validate_at("")
    }

    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let here = Fields(path);
        let sub = |name: &str| here.path(name);
        self.ransac.validate().map_err(Error::Ransac)?;
        if let Some(s) = &self.search {
            s.validate_at(&sub("search"))?;
        }
        if let Some(s) = &self.turn_search {
            s.validate_at(&sub("turn_search"))?;
        }
        self.refine.validate_at(&sub("refine"))?;
        self.global_refine.validate_at(&sub("global_refine"))?;
        self.verify.validate_at(&sub("verify"))?;
        if let Some(g) = &self.global {
            g.validate_at(&sub("global"))?;
        }
        if let Some(s) = &self.sweep {
            s.validate_at(&sub("sweep"))?;
        }
        here.check(
            "symmetry_confident_wall_lift",
            self.symmetry_confident_wall_lift,
            Rule::NotNan,
        )?;
        if let Some(p) = &self.polish {
            Fields(&sub("polish")).check("min_wall_lift", p.min_wall_lift, Rule::NotNan)?;
            p.refine.validate_at(&sub("polish.refine"))?;
        }
        if let Some(s) = &self.spectrum_rotation {
            let f = Fields(&sub("spectrum_rotation"));
            f.check("bins", s.bins as f64, Rule::AtLeastOne)?;
            f.check("max_delta_deg", s.max_delta_deg, Rule::NonNegative)?;
            f.all(
                Rule::NotNan,
                &[
                    ("min_wall_residual_px", s.min_wall_residual_px),
                    ("max_lever_px", s.max_lever_px),
                ],
            )?;
        }
        if let Some(m) = &self.manhattan_rotation {
            let f = Fields(&sub("manhattan_rotation"));
            f.check("max_delta_deg", m.max_delta_deg, Rule::NonNegative)?;
            f.all(
                Rule::NotNan,
                &[
                    ("min_contrast", m.min_contrast),
                    ("min_lever_px", m.min_lever_px),
                    ("min_reach_ratio", m.min_reach_ratio),
                    ("min_wall_residual_px", m.min_wall_residual_px),
                    ("max_lift_drop", m.max_lift_drop),
                ],
            )?;
        }
        if let Some(a) = &self.ascent {
            let f = Fields(&sub("ascent"));
            f.all(
                Rule::FinitePositive,
                &[
                    ("initial_step_px", a.initial_step_px),
                    ("final_step_px", a.final_step_px),
                ],
            )?;
            f.all(
                Rule::Finite,
                &[
                    ("turn_deg_per_px", a.turn_deg_per_px),
                    ("contradiction_weight", a.contradiction_weight),
                ],
            )?;
            f.check("min_wall_thickness", a.min_wall_thickness, Rule::NotNan)?;
            if let Some(sr) = &a.short_range {
                let f = Fields(&sub("ascent.short_range"));
                f.check("min_frontier_ratio", sr.min_frontier_ratio, Rule::NotNan)?;
                f.check("max_wall_lift", sr.max_wall_lift, Rule::NotNan)?;
            }
        }
        if let Some(t) = &self.turn_scan {
            let f = Fields(&sub("turn_scan"));
            f.check("max_deg", t.max_deg, Rule::FiniteNonNegative)?;
            f.check("step_deg", t.step_deg, Rule::FinitePositive)?;
            f.all(
                Rule::NotNan,
                &[
                    ("min_lever_px", t.min_lever_px),
                    ("max_speckle_ratio", t.max_speckle_ratio),
                ],
            )?;
        }
        Ok(())
    }
}

impl SearchConfig {
    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let f = Fields(path);
        f.all(
            Rule::FiniteNonNegative,
            &[
                ("radius_px", self.radius_px),
                ("max_angle_deg", self.max_angle_deg),
            ],
        )?;
        f.all(
            Rule::FinitePositive,
            &[
                ("step_px", self.step_px),
                ("angle_step_deg", self.angle_step_deg),
                ("sigma_px", self.sigma_px),
            ],
        )?;
        f.check("free_penalty", self.free_penalty, Rule::Finite)?;
        f.check("overlap_pivot_px", self.overlap_pivot_px, Rule::NonNegative)
    }
}

impl RefineConfig {
    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let f = Fields(path);
        f.all(
            Rule::FinitePositive,
            &[
                ("initial_gate_px", f64::from(self.initial_gate_px)),
                ("final_gate_px", f64::from(self.final_gate_px)),
                ("robust_scale_px", self.robust_scale_px),
            ],
        )?;
        f.all(
            Rule::NonNegative,
            &[
                ("max_shift_px", self.max_shift_px),
                ("tolerance_px", self.tolerance_px),
            ],
        )?;
        if let Some(w) = self.range_bias {
            f.check("range_bias", w, Rule::FiniteNonNegative)?;
        }
        f.check("range_bias_mean_px", self.range_bias_mean_px, Rule::Finite)
    }
}

impl VerifyConfig {
    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let f = Fields(path);
        f.all(
            Rule::FiniteNonNegative,
            &[
                ("wall_tolerance_px", f64::from(self.wall_tolerance_px)),
                ("wide_tolerance_px", f64::from(self.wide_tolerance_px)),
            ],
        )?;
        f.check("max_samples", self.max_samples as f64, Rule::AtLeastOne)?;
        // `shadow_px` is documented to read NaN as 0.
        f.all(
            Rule::NotNan,
            &[
                ("min_wall_lift", self.min_wall_lift),
                ("min_wide_wall_lift", self.min_wide_wall_lift),
                ("min_acceptance_index", self.min_acceptance_index),
                ("min_overlap_fraction", self.min_overlap_fraction),
                ("max_ambiguity", self.max_ambiguity),
                ("distinct_px", self.distinct_px),
                ("max_contradiction_excess", self.max_contradiction_excess),
                (
                    "clean_contradiction_excess",
                    self.clean_contradiction_excess,
                ),
                ("trusted_wide_wall_lift", self.trusted_wide_wall_lift),
                ("max_wall_contradiction", self.max_wall_contradiction),
                ("crisp_wall_lift", self.crisp_wall_lift),
                ("max_misfit_contradiction", self.max_misfit_contradiction),
                ("min_crisp_contradiction", self.min_crisp_contradiction),
                ("basin_ratio", self.basin_ratio),
            ],
        )?;
        if let Some(s) = &self.crisp_sliver {
            Fields(&f.path("crisp_sliver")).all(
                Rule::NotNan,
                &[
                    ("min_overlap_fraction", s.min_overlap_fraction),
                    ("min_wall_lift", s.min_wall_lift),
                ],
            )?;
        }
        if let Some(s) = &self.small_overlap {
            Fields(&f.path("small_overlap")).all(
                Rule::NotNan,
                &[
                    ("below", s.below),
                    ("min_wide_wall_lift", s.min_wide_wall_lift),
                ],
            )?;
        }
        if let Some(s) = &self.stand_out {
            Fields(&f.path("stand_out")).all(
                Rule::NotNan,
                &[
                    ("min_wide_wall_lift", s.min_wide_wall_lift),
                    ("margin", s.margin),
                    ("distance_px", s.distance_px),
                    ("min_wall_density", s.min_wall_density),
                    ("min_acceptance_index", s.min_acceptance_index),
                ],
            )?;
        }
        if let Some(c) = &self.clean_successor {
            Fields(&f.path("clean_successor")).all(
                Rule::NotNan,
                &[
                    ("min_wide_wall_lift", c.min_wide_wall_lift),
                    ("max_mutual_contradiction", c.max_mutual_contradiction),
                ],
            )?;
        }
        if let Some(c) = &self.clean_walls {
            Fields(&f.path("clean_walls")).all(
                Rule::NotNan,
                &[("base", c.base), ("per_lone_share", c.per_lone_share)],
            )?;
        }
        if let Some(c) = &self.clean_fit {
            Fields(&f.path("clean_fit")).all(
                Rule::NotNan,
                &[
                    ("max_lone_share", c.max_lone_share),
                    ("min_wide_wall_lift", c.min_wide_wall_lift),
                ],
            )?;
        }
        Ok(())
    }
}

impl GlobalConfig {
    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let f = Fields(path);
        f.all(
            Rule::AtLeastOne,
            &[
                ("angle_bins", self.angle_bins as f64),
                ("coarse_size", self.coarse_size as f64),
            ],
        )?;
        f.check("free_penalty", f64::from(self.free_penalty), Rule::Finite)
    }
}

impl SweepConfig {
    fn validate_at(&self, path: &str) -> Result<(), Error> {
        let f = Fields(path);
        f.check("step_deg", self.step_deg, Rule::FinitePositive)?;
        f.check("coarse_size", self.coarse_size as f64, Rule::AtLeastOne)?;
        f.check("max_cell_px", self.max_cell_px, Rule::AtLeastOne)?;
        f.all(
            Rule::NotNan,
            &[
                ("distinct_px", self.distinct_px),
                ("confident_wall_lift", self.confident_wall_lift),
            ],
        )?;
        f.check("free_penalty", f64::from(self.free_penalty), Rule::Finite)
    }
}

impl TeamConfig {
    /// Checks every setting ([`crate::settings`]): the registration's by
    /// [`RegisterConfig::validate`] (named `register.…`), the edge bar and the pose graph's
    /// bounds (0 or more) here, before any pair is registered. [`crate::team::merge_team`] calls it first.
    pub fn validate(&self) -> Result<(), Error> {
        self.register.validate_at("register")?;
        Fields("poses").all(
            Rule::NonNegative,
            &[
                ("max_rotation_deg", self.poses.max_rotation_deg),
                ("max_translation_px", self.poses.max_translation_px),
            ],
        )?;
        Fields("").check("min_edge_lift", self.min_edge_lift, Rule::NotNan)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testmaps::room;

    type Setter = fn(&mut RegisterConfig);

    /// The error `config` is refused with, as `(name, rule)`.
    fn refused(config: &RegisterConfig) -> (String, Rule) {
        match config.validate() {
            Err(Error::Setting { name, rule, .. }) => (name, rule),
            other => panic!("not refused by a setting's rule: {other:?}"),
        }
    }

    #[test]
    fn the_defaults_pass() {
        RegisterConfig::default().validate().unwrap();
        PairConfig::default().validate().unwrap();
        TeamConfig::default().validate().unwrap();
        // So does the global search, off by default.
        let mut c = RegisterConfig::default();
        c.pair.global = Some(GlobalConfig::default());
        c.validate().unwrap();
    }

    /// Every number of the settings (every `f64` and `f32` field of the pair settings and
    /// their parts, listed here from the structs' definitions, not from the checks) is
    /// refused as NaN, under its own name. `VerifyConfig::shadow_px` alone is documented to
    /// read NaN as 0.
    #[test]
    fn every_number_is_refused_as_nan_under_its_own_name() {
        let cases: Vec<(&str, Setter)> = vec![
            ("blobs.round_ratio", |c| c.blobs.round_ratio = f64::NAN),
            ("blobs.unknown", |c| {
                c.blobs.unknown = blob_features::UnknownPolicy::Drop(f64::NAN)
            }),
            ("blob_matching.ratio", |c| c.blob_matching.ratio = f64::NAN),
            ("blob_matching.max_distance", |c| {
                c.blob_matching.max_distance = f64::NAN
            }),
            ("pair.symmetry_confident_wall_lift", |c| {
                c.pair.symmetry_confident_wall_lift = f64::NAN
            }),
            ("pair.spectrum_rotation.max_delta_deg", |c| {
                c.pair.spectrum_rotation.as_mut().unwrap().max_delta_deg = f64::NAN
            }),
            ("pair.spectrum_rotation.min_wall_residual_px", |c| {
                c.pair
                    .spectrum_rotation
                    .as_mut()
                    .unwrap()
                    .min_wall_residual_px = f64::NAN
            }),
            ("pair.spectrum_rotation.max_lever_px", |c| {
                c.pair.spectrum_rotation.as_mut().unwrap().max_lever_px = f64::NAN
            }),
            ("pair.manhattan_rotation.max_delta_deg", |c| {
                c.pair.manhattan_rotation.as_mut().unwrap().max_delta_deg = f64::NAN
            }),
            ("pair.manhattan_rotation.max_lift_drop", |c| {
                c.pair.manhattan_rotation.as_mut().unwrap().max_lift_drop = f64::NAN
            }),
            ("pair.manhattan_rotation.min_contrast", |c| {
                c.pair.manhattan_rotation.as_mut().unwrap().min_contrast = f64::NAN
            }),
            ("pair.manhattan_rotation.min_lever_px", |c| {
                c.pair.manhattan_rotation.as_mut().unwrap().min_lever_px = f64::NAN
            }),
            ("pair.manhattan_rotation.min_reach_ratio", |c| {
                c.pair.manhattan_rotation.as_mut().unwrap().min_reach_ratio = f64::NAN
            }),
            ("pair.manhattan_rotation.min_wall_residual_px", |c| {
                c.pair
                    .manhattan_rotation
                    .as_mut()
                    .unwrap()
                    .min_wall_residual_px = f64::NAN
            }),
            ("pair.turn_scan.max_deg", |c| {
                c.pair.turn_scan.as_mut().unwrap().max_deg = f64::NAN
            }),
            ("pair.turn_scan.step_deg", |c| {
                c.pair.turn_scan.as_mut().unwrap().step_deg = f64::NAN
            }),
            ("pair.turn_scan.min_lever_px", |c| {
                c.pair.turn_scan.as_mut().unwrap().min_lever_px = f64::NAN
            }),
            ("pair.turn_scan.max_speckle_ratio", |c| {
                c.pair.turn_scan.as_mut().unwrap().max_speckle_ratio = f64::NAN
            }),
            ("pair.polish.min_wall_lift", |c| {
                c.pair.polish.as_mut().unwrap().min_wall_lift = f64::NAN
            }),
            ("pair.verify.wall_tolerance_px", |c| {
                c.pair.verify.wall_tolerance_px = f32::NAN
            }),
            ("pair.verify.min_wall_lift", |c| {
                c.pair.verify.min_wall_lift = f64::NAN
            }),
            ("pair.verify.wide_tolerance_px", |c| {
                c.pair.verify.wide_tolerance_px = f32::NAN
            }),
            ("pair.verify.min_wide_wall_lift", |c| {
                c.pair.verify.min_wide_wall_lift = f64::NAN
            }),
            ("pair.verify.min_acceptance_index", |c| {
                c.pair.verify.min_acceptance_index = f64::NAN
            }),
            ("pair.verify.min_overlap_fraction", |c| {
                c.pair.verify.min_overlap_fraction = f64::NAN
            }),
            ("pair.verify.max_ambiguity", |c| {
                c.pair.verify.max_ambiguity = f64::NAN
            }),
            ("pair.verify.distinct_px", |c| {
                c.pair.verify.distinct_px = f64::NAN
            }),
            ("pair.verify.max_contradiction_excess", |c| {
                c.pair.verify.max_contradiction_excess = f64::NAN
            }),
            ("pair.verify.clean_contradiction_excess", |c| {
                c.pair.verify.clean_contradiction_excess = f64::NAN
            }),
            ("pair.verify.trusted_wide_wall_lift", |c| {
                c.pair.verify.trusted_wide_wall_lift = f64::NAN
            }),
            ("pair.verify.max_wall_contradiction", |c| {
                c.pair.verify.max_wall_contradiction = f64::NAN
            }),
            ("pair.verify.crisp_wall_lift", |c| {
                c.pair.verify.crisp_wall_lift = f64::NAN
            }),
            ("pair.verify.max_misfit_contradiction", |c| {
                c.pair.verify.max_misfit_contradiction = f64::NAN
            }),
            ("pair.verify.min_crisp_contradiction", |c| {
                c.pair.verify.min_crisp_contradiction = f64::NAN
            }),
            ("pair.verify.basin_ratio", |c| {
                c.pair.verify.basin_ratio = f64::NAN
            }),
            ("pair.verify.clean_successor.min_wide_wall_lift", |c| {
                c.pair
                    .verify
                    .clean_successor
                    .as_mut()
                    .unwrap()
                    .min_wide_wall_lift = f64::NAN
            }),
            (
                "pair.verify.clean_successor.max_mutual_contradiction",
                |c| {
                    c.pair
                        .verify
                        .clean_successor
                        .as_mut()
                        .unwrap()
                        .max_mutual_contradiction = f64::NAN
                },
            ),
            ("pair.verify.stand_out.min_wide_wall_lift", |c| {
                c.pair.verify.stand_out.as_mut().unwrap().min_wide_wall_lift = f64::NAN
            }),
            ("pair.verify.stand_out.margin", |c| {
                c.pair.verify.stand_out.as_mut().unwrap().margin = f64::NAN
            }),
            ("pair.verify.stand_out.distance_px", |c| {
                c.pair.verify.stand_out.as_mut().unwrap().distance_px = f64::NAN
            }),
            ("pair.verify.stand_out.min_wall_density", |c| {
                c.pair.verify.stand_out.as_mut().unwrap().min_wall_density = f64::NAN
            }),
            ("pair.verify.stand_out.min_acceptance_index", |c| {
                c.pair
                    .verify
                    .stand_out
                    .as_mut()
                    .unwrap()
                    .min_acceptance_index = f64::NAN
            }),
            ("pair.verify.crisp_sliver.min_overlap_fraction", |c| {
                c.pair
                    .verify
                    .crisp_sliver
                    .as_mut()
                    .unwrap()
                    .min_overlap_fraction = f64::NAN
            }),
            ("pair.verify.crisp_sliver.min_wall_lift", |c| {
                c.pair.verify.crisp_sliver.as_mut().unwrap().min_wall_lift = f64::NAN
            }),
            ("pair.verify.small_overlap.below", |c| {
                c.pair.verify.small_overlap.as_mut().unwrap().below = f64::NAN
            }),
            ("pair.verify.small_overlap.min_wide_wall_lift", |c| {
                c.pair
                    .verify
                    .small_overlap
                    .as_mut()
                    .unwrap()
                    .min_wide_wall_lift = f64::NAN
            }),
            ("pair.verify.clean_walls.base", |c| {
                c.pair.verify.clean_walls.as_mut().unwrap().base = f64::NAN
            }),
            ("pair.verify.clean_walls.per_lone_share", |c| {
                c.pair.verify.clean_walls.as_mut().unwrap().per_lone_share = f64::NAN
            }),
            ("pair.verify.clean_fit.max_lone_share", |c| {
                c.pair.verify.clean_fit.as_mut().unwrap().max_lone_share = f64::NAN
            }),
            ("pair.verify.clean_fit.min_wide_wall_lift", |c| {
                c.pair.verify.clean_fit.as_mut().unwrap().min_wide_wall_lift = f64::NAN
            }),
            ("pair.global.free_penalty", |c| {
                c.pair
                    .global
                    .get_or_insert_with(Default::default)
                    .free_penalty = f32::NAN
            }),
            ("pair.sweep.step_deg", |c| {
                c.pair.sweep.as_mut().unwrap().step_deg = f64::NAN
            }),
            ("pair.sweep.distinct_px", |c| {
                c.pair.sweep.as_mut().unwrap().distinct_px = f64::NAN
            }),
            ("pair.sweep.confident_wall_lift", |c| {
                c.pair.sweep.as_mut().unwrap().confident_wall_lift = f64::NAN
            }),
            ("pair.sweep.free_penalty", |c| {
                c.pair.sweep.as_mut().unwrap().free_penalty = f32::NAN
            }),
            ("pair.refine.initial_gate_px", |c| {
                c.pair.refine.initial_gate_px = f32::NAN
            }),
            ("pair.global_refine.initial_gate_px", |c| {
                c.pair.global_refine.initial_gate_px = f32::NAN
            }),
            ("pair.polish.refine.initial_gate_px", |c| {
                c.pair.polish.as_mut().unwrap().refine.initial_gate_px = f32::NAN
            }),
            ("pair.refine.final_gate_px", |c| {
                c.pair.refine.final_gate_px = f32::NAN
            }),
            ("pair.global_refine.final_gate_px", |c| {
                c.pair.global_refine.final_gate_px = f32::NAN
            }),
            ("pair.polish.refine.final_gate_px", |c| {
                c.pair.polish.as_mut().unwrap().refine.final_gate_px = f32::NAN
            }),
            ("pair.refine.robust_scale_px", |c| {
                c.pair.refine.robust_scale_px = f64::NAN
            }),
            ("pair.global_refine.robust_scale_px", |c| {
                c.pair.global_refine.robust_scale_px = f64::NAN
            }),
            ("pair.polish.refine.robust_scale_px", |c| {
                c.pair.polish.as_mut().unwrap().refine.robust_scale_px = f64::NAN
            }),
            ("pair.refine.max_shift_px", |c| {
                c.pair.refine.max_shift_px = f64::NAN
            }),
            ("pair.global_refine.max_shift_px", |c| {
                c.pair.global_refine.max_shift_px = f64::NAN
            }),
            ("pair.polish.refine.max_shift_px", |c| {
                c.pair.polish.as_mut().unwrap().refine.max_shift_px = f64::NAN
            }),
            ("pair.refine.tolerance_px", |c| {
                c.pair.refine.tolerance_px = f64::NAN
            }),
            ("pair.global_refine.tolerance_px", |c| {
                c.pair.global_refine.tolerance_px = f64::NAN
            }),
            ("pair.polish.refine.tolerance_px", |c| {
                c.pair.polish.as_mut().unwrap().refine.tolerance_px = f64::NAN
            }),
            ("pair.refine.range_bias", |c| {
                c.pair.refine.range_bias = Some(f64::NAN)
            }),
            ("pair.global_refine.range_bias", |c| {
                c.pair.global_refine.range_bias = Some(f64::NAN)
            }),
            ("pair.polish.refine.range_bias", |c| {
                c.pair.polish.as_mut().unwrap().refine.range_bias = Some(f64::NAN)
            }),
            ("pair.refine.range_bias_mean_px", |c| {
                c.pair.refine.range_bias_mean_px = f64::NAN
            }),
            ("pair.global_refine.range_bias_mean_px", |c| {
                c.pair.global_refine.range_bias_mean_px = f64::NAN
            }),
            ("pair.polish.refine.range_bias_mean_px", |c| {
                c.pair.polish.as_mut().unwrap().refine.range_bias_mean_px = f64::NAN
            }),
            ("pair.search.radius_px", |c| {
                c.pair.search.as_mut().unwrap().radius_px = f64::NAN
            }),
            ("pair.turn_search.radius_px", |c| {
                c.pair.turn_search.as_mut().unwrap().radius_px = f64::NAN
            }),
            ("pair.search.step_px", |c| {
                c.pair.search.as_mut().unwrap().step_px = f64::NAN
            }),
            ("pair.turn_search.step_px", |c| {
                c.pair.turn_search.as_mut().unwrap().step_px = f64::NAN
            }),
            ("pair.search.max_angle_deg", |c| {
                c.pair.search.as_mut().unwrap().max_angle_deg = f64::NAN
            }),
            ("pair.turn_search.max_angle_deg", |c| {
                c.pair.turn_search.as_mut().unwrap().max_angle_deg = f64::NAN
            }),
            ("pair.search.angle_step_deg", |c| {
                c.pair.search.as_mut().unwrap().angle_step_deg = f64::NAN
            }),
            ("pair.turn_search.angle_step_deg", |c| {
                c.pair.turn_search.as_mut().unwrap().angle_step_deg = f64::NAN
            }),
            ("pair.search.sigma_px", |c| {
                c.pair.search.as_mut().unwrap().sigma_px = f64::NAN
            }),
            ("pair.turn_search.sigma_px", |c| {
                c.pair.turn_search.as_mut().unwrap().sigma_px = f64::NAN
            }),
            ("pair.search.free_penalty", |c| {
                c.pair.search.as_mut().unwrap().free_penalty = f64::NAN
            }),
            ("pair.turn_search.free_penalty", |c| {
                c.pair.turn_search.as_mut().unwrap().free_penalty = f64::NAN
            }),
            ("pair.search.overlap_pivot_px", |c| {
                c.pair.search.as_mut().unwrap().overlap_pivot_px = f64::NAN
            }),
            ("pair.turn_search.overlap_pivot_px", |c| {
                c.pair.turn_search.as_mut().unwrap().overlap_pivot_px = f64::NAN
            }),
            ("pair.ascent.initial_step_px", |c| {
                c.pair.ascent.as_mut().unwrap().initial_step_px = f64::NAN
            }),
            ("pair.ascent.final_step_px", |c| {
                c.pair.ascent.as_mut().unwrap().final_step_px = f64::NAN
            }),
            ("pair.ascent.turn_deg_per_px", |c| {
                c.pair.ascent.as_mut().unwrap().turn_deg_per_px = f64::NAN
            }),
            ("pair.ascent.min_wall_thickness", |c| {
                c.pair.ascent.as_mut().unwrap().min_wall_thickness = f64::NAN
            }),
            ("pair.ascent.short_range.min_frontier_ratio", |c| {
                let ascent = c.pair.ascent.as_mut().unwrap();
                ascent.short_range.as_mut().unwrap().min_frontier_ratio = f64::NAN
            }),
            ("pair.ascent.short_range.max_wall_lift", |c| {
                let ascent = c.pair.ascent.as_mut().unwrap();
                ascent.short_range.as_mut().unwrap().max_wall_lift = f64::NAN
            }),
            ("pair.ascent.contradiction_weight", |c| {
                c.pair.ascent.as_mut().unwrap().contradiction_weight = f64::NAN
            }),
        ];
        for (name, set) in cases {
            let mut c = RegisterConfig::default();
            set(&mut c);
            assert_eq!(refused(&c).0, name);
        }
        let mut c = RegisterConfig::default();
        c.pair.verify.shadow_px = f32::NAN;
        c.validate().unwrap();
    }

    #[test]
    fn steps_widths_and_grid_sizes_must_be_positive() {
        let cases: Vec<(&str, Rule, Setter)> = vec![
            ("blob_matching.ratio", Rule::NonNegative, |c| {
                c.blob_matching.ratio = -0.8
            }),
            ("blob_matching.max_distance", Rule::NonNegative, |c| {
                c.blob_matching.max_distance = -0.3
            }),
            ("pair.sweep.step_deg", Rule::FinitePositive, |c| {
                c.pair.sweep.as_mut().unwrap().step_deg = 0.0
            }),
            ("pair.turn_scan.step_deg", Rule::FinitePositive, |c| {
                c.pair.turn_scan.as_mut().unwrap().step_deg = -0.25
            }),
            ("pair.search.step_px", Rule::FinitePositive, |c| {
                c.pair.search.as_mut().unwrap().step_px = 0.0
            }),
            ("pair.search.sigma_px", Rule::FinitePositive, |c| {
                c.pair.search.as_mut().unwrap().sigma_px = f64::INFINITY
            }),
            ("pair.search.radius_px", Rule::FiniteNonNegative, |c| {
                c.pair.search.as_mut().unwrap().radius_px = -1.0
            }),
            ("pair.ascent.final_step_px", Rule::FinitePositive, |c| {
                c.pair.ascent.as_mut().unwrap().final_step_px = 0.0
            }),
            ("pair.refine.robust_scale_px", Rule::FinitePositive, |c| {
                c.pair.refine.robust_scale_px = 0.0
            }),
            (
                "pair.verify.wall_tolerance_px",
                Rule::FiniteNonNegative,
                |c| c.pair.verify.wall_tolerance_px = -2.0,
            ),
            ("pair.verify.max_samples", Rule::AtLeastOne, |c| {
                c.pair.verify.max_samples = 0
            }),
            ("pair.sweep.coarse_size", Rule::AtLeastOne, |c| {
                c.pair.sweep.as_mut().unwrap().coarse_size = 0
            }),
            ("pair.sweep.max_cell_px", Rule::AtLeastOne, |c| {
                c.pair.sweep.as_mut().unwrap().max_cell_px = f64::NAN
            }),
            ("pair.spectrum_rotation.bins", Rule::AtLeastOne, |c| {
                c.pair.spectrum_rotation.as_mut().unwrap().bins = 0
            }),
            ("pair.global.angle_bins", Rule::AtLeastOne, |c| {
                c.pair.global = Some(GlobalConfig {
                    angle_bins: 0,
                    ..GlobalConfig::default()
                })
            }),
        ];
        for (name, rule, set) in cases {
            let mut c = RegisterConfig::default();
            set(&mut c);
            assert_eq!(refused(&c), (name.to_string(), rule));
        }
    }

    #[test]
    fn an_infinite_bar_switches_its_test_off_and_passes() {
        let mut c = RegisterConfig::default();
        c.pair.verify.max_wall_contradiction = f64::INFINITY;
        c.pair.verify.min_wall_lift = f64::NEG_INFINITY;
        c.pair.refine.max_shift_px = f64::INFINITY;
        c.validate().unwrap();
    }

    #[test]
    fn the_error_names_the_setting_its_value_and_the_rule() {
        let mut c = RegisterConfig::default();
        c.pair.verify.min_acceptance_index = f64::NAN;
        assert_eq!(
            c.validate().unwrap_err().to_string(),
            "invalid setting `pair.verify.min_acceptance_index` = NaN: must be a number (not NaN)"
        );
        // The pair settings checked on their own are named from there, a team's from the
        // team's settings.
        assert_eq!(
            c.pair.validate().unwrap_err().to_string(),
            "invalid setting `verify.min_acceptance_index` = NaN: must be a number (not NaN)"
        );
        let team = TeamConfig {
            register: c,
            ..TeamConfig::default()
        };
        assert!(matches!(
            team.validate(),
            Err(Error::Setting { name, .. }) if name == "register.pair.verify.min_acceptance_index"
        ));
        let mut team = TeamConfig::default();
        team.poses.max_translation_px = -8.0;
        assert_eq!(
            team.validate().unwrap_err().to_string(),
            "invalid setting `poses.max_translation_px` = -8: must be 0 or more"
        );
        let team = TeamConfig {
            min_edge_lift: f64::NAN,
            ..TeamConfig::default()
        };
        assert_eq!(
            team.validate().unwrap_err().to_string(),
            "invalid setting `min_edge_lift` = NaN: must be a number (not NaN)"
        );
        // The settings of the feature crates keep their own checks.
        let mut c = RegisterConfig::default();
        c.sift.ratio = 0.0;
        assert!(matches!(c.validate(), Err(Error::Sift(_))), "{c:?}");
        let mut c = RegisterConfig::default();
        c.sift.mapping.unknown = f32::NAN;
        assert!(matches!(c.validate(), Err(Error::Sift(_))));
        let mut c = RegisterConfig::default();
        c.pair.ransac.confidence = 1.5;
        assert!(matches!(c.validate(), Err(Error::Ransac(_))));
    }

    /// `register` refuses before any work: a NaN bar is an error, not a pair declined.
    #[test]
    fn register_refuses_invalid_settings_instead_of_declining() {
        let a = room();
        let mut c = RegisterConfig::default();
        c.pair.verify.min_wall_lift = f64::NAN;
        let err = crate::register(&a, &a, &c).unwrap_err();
        assert!(
            matches!(&err, Error::Setting { name, .. } if name == "pair.verify.min_wall_lift"),
            "{err}"
        );
        // `register_with` takes the pair settings alone and checks them itself.
        let err = crate::register_with(&a, &a, &[], &c.pair).unwrap_err();
        assert!(
            matches!(&err, Error::Setting { name, .. } if name == "verify.min_wall_lift"),
            "{err}"
        );
        let team = crate::team::merge_team(
            &[&a, &a],
            &[1.0, 1.0],
            &TeamConfig {
                register: c,
                ..TeamConfig::default()
            },
            &|| {},
        );
        assert!(matches!(team, Err(Error::Setting { .. })));
    }
}
