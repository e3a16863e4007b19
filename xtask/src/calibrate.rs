//! `cargo xtask calibrate RUN...`: what an answer's confidence (its wall lift, the
//! `confidence` of `mapmerge estimate`) says about its error, from runs of `cargo xtask eval
//! --out`: per confidence band, how many accepted answers were within 3 px of the truth, 3-10
//! px off (the right place, imprecise), more than 10 px off (the wrong place), or answers to
//! pairs that share nothing and must be declined. With `--wide` the bands are of the wide
//! wall lift instead, and with `--max-lone F` only pairs whose maps both have at most F lone
//! wall cells count: how the clean-fit bar (`mapmerge::verify::CleanFit`) was chosen. With
//! `--declined` it looks at the declined pairs instead: how well the right placement fitted
//! where one was found, against how well a wrong one fits where the maps share nothing (what
//! a lower bar would let in); with `--lone-shares`, how speckled each row's maps are.

use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;

use mapmerge::verify::{Verification, VerifyConfig};

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
  cargo xtask calibrate --wide --max-lone 0.02 /tmp/unbarred
  cargo xtask eval --suites overlap,zero --noise 0.2 --out /tmp/n20
  cargo xtask calibrate --declined --wide /tmp/n20.jsonl")]
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
    #[arg(long, value_name = "F", value_parser = crate::eval::fraction::<f64>)]
    max_lone: Option<f64>,
    /// Count the declined pairs instead, each by its best-fitting candidate that passes every
    /// test but the wall lift bars (acceptance index, wall support, overlap; the library's
    /// defaults): in a pair that shares something, the best of the candidates within 3 px of
    /// the truth (a right placement found but not accepted); in a pair that shares nothing,
    /// the best of all (the fit a wrong answer reaches there).
    #[arg(long)]
    declined: bool,
    /// List, per row instead, how many maps there are and the least, median and largest share
    /// of lone wall cells among them (both maps of every case): how speckled a row's maps are.
    #[arg(long, conflicts_with = "declined")]
    lone_shares: bool,
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
    if args.declined {
        return crate::emit(&declined(&cases, by).to_string());
    }
    if args.lone_shares {
        return crate::emit(&lone_shares(&cases));
    }
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

impl Measure {
    /// Whether `case` is one of the pairs counted.
    fn keeps(&self, case: &Case) -> bool {
        match self.max_lone {
            None => true,
            Some(f) => case.lone_wall_shares.is_some_and(|[a, b]| a.max(b) <= f),
        }
    }

    /// The lift this measure bands by.
    fn lift(&self, wall_lift: f64, wide_wall_lift: f64) -> f64 {
        if self.wide { wide_wall_lift } else { wall_lift }
    }

    fn label(&self) -> &'static str {
        if self.wide {
            "wide wall lift"
        } else {
            "confidence (wall lift)"
        }
    }
}

/// The cases of `cases` that `by` keeps, each once (as its last line).
fn unique<'c>(
    cases: &'c [Case],
    by: &Measure,
) -> BTreeMap<(String, String, String, u64), &'c Case> {
    cases
        .iter()
        .filter(|c| by.keeps(c))
        .map(|c| (c.key(), c))
        .collect()
}

/// Count the accepted answers of `cases` by band of the lift `by` names, over the pairs it
/// keeps; a case held twice (same suite, row, method and seed) counts once, as its last line.
pub fn calibrate(cases: &[Case], by: Measure) -> Calibration {
    let unique = unique(cases, &by);
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
        let lift = by.lift(v.wall_lift, v.wide_wall_lift);
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
        let lift = self.measure.label();
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

/// The declined pairs of runs, by their best fit (`cargo xtask calibrate --declined`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Declined {
    pub measure: Measure,
    /// Per band (by its index in [`EDGES`]): the declined pairs that share something whose
    /// right placement fits in it, and the pairs that share nothing whose best fit does.
    pub bands: BTreeMap<usize, (usize, usize)>,
    /// Declined pairs that share something.
    pub shared: usize,
    /// Declined pairs that share nothing.
    pub unshared: usize,
    /// The right placements' fits, lowest first.
    pub right: Vec<f64>,
    /// The best fit of each pair that shares nothing, lowest first.
    pub wrong: Vec<f64>,
}

