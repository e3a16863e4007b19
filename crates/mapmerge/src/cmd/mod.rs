//! The subcommands (one module each, `run(args, ...) -> anyhow::Result<ExitCode>`) and what
//! they share: the bare-image flags and the mapping from errors to exit codes.
//!
//! A subcommand returns `Ok(code)` for the outcomes it decides itself (0, or 3 "no trustworthy
//! match" for the registration commands) and `Err` for everything else; [`run_main`] prints an
//! `Err` as one line and picks its exit code with [`exit_code_for`].

pub mod estimate;
pub mod info;
pub mod merge;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use grid_core::Pose2;
use grid_core::io::{BareImageDefaults, LoadOptions, LoadedMap};
use mapmerge::{Method, RegisterConfig, Registration};

/// Exit code: success.
pub const EXIT_OK: u8 = 0;
/// Exit code: internal error (a bug, or an environment problem that is not the input's fault).
pub const EXIT_INTERNAL: u8 = 1;
/// Exit code: bad usage or bad input.
pub const EXIT_BAD_INPUT: u8 = 2;

/// Bad usage found by the program itself (clap's own errors included): exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// The exit code for `err`: 2 when the input or the usage is wrong, 1 otherwise.
///
/// Every cause in the chain is looked at, so `.context(...)` does not change the code.
pub fn exit_code_for(err: &anyhow::Error) -> u8 {
    for cause in err.chain() {
        if cause.is::<UsageError>() {
            return EXIT_BAD_INPUT;
        }
        if let Some(e) = cause.downcast_ref::<grid_core::Error>() {
            return match e {
                // Files that cannot be read or do not hold a usable map: the user's input.
                grid_core::Error::Io { .. }
                | grid_core::Error::Format { .. }
                | grid_core::Error::AllUnknown { .. }
                | grid_core::Error::ZeroSize { .. }
                | grid_core::Error::Resolution(_)
                | grid_core::Error::ResampleTooLarge { .. } => EXIT_BAD_INPUT,
                // Inconsistent buffers can only come from our own code.
                _ => EXIT_INTERNAL,
            };
        }
    }
    EXIT_INTERNAL
}

/// Run the program body, print an error as one line `mapmerge: error: ...` on stderr and
/// return the exit code. A panic (a bug) is reported in one line too, with exit code 1.
pub fn run_main(body: impl FnOnce() -> anyhow::Result<ExitCode>) -> ExitCode {
    std::panic::set_hook(Box::new(|info| {
        eprintln!("mapmerge: internal error (this is a bug, please report it): {info}");
    }));
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(body)) {
        Ok(Ok(code)) => code,
        Ok(Err(err)) => {
            eprintln!("mapmerge: error: {}", one_line(&message(&err)));
            ExitCode::from(exit_code_for(&err))
        }
        Err(_) => ExitCode::from(EXIT_INTERNAL),
    }
}

/// What to do with a clap error: print help or version and succeed, or turn a usage error into
/// a one-line [`UsageError`] (exit code 2).
pub fn clap_outcome(e: clap::Error) -> anyhow::Result<ExitCode> {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            e.print().context("cannot write to the terminal")?;
            Ok(ExitCode::from(
                if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    EXIT_BAD_INPUT
                } else {
                    EXIT_OK
                },
            ))
        }
        _ => {
            // clap renders several lines (message, usage, a hint); keep the message lines.
            let text = e.render().to_string();
            let message: Vec<&str> = text
                .lines()
                .map(str::trim)
                .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
                .filter(|l| !l.is_empty())
                .collect();
            let message = message.join(" ");
            let message = message.strip_prefix("error: ").unwrap_or(&message);
            Err(UsageError(format!("{message} (see 'mapmerge --help')")).into())
        }
    }
}

/// The error and its causes joined by ": ", skipping a cause whose text is already there
/// (`grid_core::Error::Io` shows its OS error and also returns it as its source).
fn message(err: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if !msg.contains(&text) {
            if !msg.is_empty() {
                msg.push_str(": ");
            }
            msg.push_str(&text);
        }
    }
    msg
}

