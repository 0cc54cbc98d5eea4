//! `sppm study objectivity|convergence|montecarlo|merge`: the command-line face of the studies.

use super::convergence::{convergence, ConvergenceArgs};
use super::crack_path::CRACK_PATH_DAMAGE;
use super::monte_carlo::{
    merge, monte_carlo, parse_shard, parse_sizes, MonteCarloArgs, SIZE_VARIANT_HELP,
};
use super::objectivity::{objectivity, ObjectivityArgs, DEFAULT_SEED};
use super::options::parse_list;
use super::runner::default_jobs;
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
        /// The axis the angles turn the lattice or particle set about: z (2D, and 3D's
        /// default), x or y (3D: turns a prism's loading axis along z against the particles).
        #[arg(long, default_value_t = 'z')]
        axis: char,
        /// Random lattice offsets per angle, besides the scene's own offset (random particles:
        /// further particle sets per angle, besides the scene's own seed).
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
    /// Realisations of the scene's random fields per specimen size and the statistical size
    /// effect (output/<scene>-montecarlo/).
    ///
    /// N realisations per size, realisation r of size D with the seed hashed (SplitMix64) from
    /// (S, D in µm, r), plus one deterministic run per size without the random fields. Writes
    /// realisations.csv (a row per finished run; the same command resumes), deterministic.csv
    /// and, for the whole study, size_effect.csv/json/svg (mean, std and CoV of σN per size,
    /// Bažant type-1 and Weibull fits).
    ///
    /// σN per body: a dog-bone P_max/(0.6·D·t); a notched beam (or any beam in three-point
    /// bending) 3·P_max·S/(2·b·d²), S the span between its supports and D = d its depth; a
    /// block loaded through whole faces P_max/A over its section normal to the load. Any other
    /// body is refused.
    #[command(after_help = SIZE_VARIANT_HELP)]
    Montecarlo {
        scene: PathBuf,
        /// Realisations per size.
        #[arg(long)]
        realisations: usize,
        /// Study seed S (recorded in the CSV and size_effect.json).
        #[arg(long)]
        seed: u64,
        /// Dog-bone sizes: letters A–F (D = 0.05, 0.1, 0.2, 0.4, 0.8, 1.6 m) or D in m,
        /// comma-separated (default: the scene's own size; needs a dog-bone body).
        #[arg(long)]
        sizes: Option<String>,
        /// Run only shard k of n: the runs whose index ≡ k−1 (mod n); no size-effect report
        /// (combine the shards with `sppm study merge`).
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
        /// Write every output of every run (default: summary.json only).
        #[arg(long)]
        keep_outputs: bool,
        #[command(flatten)]
        common: StudyOptions,
    },
    /// Run one specimen under each model family, side by side: the scene as written (SPLM),
    /// its body in random particles (SPPM, lattice scenes only) and the bond-based model on the
    /// scene's own particles (output/<scene>-families/families.csv, a row per family written
    /// as it finishes; the same command resumes).
    Families {
        scene: PathBuf,
        /// Override a scene value in every run (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Study folder (default: output/<scene file stem>-families).
        #[arg(long)]
        out: Option<PathBuf>,
        /// The families to run, comma-separated: splm, sppm, bond_based (default all).
        #[arg(long, default_value = "splm,sppm,bond_based")]
        families: String,
    },
    /// The failure load under a force-controlled load: the geometric binary search of Ness
    /// (2019) on the scene's one `load.force` group, each test judged by its [failure]
    /// criterion (output/<scene>-bisection/bisection.csv, a row per test written as it
    /// finishes, and bisection.json; the same command resumes).
    Bisection {
        scene: PathBuf,
        /// The lower bound of the failure load (N, magnitude).
        #[arg(long)]
        lower: f64,
        /// The upper bound (N, magnitude).
        #[arg(long)]
        upper: f64,
        /// Stop when upper − lower is at most this (N).
        #[arg(long)]
        tolerance: f64,
        /// Override a scene value in every run (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Study folder (default: output/<scene file stem>-bisection).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Combine the shard folders of one Monte Carlo study: realisations.csv,
    /// deterministic.csv and the size-effect report in --out.
    Merge {
        /// Shard folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Folder of the merged study (default: output/<scene name>-montecarlo).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the report even if the folders lack runs their commands asked for (a shard
        /// not given or not finished); size_effect.json then records that it is partial.
        #[arg(long)]
        partial: bool,
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

/// Run a study command; exit status 0, or 3 when a run did not complete (went unstable or
/// could not be set up: its row says so; a Monte Carlo size without a completed realisation
/// is named). Errors (bad input, a busy folder, an incomplete merge) are the caller's.
pub fn dispatch(cmd: StudyCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        StudyCommand::Objectivity {
            scene,
            angles,
            axis,
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
                axis,
                offsets,
                seed,
                overrides: set,
                out,
                jobs: jobs.unwrap_or_else(default_jobs),
                progress: !quiet,
            })?;
            crate::say!("{}", report.spread_line());
            for line in report.crack_summary_lines() {
                crate::say!("{line}");
            }
            if let Some(line) = report.crack_band_line() {
                crate::say!("{line}");
            }
            if let Some(line) = report.angle_effect_line() {
                crate::say!("{line}");
            }
            if !quiet {
                crate::say!("wrote {}", report.dir.display());
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
                crate::say!("{l}");
            }
            if !quiet {
                crate::say!("wrote {}", report.dir.display());
            }
            Ok(status(report.completed, report.runs))
        }
        StudyCommand::Montecarlo {
            scene,
            realisations,
            seed,
            sizes,
            shard,
            keep_outputs,
            common:
                StudyOptions {
                    set,
                    out,
                    jobs,
                    quiet,
                },
        } => {
            let report = monte_carlo(&MonteCarloArgs {
                scene,
                realisations,
                seed,
                sizes: sizes.as_deref().map(parse_sizes).transpose()?,
                shard: shard.as_deref().map(parse_shard).transpose()?,
                keep_outputs,
                overrides: set,
                out,
                jobs: jobs.unwrap_or_else(default_jobs),
                progress: !quiet,
            })?;
            crate::say!("σN: {}", report.nominal);
            let mut empty = vec![];
            match &report.size_effect {
                Some(effect) => {
                    for l in effect.lines() {
                        crate::say!("{l}");
                    }
                    empty = effect.sizes_without_realisations();
                }
                None => crate::say!(
                    "shard done: {} runs in {} (combine the shards with `sppm study merge`)",
                    report.runs,
                    report.dir.display()
                ),
            }
            if !quiet {
                crate::say!("wrote {}", report.dir.display());
            }
            no_data(&empty, "realisations.csv");
            Ok(status(report.completed, report.runs))
        }
        StudyCommand::Families {
            scene,
            set,
            out,
            families,
        } => {
            let out = out.unwrap_or_else(|| super::families::default_out(&scene));
            let wanted: Vec<&str> = families.split(',').map(str::trim).collect();
            for w in &wanted {
                if !["splm", "sppm", "bond_based"].contains(w) {
                    anyhow::bail!(
                        "--families: {w:?} is not a family; allowed: splm, sppm, bond_based"
                    );
                }
            }
            let rows = super::families::families(&scene, &set, &out, &wanted)?;
            for r in &rows {
                crate::say!("{r}");
            }
            crate::say!("wrote {}", out.join("families.csv").display());
            let failed = rows
                .iter()
                .skip(1)
                .filter(|r| r.contains(",failed,"))
                .count();
            Ok(status(rows.len() - 1 - failed, rows.len() - 1))
        }
        StudyCommand::Bisection {
            scene,
            lower,
            upper,
            tolerance,
            set,
            out,
        } => {
            let out = out.unwrap_or_else(|| super::bisection::default_out(&scene));
            let initial = super::bisection::Bracket { lower, upper };
            let r = super::bisection::bisection(&scene, &set, &out, initial, tolerance)?;
            crate::say!(
                "failure load {:.4e} N: held {:.4e} N, failed {:.4e} N after {} tests ({})",
                r.failure_load,
                r.bracket.lower,
                r.bracket.upper,
                r.tests,
                r.criterion
            );
            if let Some(w) = &r.warning {
                eprintln!("warning: {w}");
            }
            crate::say!("wrote {}", out.join("bisection.json").display());
            Ok(status(1, 1))
        }
        StudyCommand::Merge { dirs, out, partial } => {
            let merged = merge(&dirs, out, partial)?;
            for n in &merged.notes {
                eprintln!("note: {n}");
            }
            if !merged.missing.is_empty() {
                eprintln!(
                    "warning: partial merge (--partial): the report covers only the runs there are, and size_effect.json records it; missing: {}",
                    merged.missing.join("; ")
                );
            }
            for l in merged.effect.lines() {
                crate::say!("{l}");
            }
            crate::say!("wrote {}", merged.effect.dir.display());
            no_data(
                &merged.effect.sizes_without_realisations(),
                "realisations.csv",
            );
            Ok(status(merged.completed, merged.runs))
        }
    }
}

/// Say which sizes have no completed realisation (their statistics are NaN).
fn no_data(sizes: &[f64], csv: &str) {
    if !sizes.is_empty() {
        let list: Vec<String> = sizes.iter().map(|d| format!("{d} m")).collect();
        eprintln!(
            "error: no realisation completed at D = {}: no statistics for {} (NaN in size_effect.csv, null in size_effect.json; see the status and message of the runs in {csv})",
            list.join(", "),
            if sizes.len() == 1 { "it" } else { "them" }
        );
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
