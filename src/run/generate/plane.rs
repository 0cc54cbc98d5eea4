//! What the 2D generators share: the body's shape, groups and supports, the bulk constants
//! of each particle's own spacing, the random fields, and the lattice's boundary treatment.

use crate::discretise::{groups, voronoi, Particles};
use crate::geometry::Shape2;
use crate::material::properties;
use crate::model::micro_modulus::{self, MicroModuli};
use crate::run::model::{estimated_particles, supports, Model, RandomBody, SurfaceCorrection};
use crate::run::RunError;
use crate::scene::{Scene, Surface};
use nalgebra::{Matrix3, Vector2};

/// The scene's 2D shape, having told `stage` that the body is being filled.
pub(super) fn begin(scene: &Scene, stage: &dyn Fn(&str)) -> Shape2 {
    let shape = scene.shape();
    stage(&format!(
        "filling the body with about {:.3e} particles",
        estimated_particles(scene)
    ));
    shape
}

/// The model of a 2D body filled with `particles`: groups and supports, the bulk constants
/// (4.5), (4.6) of each particle's own spacing, then `treat` (the discretisation's boundary
/// treatment or least-squares fit, into the volumes and the constants `a`, `b`; it returns
/// what a random body adds), then the random fields (docs/model.md §12). `fitted`: whether
/// the treatment fits micro-moduli (the summary's `surface_correction.enabled`).
pub(super) fn assemble_plane<const K: usize>(
    scene: &Scene,
    stage: &dyn Fn(&str),
    shape: &Shape2,
    particles: Particles<2, K>,
    fitted: bool,
    treat: impl FnOnce(
        &mut Particles<2, K>,
        &Matrix3<f64>,
        &mut [f64],
        &mut [f64],
        &mut SurfaceCorrection,
    ) -> Result<Option<RandomBody>, RunError>,
) -> Result<Model<K>, RunError> {
    let d = &scene.discretisation;
    let m = &scene.material;
    if particles.len() < 2 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: the body holds {} bonded particles at this spacing, rotation and offset; at least 2 are needed (use a smaller spacing)",
            d.spacing,
            particles.len()
        )));
    }

    // Groups, supports and loading.
    let n = particles.len();
    let (body_lo, body_hi) = shape.bounding_box();
    let extent = format!(
        "x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m",
        body_lo.x, body_hi.x, body_lo.y, body_hi.y
    );
    let (groups, constrained, prescribed) = supports(
        scene,
        &particles,
        &|sel| groups::select(sel, &particles, shape),
        &extent,
    )?;

    // Micro-moduli, with the surface treatment of particles that miss bonds.
    stage("micro-moduli and the surface correction");
    let mut particles = particles;
    // Bulk constants (4.5), (4.6) of each particle's own spacing; reported at the nominal one.
    let bulk = micro_modulus::hexagonal(
        m.youngs_modulus(),
        m.nu,
        d.spacing,
        m.thickness(),
        m.plane(),
    );
    let dmat = micro_modulus::elasticity_matrix(m.youngs_modulus(), m.nu, m.plane());
    let own: Vec<MicroModuli> = (0..n)
        .map(|i| {
            micro_modulus::hexagonal(
                m.youngs_modulus(),
                m.nu,
                particles.length[i],
                m.thickness(),
                m.plane(),
            )
        })
        .collect();
    let mut a: Vec<f64> = own.iter().map(|mm| mm.a).collect();
    let mut b: Vec<f64> = own.iter().map(|mm| mm.b).collect();
    let mut surface = SurfaceCorrection {
        method: d.surface().name(),
        enabled: fitted,
        boundary_particles: 0,
        corrected: 0,
        kept_bulk: 0,
        max_residual: 0.0,
        body_volume: shape.area() * m.thickness(),
        particle_volume: 0.0,
    };
    let random = treat(&mut particles, &dmat, &mut a, &mut b, &mut surface)?;
    if !scene.random_field.is_empty() {
        stage("random fields");
    }
    // Random fields (docs/model.md §12), over the body's box: E scales the micro-moduli here, the
    // concrete values go to the damage kernel (`build_simulation`).
    // The box is widened by a margin that does not depend on the spacing (particles may sit
    // on the outline within the lattice fill's tolerance, 1e-9·size).
    let pad = Vector2::repeat(1e-6 * shape.size().max(1.0));
    let fields = properties::sample(scene, body_lo - pad, body_hi + pad, &particles.x0)?;
    properties::check_strengths(scene, &fields)?;
    if let Some(f) = properties::stiffness_factors(&fields, m.youngs_modulus()) {
        for i in 0..n {
            a[i] *= f[i];
            b[i] *= f[i];
        }
    }
    surface.particle_volume = particles.volume.iter().sum();
    particles.a = a;
    particles.b = b;
    Ok(Model::new(
        scene,
        particles,
        (groups, constrained, prescribed),
        bulk,
        surface,
        fields,
        random,
    ))
}

