//! The `sppm` command line: a thin caller of the library.

use anyhow::Context;
use clap::{Parser, Subcommand};
use sppm::fsio::{FolderBusy, IoFailure};
use sppm::run::RunOptions;
use sppm::{say, Scene};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "sppm",
    version,
    about = "Peridynamic lattice (SPLM) and particle (SPPM) models of concrete fracture"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene and write its outputs to output/<scene>/ (or --out).
    Run {
        scene: PathBuf,
        /// Output folder (default: output/<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene value, e.g. --set material.E=3.0e10 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress bar and no report on stdout.
        #[arg(long)]
        quiet: bool,
        /// Worker threads (default: the scene's solver.threads, else all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Validate a scene and print its size, time step, steps, memory and run time estimates.
    Check {
        scene: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Throughput of the step kernel on a square hexagonal-lattice block or (--dim 3) an FCC
    /// cube (one JSON line).
    Bench(BenchArgs),
    /// Many runs of one scene: lattice objectivity, convergence with the spacing, Monte Carlo
    /// size effect (and the merge of its shards).
    Study {
        #[command(subcommand)]
        study: sppm::study::cli::StudyCommand,
    },
}

/// The options of `sppm bench`.
#[derive(clap::Args)]
struct BenchArgs {
    /// Dimension: 2 (square block of hexagonal lattice) or 3 (cube of FCC lattice,
    /// 18 neighbours).
    #[arg(long, default_value_t = 2)]
    dim: usize,
    #[arg(long, default_value_t = 100_000)]
    particles: usize,
    #[arg(long, default_value_t = 200)]
    steps: usize,
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Kernel: "elastic", "tension" (tensile damage only) or "full" (two-spring damage and
    /// plasticity; "concrete" is accepted for it).
    #[arg(long, default_value = "elastic")]
    model: String,
    /// Particles: "hexagonal" (the lattice) or "random" (SPPM; slots only; the set-up
    /// times of placement, Voronoi cells, bonds and moduli are reported too).
    #[arg(long, default_value = "hexagonal")]
    lattice: String,
    /// Run the damage kernels' scalar path instead of their AVX blocks (--model tension
    /// or full), to measure the two in one binary.
    #[arg(long)]
    scalar: bool,
}

/// `sppm check` reports its stages on stderr for bodies of at least this many particles
/// (a 2.3e6-particle plate takes minutes to set up).
const CHECK_PROGRESS_PARTICLES: f64 = 5e4;

/// Exit statuses (docs/cli.md, docs/reliability.md).
mod exit {
    /// Bad input: a malformed scene, an impossible parameter or count.
    pub const BAD_INPUT: u8 = 2;
    /// A run that went unstable or whose increments did not converge.
    pub const RUN_FAILED: u8 = 3;
    /// An output could not be written (unwritable folder, full disk).
    pub const IO_FAILURE: u8 = 4;
    /// The output or study folder is in use by another sppm process.
    pub const FOLDER_BUSY: u8 = 5;
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            let code = if e.chain().any(|c| c.is::<FolderBusy>()) {
                exit::FOLDER_BUSY
            } else if e.chain().any(|c| c.is::<IoFailure>()) {
                exit::IO_FAILURE
            } else {
                exit::BAD_INPUT
            };
            ExitCode::from(code)
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Run {
            scene,
            out,
            set,
            quiet,
            threads,
        } => run_scene(&scene, out, &set, quiet, threads),
        Command::Check { scene, set } => {
            let sc = Scene::from_file(&scene, &set)?;
            // large bodies take minutes to set up: say what is going on (stderr)
            let started = std::time::Instant::now();
            let loud = sppm::run::estimated_particles(&sc) >= CHECK_PROGRESS_PARTICLES;
            let stage = |what: &str| {
                if loud {
                    eprintln!("[{:7.1} s] {what}…", started.elapsed().as_secs_f64());
                }
            };
            sppm::run::check::check(&sc, &stage)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Bench(args) => bench(&args),
        Command::Study { study } => sppm::study::cli::dispatch(study),
    }
}

/// `sppm run`: run a scene and write its outputs into `out` (default output/<scene name>).
fn run_scene(
    scene: &std::path::Path,
    out: Option<PathBuf>,
    set: &[String],
    quiet: bool,
    threads: Option<usize>,
) -> anyhow::Result<ExitCode> {
    let sc = Scene::from_file(scene, set)?;
    if threads == Some(0) {
        anyhow::bail!("--threads 0: at least 1 worker thread is needed");
    }
    let dir = out.unwrap_or_else(|| PathBuf::from("output").join(sc.name()));
    // the folder is created, locked and so known to be writable before any compute
    let _lock = sppm::fsio::FolderLock::acquire(&dir)?;
    let outcome = sppm::run(
        &sc,
        &RunOptions {
            progress: !quiet,
            threads,
        },
    )?;
    let files = sppm::output::write_all(&outcome, &dir)?;
    let s = &outcome.summary;
    if !quiet {
        say!(
            "{}: {} particles, {} bonds, {} steps of {:.4e} s (T1 = {:.4e} s) in {:.2} s on {} threads",
            s.scene, s.particles, s.bonds, s.steps, s.dt_s, s.fundamental_period_s, s.wall_time_s, s.threads
        );
        say!(
            "peak force {:.6e} N at {:.6e} m; max kinetic/internal energy {:.3e}",
            s.peak_force_n,
            s.displacement_at_peak_m,
            s.max_kinetic_to_internal_energy
        );
        if let Some(t) = &s.load_test {
            say!(
                "load test ({}): {} at step {} ({:.4e} s): {}",
                t.criterion,
                if t.verdict == sppm::solver::failure::Verdict::Holds {
                    "holds"
                } else {
                    "fails"
                },
                t.decided_at_step,
                t.decided_at_s,
                t.reason
            );
        }
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
        // the frames of a time series in one line
        let frame = |f: &PathBuf| {
            f.file_name()
                .is_some_and(|n| sppm::output::snapshots::is_frame_file(&n.to_string_lossy()))
        };
        for f in files.iter().filter(|f| !frame(f)) {
            say!("wrote {}", f.display());
        }
        let frames = files.iter().filter(|f| frame(f)).count();
        if frames > 0 {
            let folder = dir.join(sppm::output::snapshots::FOLDER);
            say!("wrote {} frames in {}", frames, folder.display());
        }
    }
    if let (Some(k @ 1..), Some(r), false) = (
        s.unconverged_increments,
        s.max_final_residual,
        outcome.failed(),
    ) {
        eprintln!(
            "warning: {k} of {} load increments stopped at solver.max_iterations with an out-of-balance force up to {r:.3e} × the reactions (accepted by solver.max_residual = {:e})",
            s.increments.unwrap_or(0),
            sc.solver.max_residual.unwrap_or(sc.solver.tolerance)
        );
    }
    if outcome.failed() {
        eprintln!("error: {}", s.message.clone().unwrap_or_default());
        return Ok(ExitCode::from(exit::RUN_FAILED));
    }
    Ok(ExitCode::SUCCESS)
}

/// `sppm bench`: the step kernel's throughput, one JSON line.
fn bench(args: &BenchArgs) -> anyhow::Result<ExitCode> {
    let BenchArgs {
        dim,
        particles,
        steps,
        threads,
        ref model,
        ref lattice,
        scalar,
    } = *args;
    anyhow::ensure!(
        dim == 2 || dim == 3,
        "--dim {dim}: 2 (hexagonal lattice) or 3 (FCC lattice)"
    );
    let kernel = match model.as_str() {
        "elastic" => sppm::solver::KernelSet::Elastic,
        "tension" => sppm::solver::KernelSet::Tension,
        "full" | "concrete" => sppm::solver::KernelSet::Full,
        _ => anyhow::bail!(
            "--model {model}: \"elastic\", \"tension\" (tensile damage only) or \"full\" (damage and plasticity)"
        ),
    };
    anyhow::ensure!(
        !scalar || kernel != sppm::solver::KernelSet::Elastic,
        "--scalar: the scalar path of the damage kernels (--model tension or full); the elastic kernel has no switch"
    );
    if dim == 3 {
        anyhow::ensure!(
            ["hexagonal", "fcc", "random"].contains(&lattice.as_str()),
            "--lattice {lattice} with --dim 3: \"fcc\" (the FCC lattice) or \"random\" (random particles)"
        );
    }
    anyhow::ensure!(particles >= 10, "--particles {particles}: at least 10");
    sppm::limits::check_count(
        "--particles",
        particles as f64,
        sppm::bench::bytes_per_particle(kernel, dim) as f64,
        "particles",
    )?;
    anyhow::ensure!(threads >= 1, "--threads {threads}: at least 1");
    anyhow::ensure!(
        threads <= 4096,
        "--threads {threads}: at most 4096 worker threads"
    );
    let r = if dim == 3 && lattice == "random" {
        sppm::bench::bench_random3(particles, steps.max(1), threads, kernel, !scalar)
    } else if dim == 3 {
        sppm::bench::bench_fcc(particles, steps.max(1), threads, kernel, !scalar)
    } else {
        sppm::bench::bench(particles, steps.max(1), threads, kernel, lattice, !scalar)
    }
    .context("benchmark failed")?;
    say!("{}", serde_json::to_string(&r)?);
    Ok(ExitCode::SUCCESS)
}
