//! `cargo xtask regress --out DIR`: the regression batch, the sets of `cargo xtask eval` that a
//! change to registration is measured on before it lands (docs/EVALUATION.md), each written
//! to `DIR/<set>_<seed>.jsonl` and `.md`; `cargo xtask compare DIR_BEFORE DIR_AFTER` then
//! says what the change moved.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Parser;

use crate::eval::{self, EvalArgs};

/// Run the regression batch of `cargo xtask eval` sets into a directory.
#[derive(Parser)]
#[command(after_help = "\
Sets (20 cases per row, as in docs/EVALUATION.md):
  o30     the overlap suite's 30 % rows, seeds 7, 8, 9     o30h    the same, hector's mapper
  o30g    the same, GMapping's mapper                     o30s    the same, slam_toolbox's
  real    the real floors, seeds 7, 8, 9                  realh   hector's, seeds 8, 9
  zero    every must-decline row, seeds 1, 2, 3, 7        zeroh   hector's, the same seeds
                                                          zeros   slam_toolbox's, the same
  ovl     every overlap row, seed 7                       ovlh    hector's, seed 7
  large   the nav2 warehouse, seeds 7, 8                  largeh  hector's, seed 8
  floors  five real floors at 30 % overlap, seeds 7, 8
  floorzero  the same floors at zero overlap (must decline), seed 7
  crops   the same floors cut in two, sharing 30 % or nothing (must decline), seed 7
  sensor  three real robots' partial maps cut in two the same way, seeds 7, 8, 9
  paper   the paper's setting at half, 30 % and zero overlap (must decline), seeds 7, 8, 9
The whole batch (3,280 cases) took 20 min 31 s on the 2-core AMD EPYC VM (2026-12-07,
11:46-12:11 UTC, with a one-minute eval beside it for part of that time). `cargo xtask
calibrate DIR` then tabulates its answers' errors by confidence.

Examples:
  cargo xtask regress --out /tmp/before
  cargo xtask regress --out /tmp/after -- --no-manhattan-rotation
  cargo xtask compare /tmp/before /tmp/after")]
pub struct Args {
    /// Directory to write each set's table and cases into (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Sets to run, comma separated (default: all).
    #[arg(long, value_delimiter = ',')]
    sets: Vec<String>,
    /// Flags passed on to every `cargo xtask eval` run (after `--`).
    #[arg(last = true)]
    eval_flags: Vec<String>,
}

/// One set of the batch: `eval`'s suite selection and the seeds it runs at.
struct Set {
    name: &'static str,
    suites: &'static str,
    only: Option<&'static str>,
    /// `--mapper` of its runs (`None`: the default).
    mapper: Option<&'static str>,
    seeds: &'static [u64],
}

const SETS: &[Set] = &[
    Set {
        name: "o30",
        suites: "overlap",
        only: Some("overlap 0.3"),
        mapper: None,
        seeds: &[7, 8, 9],
    },
    Set {
        name: "o30h",
        suites: "overlap",
        only: Some("overlap 0.3"),
        mapper: Some("hector"),
        seeds: &[7, 8, 9],
    },
    Set {
        name: "o30g",
        suites: "overlap",
        only: Some("overlap 0.3"),
        mapper: Some("gmapping"),
        seeds: &[7, 8, 9],
    },
    Set {
        name: "o30s",
        suites: "overlap",
        only: Some("overlap 0.3"),
        mapper: Some("slam-toolbox"),
        seeds: &[7, 8, 9],
    },
    Set {
        name: "real",
        suites: "real",
        only: None,
        mapper: None,
        seeds: &[7, 8, 9],
    },
    Set {
        name: "realh",
        suites: "real",
        only: None,
        mapper: Some("hector"),
        seeds: &[8, 9],
    },
    Set {
        name: "zero",
        suites: "zero,noise",
        only: Some("must decline"),
        mapper: None,
        seeds: &[1, 2, 3, 7],
    },
    Set {
        name: "zeroh",
        suites: "zero,noise",
        only: Some("must decline"),
        mapper: Some("hector"),
        seeds: &[1, 2, 3, 7],
    },
    Set {
        name: "zeros",
        suites: "zero,noise",
        only: Some("must decline"),
        mapper: Some("slam-toolbox"),
        seeds: &[1, 2, 3, 7],
    },
    Set {
        name: "ovl",
        suites: "overlap",
        only: None,
        mapper: None,
        seeds: &[7],
    },
    Set {
        name: "ovlh",
        suites: "overlap",
        only: None,
        mapper: Some("hector"),
        seeds: &[7],
    },
    Set {
        name: "large",
        suites: "large",
        only: None,
        mapper: None,
        seeds: &[7, 8],
    },
    Set {
        name: "largeh",
        suites: "large",
        only: None,
        mapper: Some("hector"),
        seeds: &[8],
    },
    Set {
        name: "floors",
        suites: "floors",
        only: None,
        mapper: None,
        seeds: &[7, 8],
    },
    Set {
        name: "floorzero",
        suites: "floorzero",
        only: None,
        mapper: None,
        seeds: &[7],
    },
    Set {
        name: "crops",
        suites: "crops",
        only: None,
        mapper: None,
        seeds: &[7],
    },
    Set {
        name: "sensor",
        suites: "sensor",
        only: None,
        mapper: None,
        seeds: &[7, 8, 9],
    },
    Set {
        name: "paper",
        suites: "paper",
        only: None,
        mapper: None,
        seeds: &[7, 8, 9],
    },
];

