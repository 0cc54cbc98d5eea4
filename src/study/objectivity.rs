//! The objectivity study: the same scene at several lattice rotations, each with the
//! scene's own lattice offset (offset 0) and N random offsets, to measure how much the
//! peak force, the energy and the crack path depend on how the lattice sits in the body
//! (docs/validation.md §B–C: the goal is a peak-force spread of at most 3%).
//!
//! Random offsets are uniform in the lattice cell: offset k ≥ 1 adds u·a1 + v·a2 to the
//! scene's offset, with a1, a2 the rotated lattice vectors and (u, v) uniform in [0, 1)²
//! drawn from `seed` and k alone. The same (u, v) is used at every angle, so that adding an
//! angle or an offset leaves the other runs (and their rows) unchanged.
//!
//! On random particles (SPPM) "offset" k is realisation k: the particle set of seed
//! [`realisation_seed`] (k = 0: the scene's own), turned by each angle against the body
//! (`discretise::random`). objectivity.json reports, per angle, the mean and the coefficient
//! of variation of the peak force and the energy over the realisations, and for each the
//! spread of the per-angle means against what the realisations' scatter alone gives
//! ([`angle_effect`](super::angle_effect): a permutation test's p-value).
//!
//! In 3D (`--axis`) each angle turns the lattice or particle set about one axis
//! (`discretisation.rotation_deg` = [α, β, γ] about z, y and x: [a, 0, 0] about z, [0, a, 0]
//! about y, [0, 0, a] about x); about x or y it turns
//! the loading axis of a prism pulled along z against the particles. The crack-path columns
//! are those of a plane's crack and stay empty in 3D; the crack counts are filled.

use super::angle_effect::{angle_effect, AngleEffect};
use super::crack_path::{
    crack_core, crack_path, mean_axis_deg, Clearance, CrackPath, NoCrack, CLEARANCE_SPACINGS,
};
use super::runner::{RunResult, Study, Variant};
use crate::random_field::splitmix64;
use crate::run::Outcome;
use crate::Scene;
use anyhow::bail;
use nalgebra::Vector2;
use serde::Serialize;
use std::path::PathBuf;

/// The default seed of the random offsets (recorded in the CSV and objectivity.json).
pub const DEFAULT_SEED: u64 = 20_240_401;

/// The study's inputs.
#[derive(Clone, Debug)]
pub struct ObjectivityArgs {
    pub scene: PathBuf,
    pub angles_deg: Vec<f64>,
    /// The axis the angles turn the lattice or particle set about: 'z' (2D, and the default in
    /// 3D), 'x' or 'y' (3D only: turns the loading axis of a prism pulled along z against the
    /// particles).
    pub axis: char,
    /// Random offsets per angle (besides the scene's own offset).
    pub offsets: usize,
    pub seed: u64,
    /// Tensile damage at and above which a particle belongs to the crack path.
    pub crack_damage: f64,
    pub overrides: Vec<String>,
    pub out: Option<PathBuf>,
    pub jobs: usize,
    pub progress: bool,
}

/// The particle-set seed of realisation `k` of a study of random particles: the scene's seed
/// for k = 0, else a SplitMix64 hash of the study seed and k (the same at every angle, so each
/// angle turns the same particle sets).
pub fn realisation_seed(study_seed: u64, scene_seed: u64, k: usize) -> u64 {
    if k == 0 {
        scene_seed
    } else {
        splitmix64(splitmix64(study_seed) ^ k as u64) >> 1
    }
}

/// The fractional position (u, v) in [0, 1)² of random offset `k` (k ≥ 1) for `seed`.
pub fn offset_fraction(seed: u64, k: usize) -> (f64, f64) {
    let a = splitmix64(seed ^ splitmix64(2 * k as u64));
    let b = splitmix64(seed ^ splitmix64(2 * k as u64 + 1));
    let unit = |x: u64| (x >> 11) as f64 / (1u64 << 53) as f64;
    (unit(a), unit(b))
}

