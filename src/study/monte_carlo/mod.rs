//! The Monte Carlo study of the statistical size effect (docs/model.md §12, docs/validation.md §D): N
//! realisations of the scene's random fields per specimen size, each with its own seed, plus
//! one deterministic run per size (the random fields removed: the mean properties
//! everywhere), and the size-effect statistics and fits ([`super::size_effect`]).
//!
//! - **Sizes.** `--sizes` takes dog-bone letters A–F (D = 0.05, 0.1, 0.2, 0.4, 0.8, 1.6 m) or
//!   sizes D in m. The size variant of size D from a scene of size D0 and spacing s0 has
//!   `body.size = D` (a 3D prism of the dog-bone section: `body.section.size = D`, its
//!   thickness kept), `discretisation.spacing = s0·min(1, D/D0)` (the same particles per
//!   width below the scene's size; the scene's spacing, which resolves the material's
//!   correlation length, above it), every loaded group's displacement scaled by √(D/D0), and,
//!   with the relaxation solver, `solver.max_iterations()` scaled by max(1, D/D0).
//!   - The displacement: the elastic elongation at the peak grows with D, but the crack opening
//!     needed to fall to `stop_after_peak` × the peak does not (it is a fraction of COD_c), so
//!     scaling by D/D0 left the small sizes short of it (dog-bone A from the 0.1 mm of D: the
//!     force never fell to 80% within 12.5 µm) and by 1 resolves the large sizes' peaks coarsely.
//!     √(D/D0) puts the peak at 25–60% of the load path from A to F.
//!   - The iterations: increments in which damage grows do not converge and stop at
//!     max_iterations, and a crack needs about as many iterations to run as there are particles
//!     across, which grows as D/D0 above D0 (fixed spacing). With a fixed limit the peak of the
//!     large sizes came out high: dog-bone F, one realisation, 181.6 / 167.9 / 165.0 kN at 500 /
//!     2000 / 4000 iterations (E: 92.5 / 90.65 / 90.2 kN at 500 / 1000 / 2000; D: 50.52 / 50.36 kN
//!     at 500 / 2000).
//! - **Random particles** (2D, and 3D solids) draw a new particle set per realisation from its
//!   seed; 3D bodies other than the dog-bone prism read σN over their mean section normal to
//!   the loaded component ([`nominal_strength`]).
//! - **Seeds.** Realisation r (0-based) of size D has the seed
//!   [`realisation_seed`]`(S, D, r)`, a SplitMix64 hash of the study seed S, D in µm (an
//!   integer) and r: independent of the shard, the job count and the order of the runs. It is
//!   set with `--set seed=...` and recorded in summary.json and the CSV.
//! - **Shards.** The runs are listed slot-major: index = slot·(number of sizes) + size index,
//!   slot 0 the deterministic run and slot r + 1 realisation r. Shard k/n runs the indices
//!   ≡ k − 1 (mod n); adding realisations leaves every earlier run in its shard.
//! - **Files.** `realisations.csv` (one row per realisation, appended as each finishes),
//!   `deterministic.csv` (one row per size), then `size_effect.csv`, `size_effect.json` and
//!   `size_effect.svg` ([`super::size_effect_report`]); `sppm study merge` combines shard
//!   folders into the same files.

mod merge;
mod nominal;
mod records;
mod shards;
mod sizes;

pub use merge::{merge, MergeReport};
pub use nominal::{body_kind, three_point_span, Nominal};
pub use shards::{parse_shard, Item, Shard, ShardRuns};
pub use sizes::{
    nominal_strength, parse_sizes, realisation_seed, size_overrides, DISPLACEMENT_RULE,
    DOGBONE_SIZES, SIZE_VARIANT_HELP, SPACING_RULE,
};

use super::runner::{RunOutputs, RunResult, Runs, Study, Variant};
use super::size_effect_report::{report, SizeEffect};
use crate::run::Outcome;
use crate::Scene;
use anyhow::{bail, Context};
use records::{write_record, StudyInputs, StudyRequest};
use serde_json::json;
use sizes::{dogbone_size, nominal_size, size_label};
use std::path::{Path, PathBuf};

/// What a Monte Carlo command in a folder was last asked for (realisations, sizes, shard),
/// written when it starts: `sppm study merge` checks the folder's rows against it.
pub const REQUEST_FILE: &str = "study_request.json";

/// The study's inputs.
#[derive(Clone, Debug)]
pub struct MonteCarloArgs {
    pub scene: PathBuf,
    pub realisations: usize,
    pub seed: u64,
    /// Sizes D in m; `None`: the scene's own size.
    pub sizes: Option<Vec<f64>>,
    pub shard: Option<Shard>,
    /// Write every output of every run (default: summary.json only).
    pub keep_outputs: bool,
    pub overrides: Vec<String>,
    pub out: Option<PathBuf>,
    pub jobs: usize,
    pub progress: bool,
}

/// The tag columns of realisations.csv and deterministic.csv ([`records::TaggedRow`] reads
/// them back).
const TAGS: [&str; 3] = ["size_D_m", "realisation", "seed"];
const DET_TAGS: [&str; 2] = ["size_D_m", "seed"];
const METRICS: [&str; 1] = ["sigma_N_Pa"];

