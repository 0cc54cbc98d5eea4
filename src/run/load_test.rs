//! A force-controlled load test (docs/failure.md): the forces the scene's `load.force` groups
//! apply, the `[failure]` criterion that watches them, and its verdict in summary.json.

use super::RunError;
use crate::discretise::groups::Group;
use crate::scene::failure::Criterion;
use crate::scene::{Scene, SceneError};
use crate::solver::failure::{Decision, FailureWatch, Tolerances, Verdict};
use crate::solver::loading::{shared_by_volume, AppliedForce};
use serde::Serialize;

/// Every force-controlled group's force, shared among its members by volume.
pub fn applied_forces(scene: &Scene, groups: &[Group], volume: &[f64]) -> Vec<AppliedForce> {
    let mut out = Vec::new();
    for (spec, g) in scene.groups.iter().zip(groups) {
        if let Some((l, p)) = spec.load.as_ref().and_then(|l| l.force.map(|p| (l, p))) {
            out.extend(shared_by_volume(&g.members, volume, l.component.index(), p));
        }
    }
    out
}

/// The criterion of `[failure]`, with S* and F* from the ramp's steps; `None` without it.
pub fn watch(scene: &Scene, t_end: f64, dt: f64) -> Option<FailureWatch> {
    let ramp_steps = (scene.loading.ramp_fraction * t_end / dt).ceil() as usize;
    scene
        .failure
        .as_ref()
        .map(|f| FailureWatch::new(Tolerances::of(f, ramp_steps, scene.body_size())))
}

/// Refuses a `[failure]` criterion that cannot reach a verdict of "holds" within the run:
/// S* steps of stable damage (`bond_damage`) counted from the start must end before t_end.
pub fn check_judgeable(scene: &Scene, t_end: f64, dt: f64) -> Result<(), RunError> {
    let Some(w) = watch(scene, t_end, dt) else {
        return Ok(());
    };
    let steps = (t_end / dt).ceil() as usize;
    let t = w.tolerances;
    if t.criterion == Criterion::BondDamage && t.stable_steps >= steps {
        let set = scene.failure.as_ref().and_then(|f| f.stable_steps);
        return Err(RunError::Scene(SceneError::Invalid {
            key: if set.is_some() { "failure.stable_steps" } else { "loading.ramp_fraction" }.into(),
            value: match set {
                Some(s) => s.to_string(),
                None => scene.loading.ramp_fraction.to_string(),
            },
            allowed: format!(
                "a run that can judge the load: S* = {} steps of stable damage ({}) do not end before t_end ({steps} steps); shorten the ramp (Ness (2019) ramps over a tenth of the run or less), lengthen the run (loading.end_periods) or set failure.stable_steps",
                t.stable_steps,
                if set.is_some() { "failure.stable_steps" } else { "twice the ramp's steps" }
            ),
        }));
    }
    Ok(())
}

/// One force-controlled group's load.
#[derive(Clone, Debug, Serialize)]
pub struct GroupLoad {
    pub group: String,
    #[serde(rename = "force_N")]
    pub force_n: f64,
}

/// summary.json `load_test`: the loads, the criterion with its tolerances and its verdict.
#[derive(Clone, Debug, Serialize)]
pub struct LoadTestReport {
    pub loads: Vec<GroupLoad>,
    pub criterion: &'static str,
    /// "holds" or "fails".
    pub verdict: Verdict,
    pub decided_at_step: usize,
    pub decided_at_s: f64,
    pub reason: String,
    pub velocity_tolerance_m_per_s: Option<f64>,
    pub force_tolerance: f64,
    pub damage_tolerance: f64,
    pub stable_steps: usize,
    pub failing_steps: usize,
    pub check_every: usize,
}

impl LoadTestReport {
    /// The report of a run that ended at `end_step` with the criterion's `decision`, or
    /// without one (then the load was not held, [`FailureWatch::at_end`]).
    pub fn of(
        scene: &Scene,
        watch: &FailureWatch,
        decision: Option<Decision>,
        end_step: usize,
        dt: f64,
    ) -> Self {
        let decision = decision.unwrap_or_else(|| watch.at_end(end_step));
        let t = watch.tolerances;
        LoadTestReport {
            loads: scene
                .groups
                .iter()
                .filter_map(|g| {
                    let p = g.load.as_ref()?.force?;
                    Some(GroupLoad {
                        group: g.name.clone(),
                        force_n: p,
                    })
                })
                .collect(),
            criterion: t.criterion.name(),
            verdict: decision.verdict,
            decided_at_step: decision.step,
            decided_at_s: decision.step as f64 * dt,
            reason: decision.reason,
            velocity_tolerance_m_per_s: t.speed.is_finite().then_some(t.speed),
            force_tolerance: t.out_of_balance,
            damage_tolerance: t.damage,
            stable_steps: t.stable_steps,
            failing_steps: t.failing_steps,
            check_every: t.check_every,
        }
    }
}
