//! The assembled elastic model of a scene, whatever its discretisation: the body's particles,
//! groups, supports and micro-moduli ([`Model`]), what the boundary treatment did, and the
//! size checks made before anything is allocated.

use super::RunError;
use crate::discretise::random::Generation;
use crate::discretise::{bytes_per_particle, groups, Particles};
use crate::limits::available_memory;
use crate::material::properties::SampledField;
use crate::model::micro_modulus::MicroModuli;
use crate::scene::Scene;
use crate::solver::loading::Prescribed;
use crate::solver::mechanics::Mechanics;
use nalgebra::Vector2;
use serde::Serialize;

/// How the lattice's boundary particles were weighted (`discretisation.surface`; docs/model.md §1,
/// §3): their count, the fits, and the body's volume against the particles'.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceCorrection {
    /// `discretisation.surface` ("voronoi_fit", "voronoi", "lattice", "lattice_fit";
    /// "voronoi_fit" for random particles, which fit every particle).
    pub method: &'static str,
    /// Whether boundary particles got fitted micro-moduli.
    pub enabled: bool,
    /// Particles with fewer than six bonds or a clipped cell.
    pub boundary_particles: usize,
    /// Boundary particles given fitted constants.
    pub corrected: usize,
    /// Boundary particles whose bonds cannot carry a fit (kept at bulk constants, scaled by
    /// their volume fraction under a "voronoi" method).
    pub kept_bulk: usize,
    /// Largest ‖a·A + b·B − D‖/‖D‖ among the corrected particles.
    pub max_residual: f64,
    /// The body's volume (area × thickness, m³) and the particles' total ΔV.
    pub body_volume: f64,
    pub particle_volume: f64,
}

/// What a random body (SPPM) adds to the model: its Voronoi cells, what generation
/// measured, and how well each particle's fitted micro-moduli reproduce D.
#[derive(Clone, Debug)]
pub struct RandomBody {
    /// Each particle's Voronoi cell clipped to the body (counter-clockwise polygon, m).
    pub cells: Vec<Vec<Vector2<f64>>>,
    pub generation: Generation,
    pub moduli: ModuliFit,
}

/// The per-particle least-squares micro-moduli of a random body (docs/model.md §3, (3.20)).
#[derive(Clone, Debug, Serialize)]
pub struct ModuliFit {
    /// ‖a_i·A_i + b_i·B_i − D‖/‖D‖ of each particle (NaN where no fit exists).
    #[serde(skip)]
    pub residual: Vec<f64>,
    pub residual_mean: f64,
    pub residual_p99: f64,
    pub residual_max: f64,
    /// Particles whose bonds cannot carry a fit (too few, or too nearly collinear, or a fit
    /// with a ≤ 0): they keep the hexagonal lattice's constants at their own length.
    pub unfitted: usize,
}

/// The assembled elastic model of a scene, before any dynamics (T1, dampers, time step), in
/// `K` bond slots (6: the hexagonal lattice; [`random::SLOTS_2D`]: random particles).
pub struct Model<const K: usize = 6, const D: usize = 2> {
    pub scene: Scene,
    pub particles: Particles<D, K>,
    pub groups: Vec<groups::Group>,
    pub prescribed: Vec<Prescribed>,
    pub constrained: Vec<[bool; D]>,
    pub mech: Mechanics<D, K>,
    pub bulk: MicroModuli,
    pub surface: SurfaceCorrection,
    /// The scene's random fields sampled at the particles (docs/model.md §12).
    pub fields: Vec<SampledField>,
    /// Random particles only: cells, generation, fitted moduli.
    pub random: Option<RandomBody>,
}

/// A body's groups, which components its supports hold, and its prescribed displacements
/// ([`supports`]).
pub(crate) type Supports<const D: usize> = (Vec<groups::Group>, Vec<[bool; D]>, Vec<Prescribed>);

impl<const K: usize, const D: usize> Model<K, D> {
    /// The model of a body whose volumes and micro-moduli are set: its mechanics at the
    /// scene's density.
    pub(crate) fn new(
        scene: &Scene,
        particles: Particles<D, K>,
        (groups, constrained, prescribed): Supports<D>,
        bulk: MicroModuli,
        surface: SurfaceCorrection,
        fields: Vec<SampledField>,
        random: Option<RandomBody>,
    ) -> Self {
        let mech = Mechanics::new(&particles, &vec![scene.material.rho; particles.len()]);
        Model {
            scene: scene.clone(),
            particles,
            groups,
            prescribed,
            constrained,
            mech,
            bulk,
            surface,
            fields,
            random,
        }
    }
}

