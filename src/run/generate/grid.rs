//! The regular grid of the bond-based family (docs/bond_based.md, "Families"): points at the
//! centres of the cubic cells of side Δx = `discretisation.spacing` that fall in the body
//! (square cells in a 2D shape), each the volume of its cell. The grid carries no lattice
//! bonds (0 slots): the bond-based body finds its families within the horizon
//! (`model::bond_based::body`).

use super::solid::{assemble_solid, refuse_fields};
use super::Generator;
use crate::discretise::{groups, Particles};
use crate::model::dimension::MicroModuli;
use crate::run::model::{estimated_particles, supports, Model, SurfaceCorrection};
use crate::run::RunError;
use crate::scene::{Discretisation, Scene};
use nalgebra::{SVector, Vector2, Vector3};

/// The cubic grid in a solid.
#[derive(Clone, Copy, Debug, Default)]
pub struct CubicGrid;

/// The square grid in a 2D shape.
#[derive(Clone, Copy, Debug, Default)]
pub struct SquareGrid;

/// What the grid reports as its boundary treatment: the bond-based body corrects its own
/// surfaces (`model.surface_correction`), so the particles are the full cells.
fn surface_report(body_volume: f64, particle_volume: f64) -> SurfaceCorrection {
    SurfaceCorrection {
        method: "grid",
        enabled: false,
        boundary_particles: 0,
        corrected: 0,
        kept_bulk: 0,
        max_residual: 0.0,
        body_volume,
        particle_volume,
    }
}

/// The cell centres lo + offset + (i + ½)·Δx along each axis of the box [lo, hi] that `keep`
/// accepts.
fn cell_centres<const D: usize>(
    lo: [f64; D],
    hi: [f64; D],
    dx: f64,
    offset: [f64; D],
    keep: impl Fn(&SVector<f64, D>) -> bool,
) -> Vec<SVector<f64, D>> {
    let n: [i64; D] = std::array::from_fn(|k| ((hi[k] - lo[k]) / dx).ceil() as i64 + 1);
    let total: i64 = n.iter().product();
    (0..total)
        .filter_map(|mut flat| {
            let p = SVector::<f64, D>::from_fn(|k, _| {
                let i = flat % n[k];
                flat /= n[k];
                lo[k] + offset[k] + (i as f64 + 0.5) * dx
            });
            keep(&p).then_some(p)
        })
        .collect()
}

fn too_few(scene: &Scene, n: usize) -> RunError {
    RunError::Setup(format!(
        "discretisation.spacing = {}: the body holds {n} grid points at this spacing and offset; at least 2 are needed (use a smaller spacing)",
        scene.discretisation.spacing
    ))
}

impl Generator<3, 0> for CubicGrid {
    const KIND: Discretisation = Discretisation::CubicGrid;

    fn model(&self, scene: &Scene, stage: &dyn Fn(&str)) -> Result<Model<0, 3>, RunError> {
        refuse_fields(scene)?;
        stage(&format!(
            "filling the body with about {:.3e} grid points",
            estimated_particles(scene)
        ));
        let solid = scene.solid().ok_or_else(|| {
            RunError::Setup("discretisation.lattice = \"cubic\" in 3D needs a solid body".into())
        })?;
        let dx = scene.discretisation.spacing;
        let (lo, hi) = solid.bounding_box();
        let [ox, oy, oz] = scene.discretisation.offset3();
        let x0 = cell_centres::<3>(lo.into(), hi.into(), dx, [ox, oy, oz], |p| {
            solid.contains(&Vector3::new(p[0], p[1], p[2]), 0.0)
        });
        if x0.len() < 2 {
            return Err(too_few(scene, x0.len()));
        }
        let cell = dx.powi(3);
        let volume = vec![cell; x0.len()];
        let report = surface_report(solid.volume(), cell * x0.len() as f64);
        let particles = grid_particles(x0, volume, dx);
        assemble_solid(
            scene,
            particles,
            MicroModuli { a: 0.0, b: 0.0 },
            report,
            None,
        )
    }
}

impl Generator<2, 0> for SquareGrid {
    const KIND: Discretisation = Discretisation::SquareGrid;

    fn model(&self, scene: &Scene, stage: &dyn Fn(&str)) -> Result<Model<0, 2>, RunError> {
        if !scene.random_field.is_empty() {
            return Err(RunError::Setup(
                "random_field: absent with model.family = \"bond_based\"".into(),
            ));
        }
        stage(&format!(
            "filling the body with about {:.3e} grid points",
            estimated_particles(scene)
        ));
        let shape = scene.shape();
        let dx = scene.discretisation.spacing;
        let (lo, hi) = shape.bounding_box();
        let x0 = cell_centres::<2>(
            lo.into(),
            hi.into(),
            dx,
            scene.discretisation.offset2(),
            |p| shape.contains(&Vector2::new(p[0], p[1]), 0.0),
        );
        if x0.len() < 2 {
            return Err(too_few(scene, x0.len()));
        }
        let cell = dx * dx * scene.material.thickness();
        let volume = vec![cell; x0.len()];
        let report = surface_report(
            shape.area() * scene.material.thickness(),
            cell * x0.len() as f64,
        );
        let particles = grid_particles(x0, volume, dx);
        let (lo, hi) = shape.bounding_box();
        let extent = format!(
            "x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m",
            lo.x, hi.x, lo.y, hi.y
        );
        let supported = supports(
            scene,
            &particles,
            &|sel| groups::select(sel, &particles, &shape),
            &extent,
        )?;
        Ok(Model::new(
            scene,
            particles,
            supported,
            MicroModuli { a: 0.0, b: 0.0 },
            report,
            Vec::new(),
            None,
        ))
    }
}

/// Grid points without lattice bonds, at spacing Δx.
fn grid_particles<const D: usize>(
    x0: Vec<SVector<f64, D>>,
    volume: Vec<f64>,
    dx: f64,
) -> Particles<D, 0> {
    let n = x0.len();
    Particles::new(x0, volume, vec![[]; n], vec![[]; n], vec![[]; n], dx)
}
