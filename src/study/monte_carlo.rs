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

use super::runner::{RunOutputs, RunRow, Runs, Study, Variant};
use super::size_effect_report::{report, size_um, tag_f64, SizeEffect};
use crate::random_field::splitmix64;
use crate::run::Outcome;
use crate::scene::BodySpec;
use crate::Scene;
use anyhow::{bail, Context};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The van Vliet dog-bone sizes A–F (docs/validation.md §D): D in m.
pub const DOGBONE_SIZES: [(char, f64); 6] = [
    ('A', 0.05),
    ('B', 0.1),
    ('C', 0.2),
    ('D', 0.4),
    ('E', 0.8),
    ('F', 1.6),
];

/// The rule that makes a size variant, as recorded in size_effect.json.
pub const SPACING_RULE: &str = "body.size = D; discretisation.spacing = s0*min(1, D/D0); \
     each loaded group's displacement *= sqrt(D/D0); relaxation: solver.max_iterations *= \
     max(1, D/D0) (D0, s0: the scene's size and spacing)";

/// Shard k of n (1 ≤ k ≤ n).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// Read `--shard k/n`.
pub fn parse_shard(text: &str) -> anyhow::Result<Shard> {
    let bad = || {
        anyhow::anyhow!(
            "--shard `{text}`: expected k/n with whole numbers 1 ≤ k ≤ n (e.g. --shard 3/8)"
        )
    };
    let (k, n) = text.split_once('/').ok_or_else(bad)?;
    let k: usize = k.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if k < 1 || k > n {
        return Err(bad());
    }
    Ok(Shard { k, n })
}

/// Read `--sizes`: dog-bone letters A–F or sizes D in m (> 0), comma-separated; returned
/// sorted and without repeats.
pub fn parse_sizes(text: &str) -> anyhow::Result<Vec<f64>> {
    let items = super::options::comma_items(text);
    if items.is_empty() {
        bail!("--sizes `{text}`: give dog-bone letters A–F or sizes D in m, comma-separated");
    }
    let mut sizes = Vec::new();
    for s in items {
        let letter = DOGBONE_SIZES
            .iter()
            .find(|(c, _)| s.len() == 1 && s.eq_ignore_ascii_case(&c.to_string()));
        let d = match letter {
            Some((_, d)) => *d,
            None => match s.parse::<f64>() {
                Ok(d) if d.is_finite() && d > 0.0 => d,
                _ => bail!(
                    "--sizes `{text}`: `{s}` is neither a dog-bone letter A–F nor a size D in m > 0"
                ),
            },
        };
        sizes.push(d);
    }
    sizes.sort_by(f64::total_cmp);
    sizes.dedup_by(|a, b| size_um(*a) == size_um(*b));
    Ok(sizes)
}

/// The seed of realisation `r` (0-based) of size `d` (m) in a study of seed `study_seed`: a
/// SplitMix64 hash of (S, D in µm, r), kept below 2^63 so that it is a TOML integer.
pub fn realisation_seed(study_seed: u64, d: f64, r: usize) -> u64 {
    splitmix64(splitmix64(splitmix64(study_seed) ^ size_um(d)) ^ r as u64) >> 1
}

/// One run of the study: a size (index into the size list) and a realisation (`None`: the
/// deterministic run).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Item {
    pub size: usize,
    pub realisation: Option<usize>,
}

/// The runs of one shard (or of the whole study), largest size first and within a size in
/// the order of the realisations, without listing them: a shard of R realisations and a
/// million shards is a few numbers per size, not a list of runs.
///
/// The runs of size s in shard k/n are the slots x with x·S + s ≡ k − 1 (mod n) (S sizes,
/// module docs): none, or every slot x0 + t·p with p = n/gcd(S, n).
#[derive(Clone, Debug)]
pub struct ShardRuns {
    /// Per size, largest first.
    per_size: Vec<SizeRuns>,
    /// Slots between two runs of one size in the shard.
    step: u128,
    realisations: u128,
}

#[derive(Clone, Copy, Debug)]
struct SizeRuns {
    size: usize,
    /// The deterministic run (slot 0) is in the shard.
    deterministic: bool,
    /// First realisation slot (≥ 1) in the shard, and how many realisations of this size.
    first_slot: u128,
    count: u128,
    /// Realisations of the larger sizes before this one.
    before: u128,
}

fn gcd(a: u128, b: u128) -> u128 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The inverse of `a` modulo `m` (gcd(a, m) = 1, m ≥ 2).
fn mod_inverse(a: u128, m: u128) -> u128 {
    // extended Euclid on (a, m) < 2^65: fits i128
    let (mut r0, mut r1) = (a as i128, m as i128);
    let (mut s0, mut s1) = (1i128, 0i128);
    while r1 != 0 {
        let q = r0 / r1;
        (r0, r1) = (r1, r0 - q * r1);
        (s0, s1) = (s1, s0 - q * s1);
    }
    s0.rem_euclid(m as i128) as u128
}

