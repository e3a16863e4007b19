//! `cargo xtask calibrate RUN...`: what an answer's confidence (its wall lift, the
//! `confidence` of `mapmerge estimate`) says about its error, from runs of `cargo xtask eval
//! --out`: per confidence band, how many accepted answers were within 3 px of the truth, 3-10
//! px off (the right place, imprecise), more than 10 px off (the wrong place), or answers to
//! pairs that share nothing and must be declined. With `--wide` the bands are of the wide
//! wall lift instead, and with `--max-lone F` only pairs whose maps both have at most F lone
//! wall cells count: how the clean-fit bar (`mapmerge::verify::CleanFit`) was chosen.

use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;

use crate::compare::{Case, load};

/// The confidence bands' lower edges; the last band ends at 1 (and holds 1).
const EDGES: [f64; 10] = [0.0, 0.5, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95];

/// Tabulate the error of accepted answers by their confidence, over runs of `eval --out`.
#[derive(Parser)]
#[command(after_help = "\
Each run is a JSON-lines file written by `cargo xtask eval --out PREFIX` (PREFIX.jsonl) or a
directory of such files, as `cargo xtask compare` reads them; a case held by several runs (the
same suite, row, method and seed) counts once. Only accepted answers are counted, each in the
band of its confidence (wall lift, clamped to [0, 1]). A pair accepted with a wall lift below
0.65 passed by the wide tolerance or stood out (see README, \"How a pair is accepted\").

Examples:
  cargo xtask regress --out /tmp/batch
  cargo xtask calibrate /tmp/batch
  cargo xtask regress --out /tmp/unbarred -- --clean-fit off
  cargo xtask calibrate --wide --max-lone 0.02 /tmp/unbarred")]
pub struct Args {
    /// Runs of `cargo xtask eval --out`: .jsonl files or directories of them.
    #[arg(required = true)]
    runs: Vec<PathBuf>,
    /// Band the answers by their wide wall lift (the lift at the wide tolerance) instead of
    /// their wall lift.
    #[arg(long)]
    wide: bool,
    /// Count only pairs whose maps both have at most this share of lone wall cells (lines
    /// without the shares are left out).
    #[arg(long, value_name = "F")]
    max_lone: Option<f64>,
}

pub fn run(args: Args) -> Result<()> {
    let mut cases = Vec::new();
    for run in &args.runs {
        cases.extend(load(run)?);
    }
    let by = Measure {
        wide: args.wide,
        max_lone: args.max_lone,
    };
    crate::emit(&calibrate(&cases, by).to_string())
}

/// Which lift bands the answers and which pairs count.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Measure {
    /// Band by the wide wall lift, not the wall lift.
    pub wide: bool,
    /// Only pairs whose maps both have at most this share of lone wall cells.
    pub max_lone: Option<f64>,
}

/// The counts of one confidence band.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Band {
    /// Answers within 3 px of the truth.
    pub within: usize,
    /// Answers 3-10 px off.
    pub near: usize,
    /// Answers more than 10 px off.
    pub far: usize,
    /// Answers to pairs that share nothing (rows that must decline).
    pub unshared: usize,
}

impl Band {
    fn answers(&self) -> usize {
        self.within + self.near + self.far + self.unshared
    }

    fn add(&mut self, other: &Band) {
        self.within += other.within;
        self.near += other.near;
        self.far += other.far;
        self.unshared += other.unshared;
    }
}

/// Per band (by its index in [`EDGES`]), the accepted answers' counts; the cases read and
/// those accepted without a confidence (lines that lack the best candidate).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Calibration {
    pub measure: Measure,
    pub bands: BTreeMap<usize, Band>,
    pub cases: usize,
    pub without_confidence: usize,
}

/// The band of a confidence (clamped to [0, 1]).
fn band_of(confidence: f64) -> usize {
    let c = confidence.clamp(0.0, 1.0);
    EDGES.iter().rposition(|&e| c >= e).unwrap_or(0)
}

/// Count the accepted answers of `cases` by band of the lift `by` names, over the pairs it
/// keeps; a case held twice (same suite, row, method and seed) counts once, as its last line.
pub fn calibrate(cases: &[Case], by: Measure) -> Calibration {
    let kept = |c: &Case| match by.max_lone {
        None => true,
        Some(f) => c.lone_wall_shares.is_some_and(|[a, b]| a.max(b) <= f),
    };
    let unique: BTreeMap<_, &Case> = cases
        .iter()
        .filter(|c| kept(c))
        .map(|c| (c.key(), c))
        .collect();
    let mut out = Calibration {
        measure: by,
        cases: unique.len(),
        ..Calibration::default()
    };
    for case in unique.values().filter(|c| c.accepted && c.error.is_none()) {
        let Some(best) = &case.best else {
            out.without_confidence += 1;
            continue;
        };
        let v = &best.verification;
        let lift = if by.wide {
            v.wide_wall_lift
        } else {
            v.wall_lift
        };
        let band = out.bands.entry(band_of(lift)).or_default();
        match case.displacement_error_px {
            _ if case.row.contains("(must decline)") => band.unshared += 1,
            Some(d) if d <= 3.0 => band.within += 1,
            Some(d) if d <= 10.0 => band.near += 1,
            _ => band.far += 1,
        }
    }
    out
}