/// σN of a run (NaN where it is not defined: the study refuses such a scene before it runs).
fn sigma_metric(o: &Outcome) -> Vec<f64> {
    vec![nominal_strength(&o.scene, o.summary.peak_force_n).unwrap_or(f64::NAN)]
}

/// The two study tables of a folder: realisations and deterministic runs.
fn studies<'a>(
    scene: &Path,
    overrides: &[String],
    dir: &Path,
    inputs: &StudyInputs,
    jobs: usize,
    progress: bool,
    outputs: RunOutputs,
) -> (Study<'a>, Study<'a>) {
    let inputs = inputs.value();
    let make = |csv: &str, tags: &[&str]| Study {
        scene: scene.to_path_buf(),
        base_overrides: overrides.to_vec(),
        dir: dir.to_path_buf(),
        csv_name: csv.into(),
        tag_columns: tags.iter().map(|s| s.to_string()).collect(),
        metric_columns: METRICS.iter().map(|s| s.to_string()).collect(),
        metrics: &sigma_metric,
        notes: None,
        inputs: inputs.clone(),
        jobs,
        progress,
        outputs,
    };
    (
        make("realisations.csv", &TAGS),
        make("deterministic.csv", &DET_TAGS),
    )
}

/// What a Monte Carlo command did: the size effect (`None` for a shard) and the counts.
pub struct MonteCarloReport {
    pub dir: PathBuf,
    pub runs: usize,
    /// Runs (realisations and deterministic) that completed.
    pub completed: usize,
    pub size_effect: Option<SizeEffect>,
    /// How σN was read ([`Nominal::describe`]).
    pub nominal: String,
}

/// Run the study (or one shard of it); without a shard, write the size-effect report.
pub fn monte_carlo(args: &MonteCarloArgs) -> anyhow::Result<MonteCarloReport> {
    if args.realisations == 0 {
        bail!("--realisations 0: at least 1 realisation per size is needed");
    }
    let base = Scene::from_file(&args.scene, &args.overrides)?;
    let nominal = Nominal::of(&base)?;
    check_random_fields(args, &base)?;
    let sizes = study_sizes(args, &base)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("output").join(format!("{}-montecarlo", base.name())));
    let text = std::fs::read(&args.scene)
        .with_context(|| format!("cannot read {}", args.scene.display()))?;
    let d0 = nominal.size();
    let inputs = StudyInputs::of(args, &base, &sizes, &text, d0);
    let outputs = if args.keep_outputs {
        RunOutputs::All
    } else {
        RunOutputs::Summary
    };
    let (mc, det) = studies(
        &args.scene,
        &args.overrides,
        &dir,
        &inputs,
        args.jobs,
        args.progress,
        outputs,
    );
    let plan = ShardRuns::new(&sizes, args.realisations, args.shard);
    let det_sizes = plan.deterministic();
    let total = plan.realisations() + det_sizes.len() as u128;
    crate::limits::check_count_of(
        &format!(
            "--realisations {} with {} size{}{}: {total} runs{}",
            args.realisations,
            sizes.len(),
            if sizes.len() == 1 { "" } else { "s" },
            args.shard.map(|s| format!(" and --shard {s}")).unwrap_or_default(),
            if args.shard.is_some() { " in this shard" } else { "" }
        ),
        total as f64,
        mc.bytes_per_run(&base),
        "runs",
        "fewer --realisations, or split the study with --shard k/n and combine the shards with `sppm study merge`",
    )?;
    let variants = Variants::new(args, &base, &sizes, &plan);
    let det_make = |j: usize| variants.deterministic(j);
    let mc_make = |j: usize| variants.realisation(j);
    let det_runs = Runs {
        count: det_sizes.len(),
        variant: &det_make,
        probes: (0..det_sizes.len()).collect(),
    };
    let mc_runs = Runs {
        count: plan.realisations() as usize,
        variant: &mc_make,
        probes: plan.first_of_each_size(),
    };
    det.check(&det_runs)?;
    mc.check(&mc_runs)?;
    if total == 0 {
        eprintln!(
            "warning: --shard {} of {} runs holds none of them",
            args.shard.map(|s| s.to_string()).unwrap_or_default(),
            (args.realisations as u128 + 1) * sizes.len() as u128
        );
    }
    let lock = crate::fsio::FolderLock::acquire(&dir)?;
    det.check_inputs()?;
    let request = StudyRequest {
        realisations: args.realisations,
        sizes_m: sizes.clone(),
        shard: args.shard.map(|s| s.to_string()),
    };
    write_record(&dir.join(REQUEST_FILE), &request)?;
    let det_results = det.run(&lock, &det_runs)?;
    let mc_results = mc.run(&lock, &mc_runs)?;
    let runs = det_results.len() + mc_results.len();
    let completed = det_results
        .iter()
        .chain(&mc_results)
        .filter(|r| r.row.completed())
        .count();
    let size_effect = match args.shard {
        Some(_) => None,
        None => Some(size_effect(args, &base, &dir, mc_results, det_results)?),
    };
    drop(lock);
    Ok(MonteCarloReport {
        dir,
        runs,
        completed,
        size_effect,
        nominal: nominal.describe(),
    })
}