/// Particles the body will hold (area / cell area; in 3D volume / cell volume), known
/// before anything is allocated.
pub fn estimated_particles(scene: &Scene) -> f64 {
    let l0 = scene.discretisation.spacing;
    if scene.discretisation.lattice == crate::scene::Lattice::Cubic {
        return match scene.solid() {
            Some(solid) => solid.volume() / l0.powi(3),
            None => scene.shape().area() / (l0 * l0),
        };
    }
    if let Some(solid) = scene.solid() {
        return solid.volume() / crate::discretise::fcc::cell_volume(l0);
    }
    scene.shape().area() / (0.5 * 3f64.sqrt() * l0 * l0)
}

/// Estimated bytes a run of the scene allocates in `slots` bond slots (2D or 3D; with
/// `[concrete]`, the damage kernel's too; with `output.snapshots`, the frames).
pub fn memory_in_slots(scene: &Scene, slots: usize) -> f64 {
    model_memory(scene, slots) + frames_memory(scene)
}

/// Estimated bytes of the model's arrays in `slots` bond slots (with `[concrete]`, the damage
/// kernel's too).
fn model_memory(scene: &Scene, slots: usize) -> f64 {
    let dim = scene.dim();
    if scene.model.is_bond_based() {
        // the families' candidates and arrays while the body is built (the peak: 53 bytes a
        // bond at 10^6 points, benchmarks/RESULTS.md "Bond-based kernel against LAMMPS"),
        // with the bonds of a whole family: the ball of radius m cells
        let m = scene.model.horizon();
        let bonds = if dim == 3 {
            4.0 / 3.0 * std::f64::consts::PI * m.powi(3)
        } else {
            std::f64::consts::PI * m * m
        };
        let point = bytes_per_particle(dim, slots) as f64 + 12.0 * 8.0 * dim as f64;
        return estimated_particles(scene) * (bonds * BOND_BUILD_BYTES + point);
    }
    let damage = if scene.concrete.is_some() {
        crate::solver::inelastic::bytes_per_particle(dim, slots)
    } else {
        0
    };
    estimated_particles(scene) * (bytes_per_particle(dim, slots) + damage) as f64
}

/// Bytes a bond-based body takes per bond (each held by both its points) while it is built.
pub const BOND_BUILD_BYTES: f64 = 56.0;

/// Estimated bytes of the frames of `output.snapshots` (0 without).
pub fn frames_memory(scene: &Scene) -> f64 {
    let frames = scene.output.snapshots.unwrap_or(0) as f64;
    frames * estimated_particles(scene) * FRAME_BYTES_PER_PARTICLE as f64
}

/// Bytes one frame of a time series (`run::snapshots`) holds per particle: displacement
/// (3), stress (6) and the two damages (2), f64 each.
pub const FRAME_BYTES_PER_PARTICLE: usize = (3 + 6 + 2) * 8;

/// Refuse a scene whose body, or its frames (`output.snapshots`), would not fit this machine's
/// memory (80% of what is available) or that has more particles than a run can index, before anything is allocated; `slots`
/// are the bond slots of its discretisation.
pub(crate) fn check_size(scene: &Scene, slots: usize) -> Result<(), RunError> {
    let d = &scene.discretisation;
    let need = model_memory(scene, slots);
    if let Some(avail) = available_memory() {
        let frames = frames_memory(scene);
        if need <= 0.8 * avail as f64 && need + frames > 0.8 * avail as f64 {
            let n = scene.output.snapshots.unwrap_or(0);
            let fit = ((0.8 * avail as f64 - need) / (frames / n as f64)).floor();
            return Err(RunError::Setup(format!(
                "output.snapshots = {n}: {n} frames of about {:.3e} particles need about {:.1} GiB besides the model's {:.1} GiB, more than this machine has available ({:.1} GiB); at most {fit:.0} frames fit",
                estimated_particles(scene),
                frames / 2f64.powi(30),
                need / 2f64.powi(30),
                avail as f64 / 2f64.powi(30)
            )));
        }
        if need > 0.8 * avail as f64 {
            return Err(RunError::Setup(format!(
                "discretisation.spacing = {}: the body would hold about {:.3e} particles needing about {:.1} GiB, more than this machine has available ({:.1} GiB); use a larger spacing",
                d.spacing,
                estimated_particles(scene),
                need / 2f64.powi(30),
                avail as f64 / 2f64.powi(30)
            )));
        }
    }
    if estimated_particles(scene) > u32::MAX as f64 / 2.0 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: about {:.3e} particles, more than the 2.1e9 a run can index",
            d.spacing,
            estimated_particles(scene)
        )));
    }
    Ok(())
}