impl ShardRuns {
    /// The runs of `shard` (all runs without one) of `sizes` (D in m) × (1 deterministic +
    /// `realisations`).
    pub fn new(sizes: &[f64], realisations: usize, shard: Option<Shard>) -> ShardRuns {
        let ns = sizes.len() as u128;
        let (k, n) = shard.map_or((1, 1), |s| (s.k as u128, s.n as u128));
        let a = ns % n;
        let g = gcd(a, n);
        let step = n / g;
        let r = realisations as u128;
        let mut order: Vec<usize> = (0..sizes.len()).collect();
        order.sort_by(|&x, &y| sizes[y].total_cmp(&sizes[x]));
        let mut before = 0;
        let mut per_size = Vec::with_capacity(order.len());
        for size in order {
            let c = (k - 1 + n - size as u128 % n) % n;
            let (deterministic, first_slot, count) = if !c.is_multiple_of(g) {
                (false, 0, 0)
            } else {
                let x0 = if step == 1 {
                    0
                } else {
                    (c / g % step) * mod_inverse(a / g % step, step) % step
                };
                let first = if x0 == 0 { step } else { x0 };
                let count = if first > r { 0 } else { (r - first) / step + 1 };
                (x0 == 0, first, count)
            };
            per_size.push(SizeRuns {
                size,
                deterministic,
                first_slot,
                count,
                before,
            });
            before += count;
        }
        ShardRuns {
            per_size,
            step,
            realisations: before,
        }
    }

    /// Realisation runs in the shard.
    pub fn realisations(&self) -> u128 {
        self.realisations
    }

    /// Size indices whose deterministic run is in the shard, largest size first.
    pub fn deterministic(&self) -> Vec<usize> {
        self.per_size
            .iter()
            .filter(|s| s.deterministic)
            .map(|s| s.size)
            .collect()
    }

    /// Realisation runs of size index `size` in the shard.
    pub fn realisations_of(&self, size: usize) -> u128 {
        self.per_size
            .iter()
            .find(|s| s.size == size)
            .map_or(0, |s| s.count)
    }

    /// Realisation run `j` (0 ≤ j < [`Self::realisations`]) of the shard.
    pub fn realisation(&self, j: usize) -> Item {
        let j = j as u128;
        let s = self
            .per_size
            .iter()
            .find(|s| j >= s.before && j < s.before + s.count)
            .expect("realisation run index in the shard");
        let slot = s.first_slot + (j - s.before) * self.step;
        Item {
            size: s.size,
            realisation: Some((slot - 1) as usize),
        }
    }

    /// The index of the first realisation run of each size that has one (probes).
    pub fn first_of_each_size(&self) -> Vec<usize> {
        self.per_size
            .iter()
            .filter(|s| s.count > 0)
            .map(|s| s.before as usize)
            .collect()
    }
}

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

/// The nominal strength σN = P_max/(b·D·t) of a run of `scene`: b = 0.6 and D the size of a
/// dog-bone (σN is then the mean stress over the neck; in 3D t is the prism's thickness),
/// else b = 1 and D the body's width. Other 3D bodies: σN = P_max/A with A = V/ℓ, the body's
/// mean section normal to the loaded component (ℓ its extent along it; a box's or a
/// prism's section when pulled along its length).
pub fn nominal_strength(scene: &Scene, peak_force_n: f64) -> f64 {
    let (d, b) = nominal_size(scene);
    match (&scene.body, scene.solid()) {
        (BodySpec::Prism { thickness, .. }, _) if dogbone_size(&scene.body).is_some() => {
            peak_force_n.abs() / (b * d * thickness)
        }
        (_, Some(solid)) => {
            let k = scene
                .groups
                .iter()
                .find_map(|g| g.load.as_ref())
                .map_or(2, |l| l.component.index());
            let (lo, hi) = solid.bounding_box();
            peak_force_n.abs() * (hi[k] - lo[k]) / solid.volume()
        }
        _ => peak_force_n.abs() / (b * d * scene.material.thickness()),
    }
}

/// The size D of a dog-bone body: the 2D dog-bone or a prism of its section.
fn dogbone_size(body: &BodySpec) -> Option<f64> {
    match body {
        BodySpec::Dogbone { size } => Some(*size),
        BodySpec::Prism { section, .. } => dogbone_size(section),
        _ => None,
    }
}

/// (D, b) of [`nominal_strength`].
fn nominal_size(scene: &Scene) -> (f64, f64) {
    match dogbone_size(&scene.body) {
        Some(size) => (size, 0.6),
        None => {
            let (lo, hi) = scene.shape().bounding_box();
            (hi.x - lo.x, 1.0)
        }
    }
}