/// Collapse a message to one line.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// How each pair is registered: the flags `estimate` and `merge` share.
#[derive(Debug, Clone, Args)]
pub struct RegistrationArgs {
    /// Evidence used for correspondences: sift (intensity keypoints), blobs (obstacle
    /// components) or hybrid (both)
    #[arg(long, default_value = "hybrid", value_parser = parse_method)]
    pub method: Method,
    /// Seed of RANSAC; the same seed gives the same answer
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Share of the smaller map's known cells that a placement must find known in both maps
    /// [default: 0.15, or 0.1 for a placement whose walls fit at wall lift 0.95 or more; an
    /// answer under 0.25 needs a wide wall lift of 0.97]. Given, every placement needs it and
    /// no more: lower it for maps that share only a corner, at the risk of accepting a sliver
    /// where a few walls happen to line up
    #[arg(long, value_name = "FRACTION", value_parser = probability)]
    pub min_overlap: Option<f64>,
    /// Cells that the answer must find known in both maps, whatever their share of the
    /// smaller map [default: 1250, about a 35-cell square]; a map with fewer known cells is
    /// declined at once. A map that is little more than a few laser streaks fits inside the
    /// other almost anywhere; lower this for small maps at a fine resolution
    #[arg(long, value_name = "CELLS")]
    pub min_overlap_cells: Option<usize>,
    /// Lift the bars that clean maps (few lone wall cells) are held to: an answer is declined
    /// when each map puts more than about 2 % of its walls in the other's free space (the
    /// reason says "where maps with walls this clean allow"), or when its walls fit the
    /// other map's within 4 px at a lift under 0.88 (the reason starts "misfit"). Maps bent
    /// by drift, or where one robot saw many obstacles the other did not, can fail them at the
    /// right answer; without them, parts of a building whose rooms repeat but that share
    /// nothing are answered more often
    #[arg(long)]
    pub no_clean_walls: bool,
    /// Let the answer climb the verification score on walls of any thickness. By default it
    /// climbs on walls about two cells thick, as scan-matching mappers draw them, and on the
    /// thin walls of maps whose free space borders unknown more than it borders walls (a
    /// short-range sensor with few beams, such as the paper's 16-beam infrared ring: its maps'
    /// walls are one cell thick and dotted, ICP leaves the answer a few pixels or degrees off,
    /// and the score peaks at the truth). Give it for such a sensor whose maps do not show it.
    /// Not for a long-range lidar's one-cell walls: range noise pushes those behind the
    /// obstacle faces, and the climb follows the push away from the truth
    #[arg(long)]
    pub climb: bool,
    /// Before declining a pair where nothing passed, search and verify the rotation sweep's
    /// placements 1,000 deep in each direction instead of 100. On a large building floor the
    /// placement near the truth can rank far down: of 40 simulated pairs on the uos_cic floor
    /// at 30 % overlap (seeds 7 and 8) it registers 31 instead of 28, and declines none
    /// instead of 6 (the other 3 it answers 3.5-6 px off). Off by default because in
    /// open halls, where two maps share mostly free space, it can find a confident wrong
    /// answer (5 of 400 held-out simulated indoor pairs answered about 200 px off), and a
    /// declined pair takes about three times as long
    #[arg(long)]
    pub deep_screen: bool,
}

/// How deep `--deep-screen` reaches down each of the sweep's normalised rankings: the depth
/// measured (docs/EVALUATION.md, "The deep screen, off by default").
pub const DEEP_SCREEN_DEPTH: usize = 1000;

impl RegistrationArgs {
    /// The registration settings these flags ask for (the defaults otherwise).
    pub fn config(&self) -> RegisterConfig {
        let mut config = RegisterConfig {
            method: self.method,
            ..RegisterConfig::default()
        };
        config.pair.ransac.seed = self.seed;
        if self.no_clean_walls {
            config.pair.verify.clean_walls = None;
            config.pair.verify.clean_fit = None;
        }
        if self.climb
            && let Some(ascent) = config.pair.ascent.as_mut()
        {
            ascent.min_wall_thickness = 0.0;
        }
        if self.deep_screen
            && let Some(sweep) = config.pair.sweep.as_mut()
        {
            sweep.deep_screened = DEEP_SCREEN_DEPTH;
        }
        if let Some(f) = self.min_overlap {
            config.pair.verify.min_overlap_fraction = f;
            config.pair.verify.crisp_sliver = None;
            config.pair.verify.small_overlap = None;
        }
        if let Some(n) = self.min_overlap_cells {
            config.pair.verify.min_overlap_cells = n;
        }
        config
    }
}

/// What `--deep-screen` might do for a declined pair, in the report's `hint`: said only where
/// it would run (placements were checked and none passed) and only when it was not given.
pub fn deep_screen_hint(args: &RegistrationArgs, r: &Registration) -> Option<&'static str> {
    (!args.deep_screen && !r.candidates.is_empty() && r.candidates.iter().all(|c| !c.accepted))
        .then_some(
            "no placement passed. If the maps do share part of a large floor, the placement \
             near the truth may rank below the 100 the rotation sweep screens: --deep-screen \
             searches 1,000 deep (and may then answer an open hall wrongly; check its answer)",
        )
}

fn parse_method(s: &str) -> Result<Method, String> {
    s.parse()
}

