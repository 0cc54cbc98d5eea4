//! The hexagonal close-packed lattice in a 2D shape (SPLM; docs/model.md §1), with the
//! boundary treatment of `discretisation.surface` (docs/surfaces.md).

use super::plane::{assemble_plane, begin, surface_treatment};
use super::Generator;
use crate::discretise::hex::HexLattice;
use crate::run::model::Model;
use crate::run::RunError;
use crate::scene::{Discretisation, Scene};
use nalgebra::Vector2;

/// The hexagonal lattice: 6 bond slots.
#[derive(Clone, Copy, Debug, Default)]
pub struct Hexagonal;

impl Generator<2, 6> for Hexagonal {
    const KIND: Discretisation = Discretisation::Hexagonal;

    fn model(&self, scene: &Scene, stage: &dyn Fn(&str)) -> Result<Model<6, 2>, RunError> {
        let d = &scene.discretisation;
        let m = &scene.material;
        let shape = begin(scene, stage);
        let lattice = HexLattice {
            spacing: d.spacing,
            rotation_deg: d.rotation_deg.angle(),
            offset: Vector2::from(d.offset2()),
            thickness: m.thickness(),
        };
        let particles = lattice.fill_slots(&shape);
        let method = d.surface();
        assemble_plane(
            scene,
            stage,
            &shape,
            particles,
            method.fits(),
            |particles, dmat, a, b, surface| {
                stage("boundary particles: clipped Voronoi cells and fitted moduli");
                surface_treatment(
                    particles,
                    m.thickness(),
                    &shape,
                    method,
                    dmat,
                    a,
                    b,
                    surface,
                )?;
                Ok(None)
            },
        )
    }
}