/// The offset (m) of offset `k` at `angle_deg` for a lattice of `spacing` whose scene offset is
/// `base`: `base` for k = 0, else base + u·a1 + v·a2.
pub fn lattice_offset(
    seed: u64,
    k: usize,
    angle_deg: f64,
    spacing: f64,
    base: [f64; 2],
) -> [f64; 2] {
    if k == 0 {
        return base;
    }
    let (u, v) = offset_fraction(seed, k);
    let (s, c) = angle_deg.to_radians().sin_cos();
    // a1 = R(θ)(L0, 0), a2 = R(θ)(L0/2, L0·√3/2) (src/discretise/hex.rs)
    let (a1x, a1y) = (spacing * c, spacing * s);
    let (bx, by) = (0.5 * spacing, 0.5 * 3f64.sqrt() * spacing);
    let (a2x, a2y) = (c * bx - s * by, s * bx + c * by);
    [base[0] + u * a1x + v * a2x, base[1] + u * a1y + v * a2y]
}

/// The crack-path columns of the objectivity CSV; the last three are a 3D run's cracks
/// across its load axis ([`super::crack_bands`]): how many cross the section, and the
/// position (share of the body's length along the axis) and coverage of the one that covers
/// most of it.
pub const CRACK_COLUMNS: [&str; 13] = [
    "cracked_particles",
    "crack_particles",
    "crack_axis_deg",
    "crack_rms_width_m",
    "crack_centroid_x_m",
    "crack_centroid_y_m",
    "crack_core_axis_deg",
    "crack_core_rms_width_m",
    "crack_core_centroid_x_m",
    "crack_core_centroid_y_m",
    "cracks_across",
    "crack_across_share",
    "crack_across_coverage",
];

/// The in-plane reference positions of the particles of the groups with prescribed
/// displacements: the supports (fixed components) and the loaded groups.
pub(crate) fn held_points(o: &Outcome) -> Vec<Vector2<f64>> {
    let held: Vec<&str> = o
        .scene
        .groups
        .iter()
        .filter(|g| !g.fix.is_empty() || g.load.is_some())
        .map(|g| g.name.as_str())
        .collect();
    o.groups
        .iter()
        .filter(|g| held.contains(&g.name.as_str()))
        .flat_map(|g| g.members.iter().map(|&i| o.point2(i as usize)))
        .collect()
}

/// The crack path and its core of a 2D run with damage, the particles within
/// [`CLEARANCE_SPACINGS`] spacings of a support or a loaded group left out; `None` in 3D or
/// without damage.
fn crack_lines(o: &Outcome, threshold: f64) -> Option<[Result<CrackPath, NoCrack>; 2]> {
    let d = o.damage.as_ref()?;
    if o.dim == 3 {
        return None;
    }
    let wt: Vec<f64> = d.iter().map(|p| p.wt).collect();
    let x0: Vec<_> = (0..o.x0.len()).map(|i| o.point2(i)).collect();
    let held = held_points(o);
    let clear = Clearance {
        held: &held,
        distance: CLEARANCE_SPACINGS * o.scene.discretisation.spacing,
    };
    Some([
        crack_path(&x0, &wt, threshold, &clear),
        crack_core(&x0, &wt, threshold, &clear),
    ])
}

/// The crack-path columns of a run: the principal line of all cracked particles and of the
/// crack's core ([`super::crack_path`]) away from the supports and loaded groups; NaN (an
/// empty cell) where fewer than two particles are left to fit, and in 3D.
fn crack_metrics(o: &Outcome, threshold: f64) -> Vec<f64> {
    let Some(d) = &o.damage else {
        return [vec![0.0, 0.0], vec![f64::NAN; CRACK_COLUMNS.len() - 2]].concat();
    };
    let count = |t: f64| d.iter().filter(|p| p.wt >= t).count() as f64;
    let mut v = vec![count(super::crack_path::CRACKED), count(threshold)];
    match crack_lines(o, threshold) {
        Some(lines) => {
            for line in lines {
                match line {
                    Ok(p) => {
                        v.extend([p.axis_deg, p.rms_width_m, p.centroid_m[0], p.centroid_m[1]])
                    }
                    Err(_) => v.extend([f64::NAN; 4]),
                }
            }
        }
        None => v.extend([f64::NAN; 8]),
    }
    v.extend(crack_band_metrics(o, threshold));
    v
}

