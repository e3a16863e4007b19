//! `cargo xtask compare BEFORE AFTER`: what changed, case by case, between two runs of
//! `cargo xtask eval --out` (the A/B comparison behind every "no outcome changed" of
//! docs/EVALUATION.md).
//!
//! Cases are matched by suite, row, method and seed, so runs of different sets can be given
//! whole: only the cases both runs hold are compared.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Parser;

/// Compare two runs of `cargo xtask eval --out`, case by case.
#[derive(Parser)]
#[command(after_help = "\
Each run is a JSON-lines file written by `cargo xtask eval --out PREFIX` (PREFIX.jsonl) or a
directory of such files (every *.jsonl directly in it). A case's outcome is `registered`
(accepted and within 3 px), `off` (accepted but more than 3 px off, or a pair that must be
declined), `declined` (the success of a must-decline row), or `failed` (the case did not
generate). Printed: every case whose outcome changed, and every registered case whose
displacement error moved by more than --moved; a count of the cases registered after but not
before (won) and before but not after (lost), and of how many of the moved ones came nearer
the truth; then, per row, the counts of each outcome before and after.

Example:
  cargo xtask eval --suites overlap --only \"overlap 0.3\" --seed 7 --out /tmp/before
  (change something, rebuild)
  cargo xtask eval --suites overlap --only \"overlap 0.3\" --seed 7 --out /tmp/after
  cargo xtask compare /tmp/before.jsonl /tmp/after.jsonl")]
pub struct Args {
    /// The run before the change: a .jsonl file or a directory of them.
    before: PathBuf,
    /// The run after the change.
    after: PathBuf,
    /// List registered cases whose displacement error moved by more than this (pixels).
    #[arg(long, default_value_t = 0.5, value_name = "PX", value_parser = crate::eval::non_negative::<f64>)]
    moved: f64,
}

pub fn run(args: Args) -> Result<()> {
    let before = load(&args.before)?;
    let after = load(&args.after)?;
    crate::emit(&compare(&before, &after, args.moved).to_string())
}

/// What a case came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Outcome {
    /// Accepted and a success (within 3 px).
    Registered,
    /// Accepted, not a success: more than 3 px off, or a pair that must be declined.
    Off,
    /// Not accepted (for a pair that must be declined, the success).
    Declined,
    /// The case did not generate.
    Failed,
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Outcome::Registered => "registered",
            Outcome::Off => "off",
            Outcome::Declined => "declined",
            Outcome::Failed => "failed",
        })
    }
}

/// The fields of one `eval` JSON line that the comparison reads.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct Case {
    pub suite: String,
    pub row: String,
    pub method: String,
    pub seed: u64,
    pub accepted: bool,
    pub success: bool,
    pub displacement_error_px: Option<f64>,
    pub error: Option<String>,
    /// The best candidate (the answer, when accepted); `None` in lines that lack it.
    #[serde(default)]
    pub best: Option<Best>,
    /// Both maps' shares of lone wall cells; `None` in lines written before they were.
    #[serde(default)]
    pub lone_wall_shares: Option<[f64; 2]>,
    /// Every candidate's scores with its displacement error (`None` without a truth), best
    /// first; empty in lines that lack them.
    #[serde(default)]
    pub candidates: Vec<(mapmerge::verify::Verification, Option<f64>)>,
}

/// The best candidate of a case, as far as `cargo xtask calibrate` reads it: its scores (its
/// wall lift is the `confidence` of `mapmerge estimate`, clamped to [0, 1] there).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct Best {
    pub verification: mapmerge::verify::Verification,
}

impl Case {
    pub fn outcome(&self) -> Outcome {
        match (&self.error, self.accepted, self.success) {
            (Some(_), _, _) => Outcome::Failed,
            (None, true, true) => Outcome::Registered,
            (None, true, false) => Outcome::Off,
            (None, false, _) => Outcome::Declined,
        }
    }

    pub fn key(&self) -> (String, String, String, u64) {
        (
            self.suite.clone(),
            self.row.clone(),
            self.method.clone(),
            self.seed,
        )
    }

    /// The outcome with the displacement error when there is one.
    fn describe(&self) -> String {
        match self.displacement_error_px {
            Some(d) if self.accepted => format!("{} {d:.2} px", self.outcome()),
            _ => self.outcome().to_string(),
        }
    }
}

/// The cases of a run: one file, or every `*.jsonl` directly in a directory (by name).
pub fn load(path: &Path) -> Result<Vec<Case>> {
    let files = if path.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .with_context(|| format!("{}: cannot list the directory", path.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "jsonl"))
            .collect();
        files.sort();
        if files.is_empty() {
            bail!("{}: no .jsonl file in the directory", path.display());
        }
        files
    } else {
        vec![path.to_path_buf()]
    };
    let mut cases = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file)
            .with_context(|| format!("{}: cannot read", file.display()))?;
        for (i, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
        {
            let case: Case = serde_json::from_str(line).with_context(|| {
                format!(
                    "{}: line {} is not a case of `cargo xtask eval --out`",
                    file.display(),
                    i + 1
                )
            })?;
            cases.push(case);
        }
    }
    Ok(cases)
}

