//! `sppm study objectivity|convergence`: the command-line face of the studies.

use super::convergence::{convergence, ConvergenceArgs};
use super::crack_path::CRACK_PATH_DAMAGE;
use super::objectivity::{objectivity, ObjectivityArgs, DEFAULT_SEED};
use super::runner::default_jobs;
use anyhow::bail;
use clap::Subcommand;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Subcommand)]
pub enum StudyCommand {
    /// Run a scene at several lattice rotations (and random lattice offsets) and report the
    /// spread of the peak force and the crack paths (output/<scene>-objectivity/).
    Objectivity {
        scene: PathBuf,
        /// Lattice rotations in degrees, comma-separated.
        #[arg(long, default_value = "0,15,30,45")]
        angles: String,
        /// Random lattice offsets per angle, besides the scene's own offset.
        #[arg(long, default_value_t = 0)]
        offsets: usize,
        /// Seed of the random offsets (recorded in objectivity.csv and objectivity.json).
        #[arg(long, default_value_t = DEFAULT_SEED)]
        seed: u64,
        /// Tensile damage w_t at and above which a particle belongs to the crack path.
        #[arg(long, default_value_t = CRACK_PATH_DAMAGE)]
        crack_damage: f64,
        #[command(flatten)]
        common: StudyOptions,
    },
    /// Run a scene at several lattice spacings and extrapolate the peak force and the
    /// dissipated energy (output/<scene>-convergence/).
    Convergence {
        scene: PathBuf,
        /// Lattice spacings L0 in m, comma-separated.
        #[arg(long)]
        spacings: String,
        #[command(flatten)]
        common: StudyOptions,
    },
}

/// The options every study takes.
#[derive(clap::Args)]
pub struct StudyOptions {
    /// Override a scene value in every run (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Study folder (default: output/<scene name>-<study>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Runs at a time, each on one thread (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// A comma-separated list of numbers; `option` names it in the message.
pub fn parse_list(option: &str, text: &str) -> anyhow::Result<Vec<f64>> {
    let items: Vec<&str> = text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    if items.is_empty() {
        bail!("{option} `{text}`: give a comma-separated list of at least one number");
    }
    items
        .iter()
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow::anyhow!("{option} `{text}`: `{s}` is not a number (a comma-separated list of numbers is expected)")
                })
        })
        .collect()
}

/// Run a study command; exit status 0, or 3 when a run went unstable (its row says so).
pub fn dispatch(cmd: StudyCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        StudyCommand::Objectivity {
            scene,
            angles,
            offsets,
            seed,
            crack_damage,
            common:
                StudyOptions {
                    set,
                    out,
                    jobs,
                    quiet,
                },
        } => {
            let report = objectivity(&ObjectivityArgs {
                crack_damage,
                scene,
                angles_deg: parse_list("--angles", &angles)?,
                offsets,
                seed,
                overrides: set,
                out,
                jobs: jobs.unwrap_or_else(default_jobs),
                progress: !quiet,
            })?;
            println!("{}", report.spread_line());
            if !quiet {
                println!("wrote {}", report.dir.display());
            }
            Ok(status(report.completed, report.runs))
        }
        StudyCommand::Convergence {
            scene,
            spacings,
            common:
                StudyOptions {
                    set,
                    out,
                    jobs,
                    quiet,
                },
        } => {
            let report = convergence(&ConvergenceArgs {
                scene,
                spacings_m: parse_list("--spacings", &spacings)?,
                overrides: set,
                out,
                jobs: jobs.unwrap_or_else(default_jobs),
                progress: !quiet,
            })?;
            for l in report.lines() {
                println!("{l}");
            }
            if !quiet {
                println!("wrote {}", report.dir.display());
            }
            Ok(status(report.completed, report.runs))
        }
    }
}

fn status(completed: usize, runs: usize) -> ExitCode {
    if completed < runs {
        eprintln!(
            "error: {} of {runs} runs did not complete (see their status and message in the CSV)",
            runs - completed
        );
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    }
}