/// Count the declined pairs of `cases` by the fit of their best candidate that passes every
/// test but the wall lift bars ([`Verification::passes_all_but_walls`] with the library's
/// defaults): within 3 px of the truth where the pair shares something, any where it shares
/// nothing. A case held twice counts once, as its last line.
pub fn declined(cases: &[Case], by: Measure) -> Declined {
    let config = VerifyConfig::default();
    let mut out = Declined {
        measure: by,
        ..Declined::default()
    };
    for case in unique(cases, &by)
        .values()
        .filter(|c| !c.accepted && c.error.is_none())
    {
        let shares_nothing = case.row.contains("(must decline)");
        let counts = |v: &Verification, d: Option<f64>| {
            v.passes_all_but_walls(&config) && (shares_nothing || d.is_some_and(|d| d <= 3.0))
        };
        let best = case
            .candidates
            .iter()
            .filter(|(v, d)| counts(v, *d))
            .map(|(v, _)| by.lift(v.wall_lift, v.wide_wall_lift))
            .max_by(f64::total_cmp);
        if shares_nothing {
            out.unshared += 1;
        } else {
            out.shared += 1;
        }
        let Some(best) = best else { continue };
        let band = out.bands.entry(band_of(best)).or_default();
        if shares_nothing {
            band.1 += 1;
            out.wrong.push(best);
        } else {
            band.0 += 1;
            out.right.push(best);
        }
    }
    out.right.sort_by(f64::total_cmp);
    out.wrong.sort_by(f64::total_cmp);
    out
}

impl fmt::Display for Declined {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "| {} | declined pairs that share something: the right placement | declined pairs \
             that share nothing: the best placement |\n|---|---|---|",
            self.measure.label()
        )?;
        for (&i, &(right, wrong)) in &self.bands {
            let high = EDGES.get(i + 1).copied().unwrap_or(1.0);
            writeln!(f, "| {:.2}-{high:.2} | {right} | {wrong} |", EDGES[i])?;
        }
        writeln!(f, "| all | {} | {} |", self.right.len(), self.wrong.len())?;
        let spread = |fits: &[f64]| match (fits.first(), fits.last()) {
            (Some(lo), Some(hi)) => format!(
                " ({} {lo:.3}-{hi:.3}, median {:.3})",
                self.measure.label(),
                fits[fits.len() / 2]
            ),
            _ => String::new(),
        };
        writeln!(
            f,
            "\n{} declined pairs that share something: {} with a candidate within 3 px that \
             passes every test but the wall lift bars{}.",
            self.shared,
            self.right.len(),
            spread(&self.right)
        )?;
        writeln!(
            f,
            "{} declined pairs that share nothing: {} with a candidate that passes those \
             tests{}.",
            self.unshared,
            self.wrong.len(),
            spread(&self.wrong)
        )?;
        if let Some(&top) = self.wrong.last() {
            let above = self.right.iter().filter(|&&r| r > top).count();
            writeln!(
                f,
                "Right placements that fit better than every pair that shares nothing: {above}."
            )?;
        }
        Ok(())
    }
}