/// A 3D run's cracks across the axis of its probe group's load: how many cross the section,
/// and the share and coverage of the band that covers most of it (NaN where none does); all
/// NaN in 2D, without damage or without a loaded probe.
fn crack_band_metrics(o: &Outcome, threshold: f64) -> [f64; 3] {
    let axis = o.summary.probe_group.as_ref().and_then(|name| {
        let g = o.scene.groups.iter().find(|g| &g.name == name)?;
        Some(g.load.as_ref()?.component.index())
    });
    let (Some(d), Some(axis), 3) = (&o.damage, axis, o.dim) else {
        return [f64::NAN; 3];
    };
    let wt: Vec<f64> = d.iter().map(|p| p.wt).collect();
    let bands = super::crack_bands::crack_bands(
        &o.x0,
        &wt,
        threshold,
        axis,
        o.scene.discretisation.spacing,
    );
    let across = bands.iter().filter(|b| b.crosses()).count() as f64;
    match bands
        .iter()
        .max_by(|a, b| a.coverage.total_cmp(&b.coverage))
    {
        Some(b) if b.crosses() => [across, b.share, b.coverage],
        Some(b) => [across, f64::NAN, b.coverage],
        None => [0.0, f64::NAN, 0.0],
    }
}

/// Why a 2D run's crack path or core has no axis ([`NoCrack`]), for the run's message.
fn crack_note(o: &Outcome, threshold: f64) -> Option<String> {
    let [path, core] = crack_lines(o, threshold)?;
    match (path, core) {
        (Err(e), _) => Some(format!("crack path: {e}")),
        (Ok(_), Err(e)) => Some(format!("crack core: {e}")),
        _ => None,
    }
}

/// A value at its extreme among the runs.
#[derive(Clone, Debug, Serialize)]
pub struct Extreme {
    pub label: String,
    pub value: f64,
}

/// Spread (max − min)/mean of one quantity over the completed runs.
#[derive(Clone, Debug, Serialize)]
pub struct Spread {
    pub runs: usize,
    pub mean: f64,
    pub min: Extreme,
    pub max: Extreme,
    /// (max − min)/mean.
    pub spread: f64,
}

/// (max − min)/mean of `value` over `results` that completed; `None` if none did.
pub fn spread(results: &[RunResult], value: impl Fn(&RunResult) -> f64) -> Option<Spread> {
    let ok: Vec<&RunResult> = results
        .iter()
        .filter(|r| r.row.completed() && value(r).is_finite())
        .collect();
    if ok.is_empty() {
        return None;
    }
    let mean = ok.iter().map(|r| value(r)).sum::<f64>() / ok.len() as f64;
    let lo = ok
        .iter()
        .min_by(|a, b| value(a).total_cmp(&value(b)))
        .unwrap();
    let hi = ok
        .iter()
        .max_by(|a, b| value(a).total_cmp(&value(b)))
        .unwrap();
    Some(Spread {
        runs: ok.len(),
        mean,
        min: Extreme {
            label: lo.row.label.clone(),
            value: value(lo),
        },
        max: Extreme {
            label: hi.row.label.clone(),
            value: value(hi),
        },
        spread: (value(hi) - value(lo)) / mean,
    })
}

/// Per-angle means over the offsets.
#[derive(Clone, Debug, Serialize)]
pub struct AngleSummary {
    pub angle_deg: f64,
    pub runs: usize,
    #[serde(rename = "mean_peak_force_N")]
    pub mean_peak_force_n: f64,
    #[serde(rename = "mean_dissipated_energy_J")]
    pub mean_dissipated_energy_j: f64,
    /// Coefficient of variation (sample) of the peak force and of the energy over the runs.
    pub cov_peak_force: Option<f64>,
    pub cov_dissipated_energy: Option<f64>,
    /// Mean axes over the offsets: the doubled-angle mean ([`mean_axis_deg`]).
    pub mean_crack_axis_deg: Option<f64>,
    pub mean_crack_centroid_x_m: Option<f64>,
    pub mean_crack_core_axis_deg: Option<f64>,
    /// Why `mean_crack_axis_deg` is null: no run at this angle left two damaged particles
    /// away from the supports and loaded groups (their messages say how many there were),
    /// or none completed.
    pub crack_note: Option<String>,
}