/// How to read a map given as a bare image (no YAML). Ignored for YAML maps.
#[derive(Debug, Clone, Args)]
pub struct BareImageArgs {
    /// Metres per cell of a bare image [default: 0.05]
    #[arg(long, global = true, value_name = "M", value_parser = positive_finite)]
    pub resolution: Option<f64>,
    /// A bare image's pixel is occupied when p = (255 - v) / 255 exceeds this [default: 0.65]
    #[arg(long, global = true, value_name = "P", value_parser = probability)]
    pub occupied_thresh: Option<f64>,
    /// A bare image's pixel is free when p is below this [default: 0.196]
    #[arg(long, global = true, value_name = "P", value_parser = probability)]
    pub free_thresh: Option<f64>,
    /// Read a bare image's dark pixels as free (p = v / 255)
    #[arg(long, global = true)]
    pub negate: bool,
}

impl BareImageArgs {
    /// The load options these flags ask for (a [`UsageError`] if the thresholds contradict).
    pub fn load_options(&self) -> anyhow::Result<LoadOptions> {
        let d = BareImageDefaults::default();
        let bare = BareImageDefaults {
            resolution: self.resolution.unwrap_or(d.resolution),
            origin: Pose2::default(),
            negate: self.negate,
            occupied_thresh: self.occupied_thresh.unwrap_or(d.occupied_thresh),
            free_thresh: self.free_thresh.unwrap_or(d.free_thresh),
            mode: d.mode,
        };
        if bare.free_thresh >= bare.occupied_thresh {
            return Err(UsageError(format!(
                "the free threshold ({}) must be less than the occupied threshold ({}); \
                 check --free-thresh and --occupied-thresh",
                bare.free_thresh, bare.occupied_thresh
            ))
            .into());
        }
        Ok(LoadOptions {
            bare_image: bare,
            ..LoadOptions::default()
        })
    }
}

/// Load a map with the options of `bare`; errors keep their [`grid_core::Error`] for the exit
/// code.
pub fn load(path: &std::path::Path, bare: &BareImageArgs) -> anyhow::Result<LoadedMap> {
    let options = bare.load_options()?;
    Ok(grid_core::io::load_map_with_metadata(path, &options)?)
}

/// Whether `a` and `b` name the same file (compared after resolving links when both exist).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// A usage error when the output `out` (given by `flag`) is one of `inputs`.
pub fn refuse_overwriting<'a>(
    out: &Path,
    flag: &str,
    inputs: impl IntoIterator<Item = &'a PathBuf>,
) -> Result<(), UsageError> {
    if inputs.into_iter().any(|input| same_file(out, input)) {
        return Err(UsageError(format!(
            "{}: {flag} would overwrite an input map; choose another file",
            out.display()
        )));
    }
    Ok(())
}

/// A usage error when the folder the output `out` (given by `flag`) goes to does not exist:
/// checked before the work, not after it.
pub fn require_directory(out: &Path, flag: &str) -> Result<(), UsageError> {
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir.filter(|d| !d.is_dir()) {
        return Err(UsageError(format!(
            "{}: {flag}'s directory {} does not exist",
            out.display(),
            dir.display()
        )));
    }
    Ok(())
}

fn parse_f64(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|_| "not a number".to_string())
}

fn positive_finite(s: &str) -> Result<f64, String> {
    let v = parse_f64(s)?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err("must be a finite number greater than 0".into())
    }
}

fn probability(s: &str) -> Result<f64, String> {
    let v = parse_f64(s)?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err("must be a number between 0 and 1".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_follow_the_conventions() {
        let bad_file = anyhow::Error::from(grid_core::Error::Format {
            path: PathBuf::from("m.yaml"),
            reason: "missing key `image`".into(),
        });
        assert_eq!(exit_code_for(&bad_file), EXIT_BAD_INPUT);
        // Context added on top keeps the code and shows up in the message.
        let wrapped = bad_file.context("reading map A");
        assert_eq!(exit_code_for(&wrapped), EXIT_BAD_INPUT);
        assert_eq!(
            message(&wrapped),
            "reading map A: m.yaml: missing key `image`"
        );
        let unknown = anyhow::Error::from(grid_core::Error::AllUnknown {
            path: PathBuf::from("b.pgm"),
        });
        assert_eq!(exit_code_for(&unknown), EXIT_BAD_INPUT);
        let usage = anyhow::Error::from(UsageError("two maps are needed".into()));
        assert_eq!(exit_code_for(&usage), EXIT_BAD_INPUT);
        let bug = anyhow::Error::from(grid_core::Error::CellCount {
            got: 3,
            expected: 4,
        });
        assert_eq!(exit_code_for(&bug), EXIT_INTERNAL);
        assert_eq!(
            exit_code_for(&anyhow::anyhow!("disk on fire")),
            EXIT_INTERNAL
        );
    }

    #[test]
    fn io_errors_are_not_repeated() {
        let e = anyhow::Error::from(grid_core::Error::Io {
            path: PathBuf::from("x.yaml"),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "gone"),
        });
        assert_eq!(message(&e), "x.yaml: gone");
    }
}