/// `eval`'s arguments as one wraps them to parse them alone.
#[derive(Parser)]
struct EvalCommand {
    #[command(flatten)]
    args: EvalArgs,
}

/// The runs of the batch for `sets` (all when empty): each run's name and its `eval` command
/// line (without the program name), with `extra` flags appended.
fn plan(
    sets: &[String],
    out: &std::path::Path,
    extra: &[String],
) -> Result<Vec<(String, Vec<String>)>> {
    for s in sets {
        if !SETS.iter().any(|set| set.name == s) {
            let names: Vec<&str> = SETS.iter().map(|set| set.name).collect();
            bail!("unknown set {s:?} (sets: {})", names.join(", "));
        }
    }
    let mut runs = Vec::new();
    for set in SETS
        .iter()
        .filter(|set| sets.is_empty() || sets.iter().any(|s| s == set.name))
    {
        for seed in set.seeds {
            let name = format!("{}_{seed}", set.name);
            let mut argv: Vec<String> = ["--suites", set.suites, "--cases", "20"]
                .map(String::from)
                .into();
            argv.extend(["--seed".into(), seed.to_string()]);
            if let Some(only) = set.only {
                argv.extend(["--only".into(), only.into()]);
            }
            if let Some(mapper) = set.mapper {
                argv.extend(["--mapper".into(), mapper.into()]);
            }
            argv.extend([
                "--out".into(),
                out.join(&name).to_string_lossy().into_owned(),
            ]);
            argv.extend(extra.iter().cloned());
            runs.push((name, argv));
        }
    }
    Ok(runs)
}

/// `eval`'s arguments from a command line (without the program name).
fn parse_eval(argv: &[String]) -> Result<EvalArgs> {
    let full = std::iter::once("eval".to_string()).chain(argv.iter().cloned());
    Ok(EvalCommand::try_parse_from(full)
        .context("the flags passed on to `cargo xtask eval`")?
        .args)
}

pub fn run(args: Args) -> Result<()> {
    let runs = plan(&args.sets, &args.out, &args.eval_flags)?;
    // Every run's flags are checked before the first one starts.
    let parsed = runs
        .iter()
        .map(|(_, argv)| parse_eval(argv))
        .collect::<Result<Vec<_>>>()?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("{}: cannot create the directory", args.out.display()))?;
    for ((name, argv), eval_args) in runs.iter().zip(parsed) {
        let shown: Vec<String> = argv
            .iter()
            .map(|a| {
                if a.contains(' ') {
                    format!("{a:?}")
                } else {
                    a.clone()
                }
            })
            .collect();
        eprintln!("== {name}: cargo xtask eval {}", shown.join(" "));
        eval::run(eval_args).with_context(|| format!("set {name}"))?;
    }
    eprintln!(
        "wrote {} runs under {}; compare two such directories with `cargo xtask compare`",
        runs.len(),
        args.out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn every_run_of_the_batch_is_an_eval_command_line() {
        let extra = vec!["--no-manhattan-rotation".to_string()];
        let runs = plan(&[], Path::new("/tmp/b"), &extra).unwrap();
        let names: Vec<&str> = runs.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "o30_7",
                "o30_8",
                "o30_9",
                "o30h_7",
                "o30h_8",
                "o30h_9",
                "o30g_7",
                "o30g_8",
                "o30g_9",
                "o30s_7",
                "o30s_8",
                "o30s_9",
                "real_7",
                "real_8",
                "real_9",
                "realh_8",
                "realh_9",
                "zero_1",
                "zero_2",
                "zero_3",
                "zero_7",
                "zeroh_1",
                "zeroh_2",
                "zeroh_3",
                "zeroh_7",
                "zeros_1",
                "zeros_2",
                "zeros_3",
                "zeros_7",
                "ovl_7",
                "ovlh_7",
                "large_7",
                "large_8",
                "largeh_8",
                "floors_7",
                "floors_8",
                "floorzero_7",
                "crops_7",
                "sensor_7",
                "sensor_8",
                "sensor_9",
                "paper_7",
                "paper_8",
                "paper_9"
            ]
        );
        for (_, argv) in &runs {
            parse_eval(argv).unwrap();
        }
        let (_, o30h) = &runs[3];
        assert_eq!(
            o30h.join(" "),
            "--suites overlap --cases 20 --seed 7 --only overlap 0.3 --mapper hector --out /tmp/b/o30h_7 --no-manhattan-rotation"
        );
    }

    #[test]
    fn sets_are_chosen_by_name_and_unknown_names_or_flags_are_refused() {
        let runs = plan(&["zeroh".into(), "large".into()], Path::new("d"), &[]).unwrap();
        let names: Vec<&str> = runs.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "zeroh_1", "zeroh_2", "zeroh_3", "zeroh_7", "large_7", "large_8"
            ]
        );
        let err = plan(&["o31".into()], Path::new("d"), &[])
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("unknown set \"o31\" (sets: o30, o30h,"),
            "{err}"
        );
        let (_, argv) =
            &plan(&["ovl".into()], Path::new("d"), &["--no-such-flag".into()]).unwrap()[0];
        assert!(parse_eval(argv).is_err());
    }
}