/// objectivity.json.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectivityReport {
    pub scene: String,
    pub scene_file: String,
    pub overrides: Vec<String>,
    pub angles_deg: Vec<f64>,
    pub random_offsets_per_angle: usize,
    pub seed: u64,
    /// Tensile damage at and above which a particle belongs to the crack path.
    pub crack_damage: f64,
    pub runs: usize,
    pub completed: usize,
    pub peak_force: Option<Spread>,
    pub dissipated_energy: Option<Spread>,
    pub per_angle: Vec<AngleSummary>,
    /// Whether the per-angle means of the peak force and of the energy differ by more than
    /// the scatter of the runs at each angle gives (`None` with fewer than two angles of two
    /// completed runs).
    pub peak_force_angle_effect: Option<AngleEffect>,
    pub dissipated_energy_angle_effect: Option<AngleEffect>,
    pub rows: Vec<super::runner::RunRow>,
    pub dir: PathBuf,
}

/// The middle of a specimen's length along its load axis where a crack across it is away
/// from the platens: the middle 60% (a test that breaks nearer a platen is discarded).
pub const MIDDLE_SHARE: (f64, f64) = (0.2, 0.8);

impl ObjectivityReport {
    /// A 3D study's cracks across the load axis, one line: of the completed runs, how many
    /// broke with exactly one crack across the section in the middle 60% of the length
    /// ([`MIDDLE_SHARE`]), how many with two or more, and each run's crack positions; `None`
    /// where no run has the columns (2D).
    pub fn crack_band_line(&self) -> Option<String> {
        let col = |name: &str| CRACK_COLUMNS.iter().position(|c| *c == name).unwrap();
        let (n, share) = (col("cracks_across"), col("crack_across_share"));
        let rows: Vec<_> = self
            .rows
            .iter()
            .filter(|r| r.completed() && r.metrics.get(n).is_some_and(|x| x.is_finite()))
            .collect();
        if rows.is_empty() {
            return None;
        }
        let middle = |x: f64| (MIDDLE_SHARE.0..=MIDDLE_SHARE.1).contains(&x);
        let one = rows
            .iter()
            .filter(|r| r.metrics[n] == 1.0 && middle(r.metrics[share]))
            .count();
        let more = rows.iter().filter(|r| r.metrics[n] >= 2.0).count();
        let none = rows.iter().filter(|r| r.metrics[n] == 0.0).count();
        let each: Vec<String> = rows
            .iter()
            .map(|r| format!("{} {}×{:.2}", r.label, r.metrics[n], r.metrics[share]))
            .collect();
        // A crack along the load axis (a split cylinder's) crosses no section normal to it.
        let along = if none > 0 {
            " (a crack along the load axis, as a split cylinder's, is not counted)"
        } else {
            ""
        };
        Some(format!(
            "cracks across the load axis: {one} of {} runs with one crack in the middle 60% of the length, {more} with two or more, {none} with none{along} (run, cracks × position of the widest): {}",
            rows.len(),
            each.join(", ")
        ))
    }

    /// The per-angle means' spreads against the realisations' scatter, one line (where the
    /// study has at least two angles of two completed runs).
    pub fn angle_effect_line(&self) -> Option<String> {
        let (p, e) = (
            self.peak_force_angle_effect.as_ref()?,
            self.dissipated_energy_angle_effect.as_ref()?,
        );
        Some(format!(
            "per-angle means spread: peak force {:.2}% (from the scatter alone {:.2}%, p = {:.3}), energy {:.2}% ({:.2}%, p = {:.3})",
            100.0 * p.spread_of_means,
            100.0 * p.expected_spread_without_angle_effect,
            p.p_value,
            100.0 * e.spread_of_means,
            100.0 * e.expected_spread_without_angle_effect,
            e.p_value
        ))
    }

