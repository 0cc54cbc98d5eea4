//! What the 3D generators share: random fields refused (they are sampled in the plane), and
//! the groups, supports and mechanics of a solid body with its micro-moduli set.

use crate::discretise::{groups, Particles};
use crate::model::dimension::MicroModuli;
use crate::run::model::{supports, Model, RandomBody, SurfaceCorrection};
use crate::run::RunError;
use crate::scene::Scene;

/// Random fields are sampled in the plane: a 3D scene refuses them.
pub(super) fn refuse_fields(scene: &Scene) -> Result<(), RunError> {
    if scene.random_field.is_empty() {
        return Ok(());
    }
    Err(RunError::Scene(crate::scene::SceneError::Invalid {
        key: "random_field".into(),
        value: format!("{} random fields", scene.random_field.len()),
        allowed: "absent in 3D for now (the fields are sampled in the plane)".into(),
    }))
}

/// The groups, supports and mechanics of a 3D body with its micro-moduli set.
pub(super) fn assemble_solid<const K: usize>(
    scene: &Scene,
    particles: Particles<3, K>,
    bulk: MicroModuli,
    surface: SurfaceCorrection,
    random: Option<RandomBody>,
) -> Result<Model<K, 3>, RunError> {
    let solid = scene.solid().ok_or_else(|| {
        RunError::Setup(format!(
            "discretisation.lattice = \"{}\" in 3D needs a solid body (box, cylinder or prism)",
            scene.discretisation.lattice.name()
        ))
    })?;
    let section = scene.section_along_z();
    let (lo, hi) = solid.bounding_box();
    let extent = format!(
        "x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m, z ∈ [{:.6}, {:.6}] m",
        lo.x, hi.x, lo.y, hi.y, lo.z, hi.z
    );
    let supported = supports(
        scene,
        &particles,
        &|sel| groups::select_3d(sel, &particles, &solid, section.as_ref()),
        &extent,
    )?;
    Ok(Model::new(
        scene,
        particles,
        supported,
        bulk,
        surface,
        Vec::new(),
        random,
    ))
}