/// One case that changed.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    pub before: Case,
    pub after: Case,
}

/// Counts of each outcome of one row, before and after.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RowTotals {
    pub before: BTreeMap<Outcome, usize>,
    pub after: BTreeMap<Outcome, usize>,
}

/// The comparison of two runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Cases whose outcome changed, or that stayed registered and moved by more than the
    /// given distance, by suite, row, method and seed.
    pub changes: Vec<Change>,
    /// Per row (suite, row, method) of the cases both runs hold.
    pub rows: BTreeMap<(String, String, String), RowTotals>,
    /// Cases only one run holds.
    pub only_before: usize,
    pub only_after: usize,
    /// The distance a registered answer had to move to be listed (pixels).
    pub moved_px: f64,
}

/// Compare the cases both runs hold (see [`Report`]). A case a run holds twice (a directory
/// whose files share rows) counts once, as its last line.
pub fn compare(before: &[Case], after: &[Case], moved_px: f64) -> Report {
    let by_key = |cases: &[Case]| -> BTreeMap<_, Case> {
        cases.iter().map(|c| (c.key(), c.clone())).collect()
    };
    let (before, after) = (by_key(before), by_key(after));
    let mut report = Report {
        changes: Vec::new(),
        rows: BTreeMap::new(),
        only_before: before.keys().filter(|k| !after.contains_key(*k)).count(),
        only_after: after.keys().filter(|k| !before.contains_key(*k)).count(),
        moved_px,
    };
    for (key, a) in &after {
        let Some(b) = before.get(key) else {
            continue;
        };
        let totals = report
            .rows
            .entry((a.suite.clone(), a.row.clone(), a.method.clone()))
            .or_default();
        *totals.before.entry(b.outcome()).or_default() += 1;
        *totals.after.entry(a.outcome()).or_default() += 1;
        let moved = match (b.displacement_error_px, a.displacement_error_px) {
            (Some(x), Some(y)) => (x - y).abs() > moved_px,
            _ => false,
        };
        let both_registered = b.outcome() == Outcome::Registered && a.outcome() == b.outcome();
        if b.outcome() != a.outcome() || (both_registered && moved) {
            report.changes.push(Change {
                before: b.clone(),
                after: a.clone(),
            });
        }
    }
    report
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.changes.is_empty() {
            writeln!(f, "No case changed.")?;
        } else {
            writeln!(f, "Changed (before -> after):")?;
            for c in &self.changes {
                writeln!(
                    f,
                    "  {} | {} | {} | {}: {} -> {}",
                    c.after.suite,
                    c.after.row,
                    c.after.method,
                    c.after.seed,
                    c.before.describe(),
                    c.after.describe()
                )?;
            }
            let registered = |c: &Case| c.outcome() == Outcome::Registered;
            let count = |p: &dyn Fn(&Change) -> bool| self.changes.iter().filter(|c| p(c)).count();
            let won = count(&|c| !registered(&c.before) && registered(&c.after));
            let lost = count(&|c| registered(&c.before) && !registered(&c.after));
            let moved = count(&|c| registered(&c.before) && registered(&c.after));
            let nearer = count(&|c| {
                registered(&c.before)
                    && registered(&c.after)
                    && c.after.displacement_error_px < c.before.displacement_error_px
            });
            writeln!(
                f,
                "Registered: {won} won, {lost} lost; {nearer} of the {moved} registered both \
                 times that moved by more than {} px came nearer the truth.",
                self.moved_px
            )?;
        }
        writeln!(f, "Per row (registered / off / declined / failed):")?;
        let counts = |m: &BTreeMap<Outcome, usize>| {
            let n = |o| m.get(&o).copied().unwrap_or(0);
            format!(
                "{} / {} / {} / {}",
                n(Outcome::Registered),
                n(Outcome::Off),
                n(Outcome::Declined),
                n(Outcome::Failed)
            )
        };
        for ((suite, row, method), t) in &self.rows {
            writeln!(
                f,
                "  {suite} | {row} | {method}: {} -> {}",
                counts(&t.before),
                counts(&t.after)
            )?;
        }
        if self.only_before + self.only_after > 0 {
            writeln!(
                f,
                "Not compared: {} cases only in the run before, {} only in the run after.",
                self.only_before, self.only_after
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(row: &str, seed: u64, accepted: bool, success: bool, d: Option<f64>) -> Case {
        Case {
            suite: "overlap".into(),
            row: row.into(),
            method: "hybrid".into(),
            seed,
            accepted,
            success,
            displacement_error_px: d,
            error: None,
            best: None,
            lone_wall_shares: None,
            candidates: Vec::new(),
        }
    }

    #[test]
    fn changed_outcomes_and_moved_answers_are_listed_with_the_rows_totals() {
        let row = "disaster, overlap 0.3, noise 10%/10%";
        let before = vec![
            case(row, 1, true, true, Some(1.0)),  // stays, moves 0.2 px
            case(row, 2, true, false, Some(3.4)), // off -> registered
            case(row, 3, true, true, Some(0.5)),  // stays, moves 1.5 px
            case(row, 4, false, false, None),     // declined -> off
            case(row, 9, true, true, Some(1.0)),  // only before
        ];
        let mut failed = case(row, 5, false, false, None);
        failed.error = Some("overlap not reached".into());
        let after = vec![
            case(row, 1, true, true, Some(1.2)),
            case(row, 2, true, true, Some(2.9)),
            case(row, 3, true, true, Some(2.0)),
            case(row, 4, true, false, Some(250.0)),
            failed, // only after
        ];
        let report = compare(&before, &after, 0.5);
        let seeds: Vec<u64> = report.changes.iter().map(|c| c.after.seed).collect();
        assert_eq!(seeds, vec![2, 3, 4]);
        assert_eq!((report.only_before, report.only_after), (1, 1));
        let text = report.to_string();
        let expected = "\
Changed (before -> after):
  overlap | disaster, overlap 0.3, noise 10%/10% | hybrid | 2: off 3.40 px -> registered 2.90 px
  overlap | disaster, overlap 0.3, noise 10%/10% | hybrid | 3: registered 0.50 px -> registered 2.00 px
  overlap | disaster, overlap 0.3, noise 10%/10% | hybrid | 4: declined -> off 250.00 px
Registered: 1 won, 0 lost; 0 of the 1 registered both times that moved by more than 0.5 px came nearer the truth.
Per row (registered / off / declined / failed):
  overlap | disaster, overlap 0.3, noise 10%/10% | hybrid: 2 / 1 / 1 / 0 -> 3 / 1 / 0 / 0
Not compared: 1 cases only in the run before, 1 only in the run after.
";
        assert_eq!(text, expected);
    }

    #[test]
    fn a_case_held_twice_counts_once() {
        let once = vec![case("a", 1, true, true, Some(1.0))];
        let twice = vec![once[0].clone(), once[0].clone()];
        let report = compare(&twice, &twice, 0.0);
        let totals = &report.rows.values().next().unwrap();
        assert_eq!(totals.after.get(&Outcome::Registered), Some(&1));
        assert_eq!((report.only_before, report.only_after), (0, 0));
        assert_eq!(compare(&once, &twice, 0.0), report);
    }

    #[test]
    fn identical_runs_change_nothing() {
        let cases = vec![
            case("a", 1, true, true, Some(1.0)),
            case("a", 2, false, true, None),
        ];
        let report = compare(&cases, &cases, 0.0);
        assert!(report.changes.is_empty());
        assert!(report.to_string().starts_with("No case changed.\n"));
    }

    #[test]
    fn an_older_line_without_some_scores_reads_them_as_zero() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("old.jsonl");
        let line = r#"{"suite":"overlap","row":"r","method":"hybrid","seed":1,"accepted":true,"success":true,"displacement_error_px":1.0,"error":null,"best":{"verification":{"wall_lift":0.7}},"candidates":[[{"wall_lift":0.7,"acceptance_index":0.95},1.0]]}"#;
        std::fs::write(&path, format!("{line}\n")).unwrap();
        let cases = load(&path).unwrap();
        let best = &cases[0].best.as_ref().unwrap().verification;
        assert_eq!((best.wall_lift, best.wide_wall_lift), (0.7, 0.0));
        let (v, d) = cases[0].candidates[0];
        assert_eq!(
            (v.acceptance_index, v.mutual_contradiction, d),
            (0.95, 0.0, Some(1.0))
        );
    }

    #[test]
    fn a_run_is_read_from_a_file_or_every_jsonl_of_a_directory() {
        let dir = tempfile::tempdir().unwrap();
        let line = |seed| {
            format!(
                r#"{{"suite":"zero","row":"r","method":"hybrid","seed":{seed},"accepted":false,"success":true,"displacement_error_px":null,"error":null,"extra":[1,2]}}"#
            )
        };
        std::fs::write(dir.path().join("a.jsonl"), line(1) + "\n").unwrap();
        std::fs::write(dir.path().join("b.jsonl"), line(2) + "\n\n").unwrap();
        std::fs::write(dir.path().join("b.md"), "not read").unwrap();
        let all = load(dir.path()).unwrap();
        assert_eq!(all.iter().map(|c| c.seed).collect::<Vec<_>>(), vec![1, 2]);
        assert_eq!(all[0].outcome(), Outcome::Declined);
        assert_eq!(load(&dir.path().join("a.jsonl")).unwrap().len(), 1);
        std::fs::write(dir.path().join("bad.jsonl"), "{\"suite\": 3}\n").unwrap();
        let err = format!("{:#}", load(dir.path()).unwrap_err());
        assert!(
            err.contains("bad.jsonl: line 1 is not a case of `cargo xtask eval --out`"),
            "{err}"
        );
        let empty = tempfile::tempdir().unwrap();
        let err = load(empty.path()).unwrap_err().to_string();
        assert!(err.ends_with("no .jsonl file in the directory"), "{err}");
    }
}