    /// One line per angle: the mean crack axis and that of the core, or why there is none.
    pub fn crack_summary_lines(&self) -> Vec<String> {
        let deg = |a: Option<f64>| a.map_or("none".to_string(), |a| format!("{a:.1}°"));
        self.per_angle
            .iter()
            .map(|a| match &a.crack_note {
                Some(note) => format!("θ = {}°: {note}", a.angle_deg),
                None => format!(
                    "θ = {}°: crack axis {} (core {}) over {} runs, away from the supports and loading points",
                    a.angle_deg,
                    deg(a.mean_crack_axis_deg),
                    deg(a.mean_crack_core_axis_deg),
                    a.runs
                ),
            })
            .collect()
    }

    /// The one line the CLI prints.
    pub fn spread_line(&self) -> String {
        match &self.peak_force {
            Some(s) => format!(
                "peak force spread (max − min)/mean = {:.2}% over {} runs (min {:.4e} N at {}, max {:.4e} N at {})",
                100.0 * s.spread,
                s.runs,
                s.min.value,
                s.min.label,
                s.max.value,
                s.max.label
            ),
            None => format!(
                "peak force spread (max − min)/mean: undefined, none of the {} runs completed",
                self.runs
            ),
        }
    }
}

/// The label of angle `a`, offset `k`: "a15_o0".
pub fn label(angle_deg: f64, k: usize) -> String {
    format!("a{angle_deg}_o{k}")
}

/// Run (or resume) the study and write objectivity.csv, objectivity.json and
/// force_displacement_overlay.svg into the study folder.
pub fn objectivity(args: &ObjectivityArgs) -> anyhow::Result<ObjectivityReport> {
    check_options(args)?;
    let base = Scene::from_file(&args.scene, &args.overrides)?;
    let d = &base.discretisation;
    let three = base.dim() == 3;
    let axis = rotation_axis(args.axis, three)?;
    if three && !d.is_random() && args.offsets > 0 {
        bail!(
            "--offsets {}: 0 for the FCC lattice (random offsets of a 3D lattice are not drawn yet; use lattice = \"random\" for realisations)",
            args.offsets
        );
    }
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("output").join(format!("{}-objectivity", base.name())));
    // runs: angle-major, offset 0 (the scene's own) then the random ones; made when taken
    let per_angle_runs = args.offsets as u128 + 1;
    let count = args.angles_deg.len() as u128 * per_angle_runs;
    let make = variants(args, &base, three, axis);
    let threshold = args.crack_damage;
    let metrics = move |o: &Outcome| crack_metrics(o, threshold);
    let notes = move |o: &Outcome| crack_note(o, threshold);
    let study = Study {
        scene: args.scene.clone(),
        base_overrides: args.overrides.clone(),
        dir: dir.clone(),
        csv_name: "objectivity.csv".into(),
        tag_columns: vec!["angle_deg".into(), "offset".into(), "seed".into()],
        metric_columns: CRACK_COLUMNS.iter().map(|s| s.to_string()).collect(),
        metrics: &metrics,
        notes: Some(&notes),
        inputs: serde_json::json!({
            "study": "objectivity",
            "scene_file": args.scene.display().to_string(),
            "overrides": args.overrides,
            "seed": args.seed,
            "axis": args.axis.to_string(),
            "crack_damage": args.crack_damage,
        }),
        jobs: args.jobs,
        progress: args.progress,
        outputs: super::runner::RunOutputs::All,
    };
    crate::limits::check_count_of(
        &format!(
            "--angles {} and --offsets {}: {count} runs ({} angle{} × ({} random offsets + the scene's own))",
            args.angles_deg
                .iter()
                .map(|a| a.to_string())
                .collect::<Vec<_>>()
                .join(","),
            args.offsets,
            args.angles_deg.len(),
            if args.angles_deg.len() == 1 { "" } else { "s" },
            args.offsets
        ),
        count as f64,
        study.bytes_per_run(&base),
        "runs",
        "fewer --offsets or --angles",
    )?;
    let runs = super::runner::Runs {
        count: count as usize,
        variant: &make,
        // the scene's own offset at each angle
        probes: (0..args.angles_deg.len())
            .map(|i| i * per_angle_runs as usize)
            .collect(),
    };
    study.check(&runs)?;
    let lock = crate::fsio::FolderLock::acquire(&dir)?;
    let results = study.run(&lock, &runs)?;

    let title = format!(
        "{}: force–displacement at every lattice rotation and offset",
        base.name()
    );
    crate::fsio::write_with(
        &dir.join("force_displacement_overlay.svg"),
        |tmp: &std::path::Path| {
            super::plots::overlay(
                &title,
                &results,
                &|r| format!("θ = {}°, offset {}", r.row.tags[0], r.row.tags[1]),
                tmp,
            )
        },
    )?;
    let report = report(args, &base, dir, &results);
    crate::fsio::write_json(&report.dir.join("objectivity.json"), &report)?;
    drop(lock);
    Ok(report)
}