/// Refuse a random field with its own seed (every realisation would draw the same field), and
/// warn of a scene without random fields or random particles (every realisation is the same).
fn check_random_fields(args: &MonteCarloArgs, base: &Scene) -> anyhow::Result<()> {
    for (k, f) in base.random_field.iter().enumerate() {
        if let Some(s) = f.seed {
            bail!(
                "random_field[{k}].seed = {s} (property {}): with its own seed every realisation \
                 would draw the same field; remove it so that the field's seed derives from the \
                 scene's seed, which the Monte Carlo study sets per realisation",
                f.property.name()
            );
        }
    }
    // random particles draw a new particle set per realisation from its seed
    if base.random_field.is_empty() && !base.discretisation.is_random() {
        eprintln!(
            "warning: {} has no [[random_field]]: every realisation of a size is the same run",
            args.scene.display()
        );
    }
    Ok(())
}

/// The sizes D (m) of the study: `--sizes` of a dog-bone without cutouts, else the scene's
/// own size.
fn study_sizes(args: &MonteCarloArgs, base: &Scene) -> anyhow::Result<Vec<f64>> {
    let Some(s) = &args.sizes else {
        return Ok(vec![nominal_size(base)?]);
    };
    if dogbone_size(&base.body).is_none() {
        bail!(
            "--sizes needs a dog-bone body ([body] shape = \"dogbone\", or a prism of a dog-bone section); the scene's body is `{}`, whose supports and loading points are groups at fixed positions that a size variant would not move (leave --sizes out to run the scene's own size)",
            body_kind(&base.body)
        );
    }
    if !base.cutouts.is_empty() {
        bail!(
            "--sizes scales the dog-bone (body.size) but not its {} [[cutouts]]; leave --sizes out to run the scene's own size",
            base.cutouts.len()
        );
    }
    Ok(s.clone())
}

/// The runs of a study (or shard), made from their index: the deterministic runs and the
/// realisations of [`ShardRuns`], largest size first (the long runs start early and the last
/// ones to finish are short).
struct Variants<'a> {
    args: &'a MonteCarloArgs,
    sizes: &'a [f64],
    plan: &'a ShardRuns,
    det_sizes: Vec<usize>,
    /// The size variants' overrides, once per size.
    size_overrides: Vec<Vec<String>>,
}

impl<'a> Variants<'a> {
    fn new(
        args: &'a MonteCarloArgs,
        base: &Scene,
        sizes: &'a [f64],
        plan: &'a ShardRuns,
    ) -> Variants<'a> {
        Variants {
            args,
            sizes,
            plan,
            det_sizes: plan.deterministic(),
            size_overrides: sizes.iter().map(|&d| size_overrides(base, d)).collect(),
        }
    }

    /// Deterministic run `j` of the shard: the mean properties everywhere (no random field,
    /// no seed).
    fn deterministic(&self, j: usize) -> Variant {
        let s = self.det_sizes[j];
        let d = self.sizes[s];
        let mut overrides = self.size_overrides[s].clone();
        overrides.push("random_field=[]".into());
        Variant {
            label: format!("{}-det", size_label(d)),
            overrides,
            tags: vec![d.to_string(), String::new()],
        }
    }

    /// Realisation run `j` of the shard, with the seed of its size and realisation.
    fn realisation(&self, j: usize) -> Variant {
        let it = self.plan.realisation(j);
        let d = self.sizes[it.size];
        let r = it.realisation.expect("a realisation");
        let seed = realisation_seed(self.args.seed, d, r);
        let mut overrides = self.size_overrides[it.size].clone();
        overrides.push(format!("seed={seed}"));
        Variant {
            label: format!("{}-r{r}", size_label(d)),
            overrides,
            tags: vec![d.to_string(), r.to_string(), seed.to_string()],
        }
    }
}

/// The size-effect report of a whole (unsharded) study's runs.
fn size_effect(
    args: &MonteCarloArgs,
    base: &Scene,
    dir: &Path,
    mc_results: Vec<RunResult>,
    det_results: Vec<RunResult>,
) -> anyhow::Result<SizeEffect> {
    let rows = |r: Vec<RunResult>| r.into_iter().map(|r| r.row).collect::<Vec<_>>();
    let meta = json!({
        "scene": args.scene.display().to_string(),
        "scene_name": base.name(),
        "seed": args.seed,
        "realisations": args.realisations,
        "spacing_rule": SPACING_RULE,
        "scene_size_m": nominal_size(base)?,
        "nominal_stress": Nominal::of(base)?.describe(),
        "scene_spacing_m": base.discretisation.spacing,
        "overrides": args.overrides,
    });
    let title = format!(
        "{}: size effect, {} realisations",
        base.name(),
        args.realisations
    );
    report(dir, &rows(mc_results), &rows(det_results), meta, &title)
}