impl fmt::Display for Calibration {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lift = if self.measure.wide {
            "wide wall lift"
        } else {
            "confidence (wall lift)"
        };
        writeln!(
            f,
            "| {lift} | answers | within 3 px | 3-10 px off | more than 10 px off | to pairs \
             that share nothing |\n|---|---|---|---|---|---|"
        )?;
        let pct = |n: usize, d: usize| format!("{n} ({:.0} %)", 100.0 * n as f64 / d as f64);
        let line = |f: &mut fmt::Formatter<'_>, label: &str, b: &Band| {
            let n = b.answers();
            writeln!(
                f,
                "| {label} | {n} | {} | {} | {} | {} |",
                pct(b.within, n),
                pct(b.near, n),
                pct(b.far, n),
                pct(b.unshared, n)
            )
        };
        let mut all = Band::default();
        for (&i, b) in &self.bands {
            let high = EDGES.get(i + 1).copied().unwrap_or(1.0);
            line(f, &format!("{:.2}-{high:.2}", EDGES[i]), b)?;
            all.add(b);
        }
        if all.answers() > 0 {
            line(f, "all", &all)?;
        }
        let kept = match self.measure.max_lone {
            Some(l) => format!(" whose maps both have at most {l} lone wall cells"),
            None => String::new(),
        };
        writeln!(
            f,
            "\n{} cases{kept}, {} answers{}.",
            self.cases,
            all.answers(),
            if self.without_confidence > 0 {
                format!(
                    " ({} more accepted without a best candidate in their line, not counted)",
                    self.without_confidence
                )
            } else {
                String::new()
            }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::{Best, BestVerification};

    fn answer(row: &str, seed: u64, lift: f64, d: f64) -> Case {
        Case {
            suite: "s".into(),
            row: row.into(),
            method: "hybrid".into(),
            seed,
            accepted: true,
            success: d <= 3.0,
            displacement_error_px: Some(d),
            error: None,
            best: Some(Best {
                verification: BestVerification {
                    wall_lift: lift,
                    wide_wall_lift: lift,
                },
            }),
            lone_wall_shares: Some([0.0, 0.0]),
        }
    }

    #[test]
    fn the_wide_lift_bands_answers_of_clean_pairs_only_when_asked() {
        let row = "wpi_ilab cut in two, overlap 0 (must decline)";
        let mut wrong = answer(row, 1, 0.6, 180.0);
        wrong.best.as_mut().unwrap().verification.wide_wall_lift = 0.86;
        let mut speckled = answer("disaster, overlap 0.3", 2, 0.7, 1.0);
        speckled.lone_wall_shares = Some([0.01, 0.05]);
        let mut unknown = answer("disaster, overlap 0.3", 3, 0.7, 1.0);
        unknown.lone_wall_shares = None;
        let cases = [wrong, speckled, unknown];
        let by = Measure {
            wide: true,
            max_lone: Some(0.02),
        };
        let c = calibrate(&cases, by);
        assert_eq!(c.cases, 1);
        let unshared = Band {
            unshared: 1,
            ..Band::default()
        };
        assert_eq!(c.bands.get(&band_of(0.86)), Some(&unshared));
        assert!(c.to_string().starts_with("| wide wall lift |"));
        assert!(
            c.to_string()
                .contains("1 cases whose maps both have at most 0.02 lone")
        );
        // Without the filter all three count, banded by their wall lift.
        let c = calibrate(&cases, Measure::default());
        assert_eq!(c.cases, 3);
        assert_eq!(c.bands.get(&band_of(0.6)), Some(&unshared));
    }

    #[test]
    fn bands_are_closed_below_and_the_last_holds_one() {
        assert_eq!(band_of(-0.2), 0);
        assert_eq!(band_of(0.4999), 0);
        assert_eq!(band_of(0.5), 1);
        assert_eq!(band_of(0.65), 3);
        assert_eq!(band_of(0.95), 9);
        assert_eq!(band_of(1.0), 9);
        assert_eq!(band_of(1.3), 9);
    }

    #[test]
    fn answers_are_counted_by_band_and_error() {
        let row = "disaster, overlap 0.3";
        let mut declined = answer(row, 9, 0.9, 1.0);
        declined.accepted = false;
        let mut failed = answer(row, 10, 0.9, 1.0);
        failed.error = Some("overlap not reached".into());
        let mut bare = answer(row, 11, 0.9, 1.0);
        bare.best = None;
        let cases = vec![
            answer(row, 1, 0.91, 0.4),
            answer(row, 2, 0.93, 2.9),
            answer(row, 3, 0.66, 3.5),
            answer(row, 4, 0.66, 250.0),
            answer(row, 4, 0.66, 250.0), // the same case again: counted once
            answer("indoor, overlap 0 (must decline)", 5, 0.7, 0.0),
            declined,
            failed,
            bare,
        ];
        let c = calibrate(&cases, Measure::default());
        assert_eq!(c.cases, 8);
        assert_eq!(c.without_confidence, 1);
        let band = |i| c.bands.get(&i).copied().unwrap_or_default();
        assert_eq!(
            band(8),
            Band {
                within: 2,
                ..Band::default()
            }
        );
        assert_eq!(
            band(3),
            Band {
                near: 1,
                far: 1,
                ..Band::default()
            }
        );
        assert_eq!(
            band(4),
            Band {
                unshared: 1,
                ..Band::default()
            }
        );
        assert_eq!(
            c.to_string(),
            "\
| confidence (wall lift) | answers | within 3 px | 3-10 px off | more than 10 px off | to pairs that share nothing |
|---|---|---|---|---|---|
| 0.65-0.70 | 2 | 0 (0 %) | 1 (50 %) | 1 (50 %) | 0 (0 %) |
| 0.70-0.75 | 1 | 0 (0 %) | 0 (0 %) | 0 (0 %) | 1 (100 %) |
| 0.90-0.95 | 2 | 2 (100 %) | 0 (0 %) | 0 (0 %) | 0 (0 %) |
| all | 5 | 2 (40 %) | 1 (20 %) | 1 (20 %) | 1 (20 %) |

8 cases, 5 answers (1 more accepted without a best candidate in their line, not counted).
"
        );
    }
}