/// The options that need no scene: distinct finite angles, jobs and the crack threshold.
fn check_options(args: &ObjectivityArgs) -> anyhow::Result<()> {
    if args.angles_deg.is_empty() {
        bail!("--angles: give at least one angle in degrees, e.g. --angles 0,15,30,45");
    }
    if let Some(a) = args.angles_deg.iter().find(|a| !a.is_finite()) {
        bail!("--angles: {a} is not an angle in degrees");
    }
    for (i, a) in args.angles_deg.iter().enumerate() {
        if args.angles_deg[..i].contains(a) {
            bail!("--angles: {a} appears twice");
        }
    }
    if args.jobs == 0 {
        bail!("--jobs 0: at least 1");
    }
    if !(args.crack_damage > 0.0 && args.crack_damage <= 1.0) {
        bail!(
            "--crack-damage {}: a tensile damage w_t with 0 < w_t <= 1",
            args.crack_damage
        );
    }
    Ok(())
}

/// The index of `--axis` in rotation_deg = [α, β, γ], the angles about z, y and x (only z in
/// 2D).
fn rotation_axis(axis: char, three: bool) -> anyhow::Result<usize> {
    Ok(match (axis, three) {
        ('z', _) => 0,
        ('y', true) => 1,
        ('x', true) => 2,
        (a, true) => bail!("--axis {a}: x, y or z"),
        (a, false) => {
            bail!("--axis {a}: z (or absent) for a 2D scene, whose lattice turns in its plane")
        }
    })
}

/// The rotation override of angle `a`: one angle in 2D, three in 3D (the angle about `axis`).
fn rotation_override(a: f64, three: bool, axis: usize) -> String {
    if three {
        let mut r = [0.0; 3];
        r[axis] = a;
        format!(
            "discretisation.rotation_deg=[{:?}, {:?}, {:?}]",
            r[0], r[1], r[2]
        )
    } else {
        format!("discretisation.rotation_deg={a:?}")
    }
}

/// Run `j` of the study (angle-major, offset 0 the scene's own then the random ones), made
/// when it is taken. On random particles "offset" k is realisation k, a particle set of its
/// own seed (k = 0: the scene's seed), turned by the angle.
fn variants<'a>(
    args: &'a ObjectivityArgs,
    base: &Scene,
    three: bool,
    axis: usize,
) -> impl Fn(usize) -> Variant + Sync + 'a {
    let d = &base.discretisation;
    let per_angle_runs = args.offsets as u128 + 1;
    let spacing = d.spacing;
    let scene_offset = d.offset2();
    let random = d.is_random();
    let scene_seed = crate::discretise::random::RandomParticles::of_scene(base).seed;
    move |j: usize| {
        let (i, k) = (j as u128 / per_angle_runs, j as u128 % per_angle_runs);
        let (a, k) = (args.angles_deg[i as usize], k as usize);
        let rotation = rotation_override(a, three, axis);
        if random {
            let seed = realisation_seed(args.seed, scene_seed, k);
            return Variant {
                label: label(a, k),
                overrides: vec![rotation, format!("seed={seed}")],
                tags: vec![a.to_string(), k.to_string(), seed.to_string()],
            };
        }
        let off = lattice_offset(args.seed, k, a, spacing, scene_offset);
        Variant {
            label: label(a, k),
            overrides: vec![
                rotation,
                format!("discretisation.offset=[{:?}, {:?}]", off[0], off[1]),
            ],
            tags: vec![a.to_string(), k.to_string(), args.seed.to_string()],
        }
    }
}

