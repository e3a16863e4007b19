//! The `mapmerge` command line: one module per subcommand under `cmd/`, one small function
//! mapping errors to the exit codes of the conventions (0 ok, 2 bad usage or input, 1 internal
//! error), and no panic or stack trace reaching the user.

mod cmd;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

const AFTER_HELP: &str = "\
Examples:
  mapmerge estimate fixtures/maps/sunil_pair_a/sunil_pair_a.yaml fixtures/maps/sunil_pair_b/sunil_pair_b.yaml
  mapmerge estimate a.yaml b.yaml --json --debug-png matches.png
  mapmerge merge fixtures/maps/sunil_pair_a/sunil_pair_a.yaml fixtures/maps/sunil_pair_b/sunil_pair_b.yaml -o merged.yaml
  mapmerge merge robot1.yaml robot2.yaml robot3.yaml -o team.yaml --weights 1,1,0.5
  mapmerge info fixtures/maps/wpi_ilab/wpi_ilab.yaml
  mapmerge info --json maps/robot1.yaml
  mapmerge info scan.pgm --resolution 0.1 --negate

MAP is a ROS map_server YAML (.yaml/.yml, naming a PGM or PNG image beside it) or a bare
image (.pgm/.pnm/.png). A bare image is read as a trinary map with resolution 0.05 m/cell,
origin [0, 0, 0], occupied_thresh 0.65 and free_thresh 0.196 unless the flags above say
otherwise; those flags do not change maps given by YAML.

Exit codes: 0 success, 3 no trustworthy match (estimate declined the pair, or merge could
place no map in the first map's frame), 2 bad usage or bad input (one line on stderr naming
the file and the problem), 1 internal error.";

/// Merge the occupancy grid maps of a robot team without knowing where each robot started.
#[derive(Debug, Parser)]
#[command(name = "mapmerge", version, about, after_help = AFTER_HELP)]
struct Cli {
    #[command(flatten)]
    bare: cmd::BareImageArgs,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print a map's size, resolution, origin and counts of free, occupied and unknown cells.
    Info(cmd::info::InfoArgs),
    /// Find the rigid transform that maps map B onto map A, or decline the pair (exit 3).
    Estimate(cmd::estimate::EstimateArgs),
    /// Register every pair of maps, place them all in the first map's frame and fuse them into
    /// one map (PGM + YAML) with a JSON report of every map's pose.
    Merge(cmd::merge::MergeArgs),
}

fn main() -> ExitCode {
    cmd::run_main(|| {
        let cli = match Cli::try_parse() {
            Ok(cli) => cli,
            Err(e) => return cmd::clap_outcome(e),
        };
        match &cli.command {
            Command::Info(args) => cmd::info::run(args, &cli.bare),
            Command::Estimate(args) => cmd::estimate::run(args, &cli.bare),
            Command::Merge(args) => cmd::merge::run(args, &cli.bare),
        }
    })
}