fn body_name(body: &BodySpec) -> &'static str {
    body.name()
}

/// The label of a size: D in mm, e.g. `D50mm`.
fn size_label(d: f64) -> String {
    format!("D{}mm", size_um(d) as f64 / 1000.0)
}

/// A float as a TOML value.
fn toml_float(v: f64) -> String {
    format!("{v:?}")
}

/// The overrides that make the size variant of size `d` from `base` ([`SPACING_RULE`]).
pub fn size_overrides(base: &Scene, d: f64) -> Vec<String> {
    let Some(d0) = dogbone_size(&base.body) else {
        return vec![];
    };
    let key = match base.body {
        BodySpec::Prism { .. } => "body.section.size",
        _ => "body.size",
    };
    let ratio = d / d0;
    let mut o = vec![
        format!("{key}={}", toml_float(d)),
        format!(
            "discretisation.spacing={}",
            toml_float(base.discretisation.spacing * ratio.min(1.0))
        ),
    ];
    for (i, g) in base.groups.iter().enumerate() {
        if let Some(load) = &g.load {
            o.push(format!(
                "groups.{i}.load.displacement={}",
                toml_float(load.delta() * ratio.sqrt())
            ));
        }
    }
    if base.solver.method.is_incremental() {
        let m = (base.solver.max_iterations() as f64 * ratio.max(1.0)).round() as usize;
        o.push(format!("solver.max_iterations={m}"));
    }
    o
}