/// objectivity.json of the study's results: the spreads, the per-angle means and the
/// angle effect.
fn report(
    args: &ObjectivityArgs,
    base: &Scene,
    dir: PathBuf,
    results: &[RunResult],
) -> ObjectivityReport {
    // the completed runs of each angle, in the order of `angles_deg`
    let by_angle: Vec<Vec<&RunResult>> = args
        .angles_deg
        .iter()
        .map(|&a| {
            results
                .iter()
                .filter(|r| r.row.completed() && r.row.rotation_deg == a)
                .collect()
        })
        .collect();
    let groups = |value: fn(&RunResult) -> f64| -> Vec<Vec<f64>> {
        by_angle
            .iter()
            .map(|rs| {
                rs.iter()
                    .map(|r| value(r))
                    .filter(|v| v.is_finite())
                    .collect()
            })
            .collect()
    };
    let peak_force_angle_effect = angle_effect(&groups(|r| r.row.peak_force_n), args.seed);
    let dissipated_energy_angle_effect =
        angle_effect(&groups(|r| r.row.dissipated_energy_j), args.seed);
    ObjectivityReport {
        scene: base.name().to_string(),
        scene_file: args.scene.display().to_string(),
        overrides: args.overrides.clone(),
        angles_deg: args.angles_deg.clone(),
        random_offsets_per_angle: args.offsets,
        seed: args.seed,
        crack_damage: args.crack_damage,
        runs: results.len(),
        completed: results.iter().filter(|r| r.row.completed()).count(),
        peak_force: spread(results, |r| r.row.peak_force_n),
        dissipated_energy: spread(results, |r| r.row.dissipated_energy_j),
        per_angle: per_angle(&args.angles_deg, &by_angle, base.dim() == 3),
        peak_force_angle_effect,
        dissipated_energy_angle_effect,
        rows: results.iter().map(|r| r.row.clone()).collect(),
        dir,
    }
}