/// The error of a ν outside the range random particles' elastic calibration covers
/// (`allowed` names the range).
pub(crate) fn nu_outside_calibration(nu: f64, allowed: String) -> RunError {
    RunError::Scene(crate::scene::SceneError::Invalid {
        key: "material.nu".into(),
        value: nu.to_string(),
        allowed,
    })
}

/// The scene's groups on a body, its supports (`constrained`) and its prescribed
/// displacements; `select` picks a selection's members, `extent` describes the body for the
/// message of a selection that picks nothing.
pub(crate) fn supports<const D: usize, const K: usize>(
    scene: &Scene,
    particles: &Particles<D, K>,
    select: &dyn Fn(&crate::scene::Selection) -> Vec<u32>,
    extent: &str,
) -> Result<Supports<D>, RunError> {
    let n = particles.len();
    let mut groups = Vec::new();
    let mut constrained = vec![[false; D]; n];
    let mut amplitude: Vec<[Option<(f64, String)>; D]> = vec![std::array::from_fn(|_| None); n];
    for g in &scene.groups {
        let members = select(&g.select);
        if members.is_empty() {
            return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                key: format!("groups.{}.select", g.name),
                value: g.select.scene_text(),
                allowed: format!(
                    "a selection that contains at least one particle; the body spans {extent}"
                ),
            }));
        }
        let mut entries: Vec<(usize, f64)> = g.fix.iter().map(|a| (a.index(), 0.0)).collect();
        if let Some(l) = g.load.as_ref().filter(|l| l.force.is_none()) {
            entries.push((l.component.index(), l.delta()));
        }
        for &i in &members {
            for &(c, amp) in &entries {
                let slot = &mut amplitude[i as usize][c];
                match slot {
                    Some((prev, other)) if *prev != amp => {
                        return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                            key: format!("groups.{}", g.name),
                            value: format!("particle {i} at {:?}", particles.x0[i as usize].as_slice()),
                            allowed: format!(
                                "groups that overlap must prescribe the same displacement: groups.{other} already prescribes {prev} m in component {c}, this group {amp} m"
                            ),
                        }))
                    }
                    _ => *slot = Some((amp, g.name.clone())),
                }
                constrained[i as usize][c] = true;
            }
        }
        groups.push(groups::Group {
            name: g.name.clone(),
            members,
        });
    }
    forces_on_free_components(scene, &groups, &constrained)?;
    let prescribed: Vec<Prescribed> = (0..n)
        .flat_map(|i| {
            let a = amplitude[i].clone();
            (0..D).filter_map(move |c| {
                a[c].as_ref().map(|(amp, _)| Prescribed {
                    particle: i as u32,
                    component: c as u8,
                    amplitude: *amp,
                })
            })
        })
        .collect();
    Ok((groups, constrained, prescribed))
}

/// Refuses a force-controlled load on a component that another group holds or moves.
fn forces_on_free_components<const D: usize>(
    scene: &Scene,
    groups: &[groups::Group],
    constrained: &[[bool; D]],
) -> Result<(), RunError> {
    for (g, spec) in groups.iter().zip(&scene.groups) {
        let Some(l) = spec.load.as_ref().filter(|l| l.force.is_some()) else {
            continue;
        };
        let c = l.component.index();
        if let Some(&i) = g.members.iter().find(|&&i| constrained[i as usize][c]) {
            return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                key: format!("groups.{}.load.force", g.name),
                value: format!("{}", l.force.unwrap()),
                allowed: format!(
                    "a force on components no other group fixes or displaces: particle {i} of this group has its {} component held by another group",
                    ["x", "y", "z"][c]
                ),
            }));
        }
    }
    Ok(())
}