/// FNV-1a of bytes (a fingerprint of the scene file in study_inputs.json).
fn fnv1a(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h = (h ^ *b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

const TAGS: [&str; 3] = ["size_D_m", "realisation", "seed"];
const DET_TAGS: [&str; 2] = ["size_D_m", "seed"];
const METRICS: [&str; 1] = ["sigma_N_Pa"];

fn sigma_metric(o: &Outcome) -> Vec<f64> {
    vec![nominal_strength(&o.scene, o.summary.peak_force_n)]
}

/// The two study tables of a folder: realisations and deterministic runs.
fn studies<'a>(
    scene: &Path,
    overrides: &[String],
    dir: &Path,
    inputs: &serde_json::Value,
    jobs: usize,
    progress: bool,
    outputs: RunOutputs,
) -> (Study<'a>, Study<'a>) {
    let make = |csv: &str, tags: &[&str]| Study {
        scene: scene.to_path_buf(),
        base_overrides: overrides.to_vec(),
        dir: dir.to_path_buf(),
        csv_name: csv.into(),
        tag_columns: tags.iter().map(|s| s.to_string()).collect(),
        metric_columns: METRICS.iter().map(|s| s.to_string()).collect(),
        metrics: &sigma_metric,
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
}

/// Run the study (or one shard of it); without a shard, write the size-effect report.
pub fn monte_carlo(args: &MonteCarloArgs) -> anyhow::Result<MonteCarloReport> {
    if args.realisations == 0 {
        bail!("--realisations 0: at least 1 realisation per size is needed");
    }
    let base = Scene::from_file(&args.scene, &args.overrides)?;
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
    let sizes = match &args.sizes {
        Some(s) => {
            if dogbone_size(&base.body).is_none() {
                bail!(
                    "--sizes needs a dog-bone body ([body] shape = \"dogbone\", or a prism of a dog-bone section); the scene's body is `{}` (leave --sizes out to run the scene's own size)",
                    body_name(&base.body)
                );
            }
            if !base.cutouts.is_empty() {
                bail!(
                    "--sizes scales the dog-bone (body.size) but not its {} [[cutouts]]; leave --sizes out to run the scene's own size",
                    base.cutouts.len()
                );
            }
            s.clone()
        }
        None => vec![nominal_size(&base).0],
    };
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("output").join(format!("{}-montecarlo", base.name())));
    let text = std::fs::read(&args.scene)
        .with_context(|| format!("cannot read {}", args.scene.display()))?;
    let d0 = nominal_size(&base).0;
    let inputs = json!({
        "study": "montecarlo",
        "scene": args.scene.display().to_string(),
        "scene_name": base.name(),
        "scene_fnv1a": fnv1a(&text),
        "overrides": args.overrides,
        "seed": args.seed,
        "sizes_m": sizes,
        "scene_size_m": d0,
        "scene_spacing_m": base.discretisation.spacing,
        "shard": args.shard.map(|s| s.to_string()),
    });
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
    // the size variants' overrides, once per size
    let size_o: Vec<Vec<String>> = sizes.iter().map(|&d| size_overrides(&base, d)).collect();
    // largest first: the long runs start early and the last ones to finish are short
    let det_make = |j: usize| {
        let s = det_sizes[j];
        let d = sizes[s];
        let mut overrides = size_o[s].clone();
        // the mean properties everywhere: no random field, no seed
        overrides.push("random_field=[]".into());
        Variant {
            label: format!("{}-det", size_label(d)),
            overrides,
            tags: vec![d.to_string(), String::new()],
        }
    };
    let mc_make = |j: usize| {
        let it = plan.realisation(j);
        let d = sizes[it.size];
        let r = it.realisation.expect("a realisation");
        let seed = realisation_seed(args.seed, d, r);
        let mut overrides = size_o[it.size].clone();
        overrides.push(format!("seed={seed}"));
        Variant {
            label: format!("{}-r{r}", size_label(d)),
            overrides,
            tags: vec![d.to_string(), r.to_string(), seed.to_string()],
        }
    };
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
    let request = json!({
        "realisations": args.realisations,
        "sizes_m": sizes,
        "shard": args.shard.map(|s| s.to_string()),
    });
    crate::fsio::write_json(&dir.join(REQUEST_FILE), &request)?;
    let det_results = det.run(&lock, &det_runs)?;
    let mc_results = mc.run(&lock, &mc_runs)?;
    let runs = det_results.len() + mc_results.len();
    let completed = det_results
        .iter()
        .chain(&mc_results)
        .filter(|r| r.row.completed())
        .count();
    if args.shard.is_some() {
        return Ok(MonteCarloReport {
            dir,
            runs,
            completed,
            size_effect: None,
        });
    }
    let rows = |r: Vec<super::RunResult>| r.into_iter().map(|r| r.row).collect::<Vec<_>>();
    let meta = json!({
        "scene": args.scene.display().to_string(),
        "scene_name": base.name(),
        "seed": args.seed,
        "realisations": args.realisations,
        "spacing_rule": SPACING_RULE,
        "scene_size_m": d0,
        "scene_spacing_m": base.discretisation.spacing,
        "overrides": args.overrides,
    });
    let title = format!(
        "{}: size effect, {} realisations",
        base.name(),
        args.realisations
    );
    let effect = report(&dir, &rows(mc_results), &rows(det_results), meta, &title)?;
    drop(lock);
    Ok(MonteCarloReport {
        dir,
        runs,
        completed,
        size_effect: Some(effect),
    })
}

/// What `sppm study merge` did: the size effect, what the folders lack against what their
/// commands asked for (empty: the whole study), and the counts of runs.
pub struct MergeReport {
    pub effect: SizeEffect,
    pub missing: Vec<String>,
    /// Notes on folders whose request is not recorded (made by an older sppm).
    pub notes: Vec<String>,
    pub runs: usize,
    pub completed: usize,
}

/// Refuse to merge into `out` when it holds another study, or study rows without an inputs
/// record.
fn check_merge_out(out: &Path, inputs: &serde_json::Value) -> anyhow::Result<()> {
    let path = out.join(super::runner::INPUTS_FILE);
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let old: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
            let mut old_unsharded = old.clone();
            if let Some(o) = old_unsharded.as_object_mut() {
                o.insert("shard".into(), serde_json::Value::Null);
            }
            if old_unsharded != *inputs {
                bail!(
                    "{} holds another study ({old}); the shards are from {inputs}: use another --out folder or remove it",
                    out.display()
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if let Some((csv, rows)) = super::runner::study_rows_in(out)? {
                bail!("{}", super::runner::no_inputs_record(out, &csv, rows));
            }
        }
        Err(e) => return Err(crate::fsio::IoFailure::new("read", &path, e).into()),
    }
    Ok(())
}

/// A list of sizes as the messages write it: "0.05, 0.1 m".
fn sizes_text(sizes: &[f64]) -> String {
    let v: Vec<String> = sizes.iter().map(|d| d.to_string()).collect();
    format!("{} m", v.join(", "))
}

/// Combine shard folders of one study into `out` (default: output/<scene>-montecarlo/):
/// realisations.csv, deterministic.csv, study_inputs.json (without the shard) and the
/// size-effect report. Folders of the same study at other sizes (another `--sizes`) combine
/// too: a realisation's seed depends on (S, D, r) only, so e.g. the small sizes at N = 100 and
/// the largest at fewer realisations make one report. Duplicate runs with the same seed are
/// kept once; the same run with different seeds, or folders of different studies (scene,
/// overrides, seed), are an error.
///
/// The folders must hold every run their commands asked for (study_request.json: the
/// realisations, sizes and shard): a missing shard, a shard that has not finished, or a
/// size with fewer realisations than asked is named and refused, unless `partial`, which
/// writes the report of the runs there are and records in size_effect.json that it is
/// partial and what is missing.
pub fn merge(dirs: &[PathBuf], out: Option<PathBuf>, partial: bool) -> anyhow::Result<MergeReport> {
    if dirs.is_empty() {
        bail!("merge: give at least one shard folder");
    }
    let mut common: Option<(serde_json::Value, PathBuf)> = None;
    let mut sizes: Vec<f64> = Vec::new();
    // per folder: its sizes and shard (from study_inputs.json) and requested realisations
    let mut asked: Vec<(Vec<f64>, Option<Shard>, Option<usize>)> = Vec::new();
    for d in dirs {
        let path = d.join("study_inputs.json");
        let text = std::fs::read_to_string(&path).with_context(|| {
            format!(
                "cannot read {} (is {} a Monte Carlo study folder?)",
                path.display(),
                d.display()
            )
        })?;
        let mut v: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("cannot read {}", path.display()))?;
        if v.get("study").and_then(|s| s.as_str()) != Some("montecarlo") {
            bail!("{} is not from a Monte Carlo study", path.display());
        }
        let shard = match v.get("shard").and_then(|s| s.as_str()) {
            Some(t) => Some(parse_shard(t).with_context(|| format!("{}: shard", path.display()))?),
            None => None,
        };
        let mut own_sizes = Vec::new();
        // shards, and studies of other sizes (seeds depend on (S, D, r) only), combine
        if let Some(o) = v.as_object_mut() {
            o.insert("shard".into(), serde_json::Value::Null);
            if let Some(list) = o.insert("sizes_m".into(), serde_json::Value::Null) {
                own_sizes = serde_json::from_value::<Vec<f64>>(list).unwrap_or_default();
                sizes.extend(own_sizes.iter().copied());
            }
        }
        let request = d.join(REQUEST_FILE);
        let realisations = match std::fs::read_to_string(&request) {
            Ok(t) => {
                let r: serde_json::Value = serde_json::from_str(&t)
                    .with_context(|| format!("cannot read {}", request.display()))?;
                Some(
                    r.get("realisations")
                        .and_then(|n| n.as_u64())
                        .with_context(|| format!("{}: no realisations", request.display()))?
                        as usize,
                )
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(crate::fsio::IoFailure::new("read", &request, e).into()),
        };
        asked.push((own_sizes, shard, realisations));
        match &common {
            None => common = Some((v, path)),
            Some((c, first)) if *c != v => bail!(
                "{} and {} are from different studies (their study_inputs.json differ beyond the shard): {c} against {v}",
                first.display(),
                path.display()
            ),
            _ => {}
        }
    }
    let (mut inputs, _) = common.unwrap();
    sizes.sort_by(f64::total_cmp);
    sizes.dedup_by(|a, b| size_um(*a) == size_um(*b));
    inputs["sizes_m"] = json!(sizes);
    let get = |k: &str| inputs.get(k).cloned().unwrap_or(serde_json::Value::Null);
    let scene_name = get("scene_name").as_str().unwrap_or("scene").to_string();
    let out =
        out.unwrap_or_else(|| PathBuf::from("output").join(format!("{scene_name}-montecarlo")));
    check_merge_out(&out, &inputs)?;
    let scene = PathBuf::from(get("scene").as_str().unwrap_or_default());
    let overrides: Vec<String> = serde_json::from_value(get("overrides")).unwrap_or_default();
    let mut merged: [BTreeMap<String, RunRow>; 2] = [BTreeMap::new(), BTreeMap::new()];
    let mut folder_missing = Vec::new();
    let mut notes = Vec::new();
    for (d, (own_sizes, shard, realisations)) in dirs.iter().zip(&mut asked) {
        let (mc, det) = studies(
            &scene,
            &overrides,
            d,
            &inputs,
            1,
            false,
            RunOutputs::Summary,
        );
        // per size (µm): realisations of this folder, and whether its deterministic run is here
        let mut have: BTreeMap<u64, (std::collections::BTreeSet<usize>, bool)> = BTreeMap::new();
        for (k, (study, seed_col)) in [(&mc, 2), (&det, 1)].into_iter().enumerate() {
            for row in study.read_rows()? {
                let entry = have.entry(size_um(tag_f64(&row, 0))).or_default();
                match k {
                    0 => {
                        if let Ok(r) = row.tags[1].parse::<usize>() {
                            entry.0.insert(r);
                        }
                    }
                    _ => entry.1 = true,
                }
                match merged[k].get(&row.label) {
                    Some(old) if old.tags[seed_col] != row.tags[seed_col] => bail!(
                        "run {} appears with seed {} and with seed {} (in {}): the shards do not belong together",
                        row.label,
                        old.tags[seed_col],
                        row.tags[seed_col],
                        d.display()
                    ),
                    Some(_) => {}
                    None => {
                        merged[k].insert(row.label.clone(), row);
                    }
                }
            }
        }
        let n_asked = match realisations {
            Some(n) => *n,
            None => {
                let n = have
                    .values()
                    .filter_map(|h| h.0.iter().next_back())
                    .max()
                    .map_or(0, |r| r + 1);
                notes.push(format!(
                    "{} has no {REQUEST_FILE} (a folder of an older sppm): the realisations it was asked for are taken as {n}, its largest realisation + 1",
                    d.display()
                ));
                *realisations = Some(n);
                n
            }
        };
        let plan = ShardRuns::new(own_sizes, n_asked, *shard);
        let det_sizes = plan.deterministic();
        let what = format!(
            "{} ({}{} realisations of {})",
            d.display(),
            shard.map(|s| format!("shard {s}, ")).unwrap_or_default(),
            n_asked,
            sizes_text(own_sizes)
        );
        for (i, &dm) in own_sizes.iter().enumerate() {
            let (reals, det_here) = have.remove(&size_um(dm)).unwrap_or_default();
            let want = plan.realisations_of(i);
            let got = reals.iter().filter(|&&r| r < n_asked).count() as u128;
            if got < want {
                folder_missing.push(format!(
                    "{what} holds {got} of the {want} realisations of D = {dm} m it was asked for"
                ));
            }
            if det_sizes.contains(&i) && !det_here {
                folder_missing.push(format!("{what} lacks the deterministic run of D = {dm} m"));
            }
        }
    }
    // per size: the realisations the folders asked for (the most any asked), against the
    // distinct realisations there are
    let mut size_missing = Vec::new();
    for &dm in &sizes {
        let um = size_um(dm);
        let want = dirs
            .iter()
            .zip(&asked)
            .filter(|(_, (s, _, _))| s.iter().any(|x| size_um(*x) == um))
            .map(|(_, (_, _, n))| n.unwrap_or(0))
            .max()
            .unwrap_or(0);
        let got = merged[0]
            .values()
            .filter(|r| size_um(tag_f64(r, 0)) == um)
            .filter(|r| r.tags[1].parse::<usize>().is_ok_and(|x| x < want))
            .count();
        if got < want {
            size_missing.push(format!("D = {dm} m: {got} of {want} realisations"));
        }
        if !merged[1].values().any(|r| size_um(tag_f64(r, 0)) == um) {
            size_missing.push(format!("D = {dm} m: no deterministic run"));
        }
    }
    let mut missing = Vec::new();
    if !folder_missing.is_empty() || !size_missing.is_empty() {
        // name the shards that were not given, per study of n shards and its sizes
        // (shard count, sizes in µm) → (sizes, the shard numbers given)
        type Group = (Vec<f64>, std::collections::BTreeSet<usize>);
        let mut groups: BTreeMap<(usize, Vec<u64>), Group> = BTreeMap::new();
        for (s, shard, _) in &asked {
            if let Some(sh) = shard {
                let key = (sh.n, s.iter().map(|d| size_um(*d)).collect());
                groups
                    .entry(key)
                    .or_insert((s.clone(), Default::default()))
                    .1
                    .insert(sh.k);
            }
        }
        for ((n, _), (s, ks)) in groups {
            let absent: Vec<String> = (1..=n)
                .filter(|k| !ks.contains(k))
                .map(|k| format!("{k}/{n}"))
                .collect();
            if !absent.is_empty() {
                missing.push(format!(
                    "shard{} {} of the study of {} not given",
                    if absent.len() == 1 { "" } else { "s" },
                    absent.join(", "),
                    sizes_text(&s)
                ));
            }
        }
        missing.extend(folder_missing);
        missing.extend(size_missing);
    }
    if !missing.is_empty() && !partial {
        bail!(
            "merge: the folders do not hold the whole study: {}. Give the missing shard folders (or finish a shard by running its command again), or add --partial to write the report of the runs there are",
            missing.join("; ")
        );
    }
    let lock = crate::fsio::FolderLock::acquire(&out)?;
    check_merge_out(&out, &inputs)?;
    let [mc_rows, det_rows] = merged.map(|m| m.into_values().collect::<Vec<_>>());
    let (mc, det) = studies(
        &scene,
        &overrides,
        &out,
        &inputs,
        1,
        false,
        RunOutputs::Summary,
    );
    mc.write_rows(&mc_rows)?;
    det.write_rows(&det_rows)?;
    crate::fsio::write_json(&out.join(super::runner::INPUTS_FILE), &inputs)?;
    let per_size = mc_rows
        .iter()
        .fold(BTreeMap::<u64, usize>::new(), |mut m, r| {
            *m.entry(size_um(tag_f64(r, 0))).or_default() += 1;
            m
        });
    let realisations = per_size.values().copied().max().unwrap_or(0);
    let requested = asked.iter().filter_map(|a| a.2).max().unwrap_or(0);
    crate::fsio::write_json(
        &out.join(REQUEST_FILE),
        &json!({
            "realisations": requested,
            "sizes_m": sizes,
            "shard": null,
        }),
    )?;
    let meta = json!({
        "scene": get("scene"),
        "scene_name": scene_name,
        "seed": get("seed"),
        "realisations": realisations,
        "spacing_rule": SPACING_RULE,
        "scene_size_m": get("scene_size_m"),
        "scene_spacing_m": get("scene_spacing_m"),
        "overrides": get("overrides"),
        "merged_from": dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>(),
        "partial": !missing.is_empty(),
        "missing": missing,
    });
    let fewest = per_size.values().copied().min().unwrap_or(0);
    let mut title = if fewest == realisations {
        format!("{scene_name}: size effect, {realisations} realisations")
    } else {
        format!("{scene_name}: size effect, {fewest}–{realisations} realisations per size")
    };
    if !missing.is_empty() {
        title.push_str(" (partial)");
    }
    let effect = report(&out, &mc_rows, &det_rows, meta, &title)?;
    drop(lock);
    let runs = mc_rows.len() + det_rows.len();
    let completed = mc_rows
        .iter()
        .chain(&det_rows)
        .filter(|r| r.completed())
        .count();
    Ok(MergeReport {
        effect,
        missing,
        notes,
        runs,
        completed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_take_letters_and_metres() {
        assert_eq!(
            parse_sizes("F,a,0.2,B").unwrap(),
            vec![0.05, 0.1, 0.2, 1.6],
            "sorted, repeats (B = 0.1) kept once"
        );
        let e = parse_sizes("A,G").unwrap_err().to_string();
        assert!(e.contains("--sizes") && e.contains("`G`"), "{e}");
        assert!(parse_sizes("0.1,-0.2").is_err());
        assert!(parse_sizes(" , ").is_err());
    }

    #[test]
    fn shard_needs_one_le_k_le_n() {
        assert_eq!(parse_shard("2/5").unwrap(), Shard { k: 2, n: 5 });
        for bad in ["0/2", "3/2", "1", "a/2", "1/0", "-1/2"] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert!(e.contains("--shard") && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn seeds_depend_on_study_seed_size_and_realisation_only() {
        let s = realisation_seed(7, 0.1, 3);
        assert_eq!(s, realisation_seed(7, 0.1 + 1e-9, 3), "same µm, same seed");
        assert!(s < 1 << 63, "a TOML integer");
        let mut all = std::collections::HashSet::new();
        for seed in [7, 8] {
            for d in [0.05, 0.1, 0.2] {
                for r in 0..50 {
                    assert!(all.insert(realisation_seed(seed, d, r)));
                }
            }
        }
    }

    /// The runs of a shard by the definition: every index slot·S + size ≡ k − 1 (mod n),
    /// listed slot-major.
    fn shard_items(sizes: usize, realisations: usize, shard: Option<Shard>) -> Vec<Item> {
        let mut out = Vec::new();
        for slot in 0..=realisations {
            for size in 0..sizes {
                let index = slot * sizes + size;
                if shard.is_none_or(|s| index % s.n == s.k - 1) {
                    out.push(Item {
                        size,
                        realisation: slot.checked_sub(1),
                    });
                }
            }
        }
        out
    }

    /// A shard's runs as [`ShardRuns`] makes them: the deterministic runs, then the
    /// realisations in the order they are taken.
    fn planned(sizes: &[f64], realisations: usize, shard: Option<Shard>) -> Vec<Item> {
        let plan = ShardRuns::new(sizes, realisations, shard);
        let mut v: Vec<Item> = plan
            .deterministic()
            .into_iter()
            .map(|size| Item {
                size,
                realisation: None,
            })
            .collect();
        v.extend((0..plan.realisations() as usize).map(|j| plan.realisation(j)));
        v
    }

    #[test]
    fn shard_runs_are_the_definition_largest_size_first() {
        for ns in 1..=6 {
            // sizes ascending as parse_sizes returns them; descending too
            let asc: Vec<f64> = (1..=ns).map(|i| 0.05 * i as f64).collect();
            let desc: Vec<f64> = asc.iter().rev().copied().collect();
            for sizes in [asc, desc] {
                for r in 0..=9 {
                    for n in 1..=8 {
                        for k in 1..=n {
                            let shard = Some(Shard { k, n });
                            let got = planned(&sizes, r, shard);
                            let mut want = shard_items(ns, r, shard);
                            // largest size first, then deterministic, then by realisation
                            want.sort_by(|a, b| {
                                (a.realisation.is_some())
                                    .cmp(&b.realisation.is_some())
                                    .then(sizes[b.size].total_cmp(&sizes[a.size]))
                                    .then(a.realisation.cmp(&b.realisation))
                            });
                            assert_eq!(got, want, "sizes {sizes:?}, N = {r}, shard {k}/{n}");
                        }
                    }
                }
            }
        }
        assert_eq!(planned(&[0.1, 0.2], 3, None).len(), 8);
    }

    #[test]
    fn shard_runs_of_huge_counts_are_counted_not_listed() {
        // 2 sizes × (2^64 − 1 + 1) runs over a million shards: 36 893 488 147 420 or …421
        let plan = ShardRuns::new(&[0.05, 0.1], usize::MAX, Some(Shard { k: 1, n: 1_000_000 }));
        let total = plan.realisations() + plan.deterministic().len() as u128;
        let all = 2 * (usize::MAX as u128 + 1);
        assert_eq!(total, all.div_ceil(1_000_000));
        // the last shard of 7 of 3 sizes × 4 slots = 12 runs: runs 6 (size 0, slot 2) only
        let plan = ShardRuns::new(&[0.05, 0.1, 0.2], 3, Some(Shard { k: 7, n: 7 }));
        assert_eq!(plan.realisations(), 1);
        assert_eq!(
            plan.realisation(0),
            Item {
                size: 0,
                realisation: Some(1)
            }
        );
        // a shard beyond the runs is empty
        let plan = ShardRuns::new(&[0.05], 1, Some(Shard { k: 5, n: 9 }));
        assert_eq!((plan.realisations(), plan.deterministic().len()), (0, 0));
    }

    #[test]
    fn shards_are_disjoint_and_cover_the_runs() {
        let sizes = [0.05, 0.1, 0.2, 0.4, 0.8, 1.6];
        let all = planned(&sizes, 7, None);
        assert_eq!(all.len(), 6 * 8);
        for n in 1..=5 {
            let mut union: Vec<Item> = (1..=n)
                .flat_map(|k| planned(&sizes, 7, Some(Shard { k, n })))
                .collect();
            let len = union.len();
            union.sort();
            union.dedup();
            assert_eq!(union.len(), len, "shards of {n} overlap");
            let mut want = all.clone();
            want.sort();
            assert_eq!(union, want, "shards of {n} do not cover the runs");
        }
        // adding realisations keeps every earlier run in its shard
        let s = Some(Shard { k: 2, n: 3 });
        let small = planned(&sizes, 3, s);
        let large = planned(&sizes, 9, s);
        assert!(small.iter().all(|i| large.contains(i)));
    }

    #[test]
    fn size_variant_follows_the_spacing_rule() {
        let base = Scene::from_file(Path::new("lattices/dogbone_D.toml"), &[]).unwrap();
        let o = size_overrides(&base, 0.1);
        assert_eq!(o[0], "body.size=0.1");
        assert_eq!(o[1], "discretisation.spacing=0.002", "8 mm × 0.1/0.4");
        assert_eq!(
            o[2], "groups.2.load.displacement=0.00025",
            "0.5 mm × √(1/4)"
        );
        let o = size_overrides(&base, 1.6);
        assert_eq!(
            o[1], "discretisation.spacing=0.008",
            "the scene's spacing above D0"
        );
        assert_eq!(o[2], "groups.2.load.displacement=0.001", "0.5 mm × √4");
        assert_eq!(o.len(), 3, "explicit: max_iterations is not set");
        let s = Scene::from_file(Path::new("lattices/dogbone_D.toml"), &o).unwrap();
        assert!(matches!(s.body, BodySpec::Dogbone { size } if size == 1.6));
        let sigma = nominal_strength(&s, 1.0e5);
        assert!((sigma - 1.0e5 / (0.6 * 1.6 * 0.1)).abs() < 1e-6);
        let relax = Scene::from_file(Path::new("lattices/dogbone_montecarlo.toml"), &[]).unwrap();
        let o = size_overrides(&relax, 1.6);
        assert_eq!(o[3], "solver.max_iterations=2000", "500 × 1.6/0.4");
        let o = size_overrides(&relax, 0.05);
        assert_eq!(o[3], "solver.max_iterations=500", "not below the scene's");
    }

    /// 3D: a prism of the dog-bone section scales its section's size (thickness kept) and
    /// its σN is the mean stress over the neck; a box pulled along z reads σN over its section.
    #[test]
    fn size_variant_and_strength_in_3d() {
        let base = Scene::from_file(Path::new("lattices/dogbone_B_3d.toml"), &[]).unwrap();
        let o = size_overrides(&base, 0.2);
        assert_eq!(o[0], "body.section.size=0.2");
        assert_eq!(
            o[1], "discretisation.spacing=0.00625",
            "the scene's above D0"
        );
        let s = Scene::from_file(Path::new("lattices/dogbone_B_3d.toml"), &o).unwrap();
        assert_eq!(dogbone_size(&s.body), Some(0.2));
        let sigma = nominal_strength(&s, 1.0e5);
        assert!((sigma / (1.0e5 / (0.6 * 0.2 * 0.1)) - 1.0).abs() < 1e-12);
        let prism = Scene::from_file(Path::new("lattices/tension_prism_3d.toml"), &[]).unwrap();
        let sigma = nominal_strength(&prism, 1.0e5);
        assert!((sigma / (1.0e5 / (0.15 * 0.15)) - 1.0).abs() < 1e-12);
    }
}