/// The per-angle means over the offsets of the completed runs of each angle (`by_angle`, in
/// the order of `angles`).
fn per_angle(angles: &[f64], by_angle: &[Vec<&RunResult>], three_d: bool) -> Vec<AngleSummary> {
    let metric = |r: &RunResult, name: &str| {
        let i = CRACK_COLUMNS.iter().position(|c| *c == name).unwrap();
        r.row.metrics[i]
    };
    let mean_of = |v: Vec<f64>| {
        let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let cov_of = |v: Vec<f64>| {
        let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
        (v.len() >= 2).then(|| super::size_effect::sample(&v).cov)
    };
    let axis_of = |rs: &[&RunResult], name: &str| {
        mean_axis_deg(
            &rs.iter()
                .map(|r| metric(r, name))
                .filter(|a| a.is_finite())
                .collect::<Vec<_>>(),
        )
    };
    angles
        .iter()
        .zip(by_angle)
        .map(|(&a, rs)| AngleSummary {
            angle_deg: a,
            runs: rs.len(),
            mean_peak_force_n: mean_of(rs.iter().map(|r| r.row.peak_force_n).collect())
                .unwrap_or(f64::NAN),
            mean_dissipated_energy_j: mean_of(
                rs.iter().map(|r| r.row.dissipated_energy_j).collect(),
            )
            .unwrap_or(f64::NAN),
            cov_peak_force: cov_of(rs.iter().map(|r| r.row.peak_force_n).collect()),
            cov_dissipated_energy: cov_of(rs.iter().map(|r| r.row.dissipated_energy_j).collect()),
            mean_crack_axis_deg: axis_of(rs, "crack_axis_deg"),
            mean_crack_centroid_x_m: mean_of(
                rs.iter().map(|r| metric(r, "crack_centroid_x_m")).collect(),
            ),
            mean_crack_core_axis_deg: axis_of(rs, "crack_core_axis_deg"),
            crack_note: crack_note_of(rs, axis_of(rs, "crack_axis_deg").is_some(), three_d, |r| {
                metric(r, "crack_axis_deg")
            }),
        })
        .collect()
}

/// [`AngleSummary::crack_note`] of the completed runs `rs` of an angle. A 3D study fits no
/// in-plane crack axis: its cracks are counted across the load axis
/// ([`ObjectivityReport::crack_band_line`]).
fn crack_note_of(
    rs: &[&RunResult],
    has_mean: bool,
    three_d: bool,
    axis: impl Fn(&RunResult) -> f64,
) -> Option<String> {
    let measured = rs.iter().filter(|r| axis(r).is_finite()).count();
    match (has_mean, rs.len(), measured) {
        (true, _, _) => None,
        (false, 0, _) => Some("no crack: no run completed at this angle".into()),
        (false, n, _) if three_d => Some(format!(
            "{n} completed 3D runs: no in-plane crack axis is fitted in 3D; the cracks across \
             the load axis are counted below"
        )),
        (false, n, 0) => Some(format!(
            "no crack in the {n} completed runs: fewer than 2 damaged particles away from the \
             supports and loading points"
        )),
        (false, _, m) => Some(format!(
            "the crack axes of the {m} runs with a crack cancel: no mean direction"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::runner::RunRow;

    #[test]
    fn offsets_lie_in_the_rotated_cell_and_depend_on_seed_and_index_only() {
        let l0 = 0.01;
        for k in 1..50 {
            let (u, v) = offset_fraction(7, k);
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
            for angle in [0.0, 30.0, 45.0] {
                let o = lattice_offset(7, k, angle, l0, [0.0, 0.0]);
                // back to lattice coordinates: rotate by −θ, then solve with a1, a2
                let (s, c) = (-angle.to_radians()).sin_cos();
                let (x, y) = (c * o[0] - s * o[1], s * o[0] + c * o[1]);
                let vv = y / (0.5 * 3f64.sqrt() * l0);
                let uu = (x - 0.5 * l0 * vv) / l0;
                assert!((uu - u).abs() < 1e-12 && (vv - v).abs() < 1e-12);
            }
        }
        assert_eq!(lattice_offset(7, 0, 30.0, l0, [1e-3, 2e-3]), [1e-3, 2e-3]);
        assert_ne!(offset_fraction(7, 1), offset_fraction(8, 1));
        assert_ne!(offset_fraction(7, 1), offset_fraction(7, 2));
        // the draws fill the cell: mean near 1/2
        let mean_u = (1..=2000).map(|k| offset_fraction(1, k).0).sum::<f64>() / 2000.0;
        assert!((mean_u - 0.5).abs() < 0.03, "{mean_u}");
    }
    fn run(axis_deg: f64) -> RunResult {
        let mut metrics = vec![f64::NAN; CRACK_COLUMNS.len()];
        metrics[2] = axis_deg;
        RunResult {
            row: RunRow {
                label: "a0_o0".into(),
                tags: vec![],
                spacing_m: 0.01,
                rotation_deg: 0.0,
                offset_m: [0.0; 2],
                particles: 100,
                peak_force_n: 1.0,
                displacement_at_peak_m: 1e-4,
                dissipated_energy_j: 1.0,
                wall_time_s: 1.0,
                total_time_s: 1.0,
                status: "completed".into(),
                metrics,
                message: String::new(),
            },
            curve: vec![],
        }
    }

    #[test]
    fn a_3d_angle_says_its_cracks_are_counted_across_the_load_axis_not_that_it_has_none() {
        let (a, b) = (run(f64::NAN), run(f64::NAN));
        let rs = [&a, &b];
        let axis = |r: &RunResult| r.row.metrics[2];
        let note3 = crack_note_of(&rs, false, true, axis).unwrap();
        assert!(note3.contains("2 completed 3D runs") && note3.contains("across the load axis"));
        let note2 = crack_note_of(&rs, false, false, axis).unwrap();
        assert!(note2.starts_with("no crack in the 2 completed runs") && !note2.contains("3D"));
        let c = run(90.0);
        assert_eq!(crack_note_of(&[&c], true, false, axis), None);
        assert!(crack_note_of(&[], false, true, axis)
            .unwrap()
            .contains("no run completed"));
    }
}