/// Per row (suite, row and method), the maps' shares of lone wall cells: how many, the least,
/// the median (the upper of the two middle ones) and the largest, as a Markdown table. A case
/// held twice counts once; lines without the shares are left out.
pub fn lone_shares(cases: &[Case]) -> String {
    let mut rows: BTreeMap<(String, String, String), Vec<f64>> = BTreeMap::new();
    for case in unique(cases, &Measure::default()).values() {
        if let Some(shares) = case.lone_wall_shares {
            rows.entry((case.suite.clone(), case.row.clone(), case.method.clone()))
                .or_default()
                .extend(shares);
        }
    }
    let mut out = String::from(
        "| suite | case family | method | maps | least | median | largest |\n|---|---|---|---|---|---|---|\n",
    );
    for ((suite, row, method), mut shares) in rows {
        shares.sort_by(f64::total_cmp);
        out += &format!(
            "| {suite} | {row} | {method} | {} | {:.3} | {:.3} | {:.3} |\n",
            shares.len(),
            shares[0],
            shares[shares.len() / 2],
            shares[shares.len() - 1]
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::Best;

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
                verification: Verification {
                    wall_lift: lift,
                    wide_wall_lift: lift,
                    ..Verification::default()
                },
            }),
            lone_wall_shares: Some([0.0, 0.0]),
            candidates: Vec::new(),
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

    /// A candidate's scores: wide lift `wide`, passing every test but the wall bars unless
    /// `thin` (too little overlap).
    fn fit(wide: f64, thin: bool) -> Verification {
        Verification {
            wall_lift: wide - 0.2,
            wide_wall_lift: wide,
            wall_support: 500,
            acceptance_index: 0.95,
            overlap_fraction: if thin { 0.05 } else { 0.4 },
            ..Verification::default()
        }
    }

    #[test]
    fn declined_pairs_are_counted_by_their_right_or_best_placement() {
        let shared = "indoor, overlap 0.5";
        let unshared = "indoor, overlap 0 (must decline)";
        let decline = |row: &str, seed: u64, candidates: Vec<(Verification, Option<f64>)>| {
            let mut c = answer(row, seed, 0.0, 0.0);
            c.accepted = false;
            c.success = false;
            c.displacement_error_px = None;
            c.best = None;
            c.candidates = candidates;
            c
        };
        let cases = vec![
            // The right placement (within 3 px) counts, not the better-fitting wrong one, nor
            // a right one that fails the overlap test.
            decline(
                shared,
                1,
                vec![
                    (fit(0.9, false), Some(290.0)),
                    (fit(0.85, true), Some(1.0)),
                    (fit(0.72, false), Some(2.5)),
                    (fit(0.6, false), Some(0.5)),
                ],
            ),
            // No right placement found.
            decline(shared, 2, vec![(fit(0.7, false), Some(40.0))]),
            // Sharing nothing: the best that passes the other tests.
            decline(
                unshared,
                3,
                vec![(fit(0.95, true), None), (fit(0.66, false), None)],
            ),
            decline(unshared, 4, vec![(fit(0.55, false), None)]),
            // Accepted pairs are not counted.
            answer(shared, 5, 0.9, 1.0),
        ];
        let d = declined(
            &cases,
            Measure {
                wide: true,
                max_lone: None,
            },
        );
        assert_eq!((d.shared, d.unshared), (2, 2));
        assert_eq!(d.right, vec![0.72]);
        assert_eq!(d.wrong, vec![0.55, 0.66]);
        assert_eq!(d.bands.get(&band_of(0.72)), Some(&(1, 0)));
        assert_eq!(d.bands.get(&band_of(0.66)), Some(&(0, 1)));
        let text = d.to_string();
        assert!(text.contains("2 declined pairs that share something: 1 with a candidate"));
        assert!(
            text.contains(
                "Right placements that fit better than every pair that shares nothing: 1."
            )
        );
        // By wall lift the same candidates count, banded 0.2 lower.
        let d = declined(&cases, Measure::default());
        assert_eq!(d.bands.get(&band_of(0.52)), Some(&(1, 0)));
    }

    #[test]
    fn lone_shares_are_listed_per_row_over_both_maps_of_each_case_once() {
        let row = "disaster, overlap 0.3";
        let mut a = answer(row, 1, 0.9, 1.0);
        a.lone_wall_shares = Some([0.05, 0.03]);
        let mut b = answer(row, 2, 0.9, 1.0);
        b.lone_wall_shares = Some([0.08, 0.04]);
        let mut unknown = answer("indoor, overlap 0.3", 3, 0.9, 1.0);
        unknown.lone_wall_shares = None;
        let cases = [a.clone(), b, a, unknown];
        assert_eq!(
            lone_shares(&cases),
            "\
| suite | case family | method | maps | least | median | largest |
|---|---|---|---|---|---|---|
| s | disaster, overlap 0.3 | hybrid | 4 | 0.030 | 0.050 | 0.080 |
"
        );
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
