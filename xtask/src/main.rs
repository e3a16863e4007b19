//! Project automation (`cargo xtask <command>`): one module per command; this file only
//! dispatches. Not shipped; not a library.

use clap::{Parser, Subcommand};

mod calibrate;
mod compare;
mod eval;
mod r#gen;
mod picture;
mod regress;
mod team;

/// mapmerge project tasks.
#[derive(Parser)]
#[command(name = "xtask")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// The arguments are boxed: their many flags make the variants large and of unequal size.
#[derive(Subcommand)]
enum Command {
    /// Generate simulated robot-team cases (partial maps with known truth).
    Gen(Box<r#gen::Args>),
    /// Measure registration accuracy, decline rate and time on regenerable simulated suites.
    Eval(Box<eval::EvalArgs>),
    /// Compare two runs of `eval --out`, case by case: what changed.
    Compare(compare::Args),
    /// Run the regression batch of eval sets into a directory (for `compare`).
    Regress(regress::Args),
    /// Measure how well `mapmerge merge` places every map of simulated robot teams.
    Team(team::Args),
    /// Tabulate accepted answers' errors by their confidence, over runs of `eval --out`.
    Calibrate(calibrate::Args),
}

/// Write `text` to stdout. A reader that stopped reading (`cargo xtask compare A B | head`)
/// ends the output quietly instead of with `print!`'s panic.
pub fn emit(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().command {
        Command::Gen(args) => r#gen::run(*args),
        Command::Eval(args) => eval::run(*args),
        Command::Compare(args) => compare::run(args),
        Command::Regress(args) => regress::run(args),
        Command::Team(args) => team::run(args),
        Command::Calibrate(args) => calibrate::run(args),
    }
}