/// The boundary treatment of a lattice body (`discretisation.surface`, docs/model.md §1, §3) into
/// `particles.volume` and the micro-moduli `a`, `b` (which hold each particle's bulk
/// constants on entry).
///
/// - `voronoi_fit`, `voronoi`: each particle's volume is its Voronoi cell clipped to the body
///   (`discretise::voronoi`), so the particles carry the body's mass at any rotation and
///   offset. A particle with all six bonds and an unclipped cell keeps the lattice cell
///   (bit for bit). Any other particle gets, under `voronoi_fit`, the least-squares (a, b) of
///   its own bonds and clipped volume against D (3.20), which for a particle with six bonds
///   is exactly the bulk constants times its volume fraction; under `voronoi` (and where a
///   fit does not exist) the bulk constants times its volume fraction.
/// - `lattice`: the source's full cells and bulk constants.
/// - `lattice_fit`: full cells; particles missing bonds get the least-squares fit.
#[allow(clippy::too_many_arguments)]
pub(super) fn surface_treatment<const K: usize>(
    particles: &mut Particles<2, K>,
    thickness: f64,
    shape: &crate::geometry::Shape2,
    method: Surface,
    dmat: &nalgebra::Matrix3<f64>,
    a: &mut [f64],
    b: &mut [f64],
    report: &mut SurfaceCorrection,
) -> Result<(), RunError> {
    let n = particles.len();
    let clipped = match method {
        Surface::VoronoiFit | Surface::Voronoi => Some(
            voronoi::clipped_cells(&particles.x0, shape).map_err(|e| {
                RunError::Setup(format!(
                    "discretisation.surface = \"{}\": the clipped Voronoi cells of the lattice failed: {e}",
                    method.name()
                ))
            })?,
        ),
        Surface::Lattice | Surface::LatticeFit => None,
    };
    for i in 0..n {
        let cell = particles.volume[i];
        let full_bonds = particles.bond_count(i) == 6;
        let volume = match &clipped {
            Some(c) => {
                let v = c[i].1 * thickness;
                if full_bonds && (v - cell).abs() <= 1e-12 * cell {
                    cell
                } else {
                    v
                }
            }
            None => cell,
        };
        if full_bonds && volume == cell {
            continue;
        }
        report.boundary_particles += 1;
        let volume = quantised(volume, cell, 28);
        particles.volume[i] = volume;
        let fraction = volume / cell;
        let fit = match method {
            Surface::VoronoiFit | Surface::LatticeFit => {
                micro_modulus::fit(&particles.reference_bonds(i), volume, dmat)
            }
            Surface::Voronoi | Surface::Lattice => None,
        };
        match fit {
            Some(f) => {
                let scale = a[i];
                a[i] = quantised(f.moduli.a, scale, 20);
                b[i] = quantised(f.moduli.b, scale, 20);
                report.corrected += 1;
                report.max_residual = report.max_residual.max(f.residual);
            }
            None => {
                a[i] *= fraction;
                b[i] *= fraction;
                if report.enabled {
                    report.kept_bulk += 1;
                }
            }
        }
    }
    Ok(())
}

/// `value` rounded to a multiple of 2⁻ᵇⁱᵗˢ·|scale|.
///
/// The clipped cells and the fits of two particles that are mirror images of each other come
/// out equal only to round-off (6e-14 relative for the volumes on the split cylinder, more
/// for b, a small difference of large terms), because their cells and bonds are visited in
/// a different order; a crack then grows from that difference and a symmetric specimen
/// cracks asymmetrically. Rounding to a grid far coarser than the round-off and far finer
/// than anything physical makes the pairs equal bit for bit: volumes to 2⁻²⁸ of the cell
/// (3.7e-9; the body's mass stays exact to 1e-9), a and b to 2⁻²⁰ of the bulk a (9.5e-7 of
/// a, 2.4e-5 of b).
fn quantised(value: f64, scale: f64, bits: i32) -> f64 {
    let q = scale.abs() * 2f64.powi(-bits);
    (value / q).round() * q
}
