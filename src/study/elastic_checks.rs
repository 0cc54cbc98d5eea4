//! Elastic stiffness of simple members against theory, solved statically (small strain):
//! a cantilever against Timoshenko's tip stiffness and a plate in uniaxial tension against E.
//! They measure how a discretisation's boundary particles carry stiffness
//! (`discretisation.surface`; tests/suite/surfaces.rs, benchmarks/surfaces.rs).

use crate::run::{prepare_model, Hexagonal, Model, RunError};
use crate::scene::Scene;
use crate::solver::linear::LinearOperator;
use crate::solver::modal::{static_force_response, static_response};
use nalgebra::{Matrix3, Vector2, Vector3};

/// E, ν, thickness of the checks (plane stress).
pub const E: f64 = 30e9;
pub const NU: f64 = 0.2;
pub const THICKNESS: f64 = 0.05;

/// A lattice's placement and boundary treatment.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub spacing: f64,
    pub rotation_deg: f64,
    pub offset: [f64; 2],
    /// `discretisation.surface` ("voronoi_fit", "voronoi", "lattice", "lattice_fit").
    pub surface: &'static str,
}

fn discretisation(p: &Placement) -> String {
    format!(
        "[discretisation]\nspacing = {}\nrotation_deg = {}\noffset = [{}, {}]\nsurface = \"{}\"\n",
        p.spacing, p.rotation_deg, p.offset[0], p.offset[1], p.surface
    )
}

fn material() -> String {
    format!(
        "[material]\nE = {E}\nnu = {NU}\nrho = 2400.0\nthickness = {THICKNESS}\nplane = \"stress\"\n"
    )
}

/// A cantilever of depth h and free length `length` along x (y ∈ [0, h]), clamped (x and y
/// held) over the three spacings x ∈ [−3·L0, 0] behind its root.
pub fn cantilever_scene(h: f64, length: f64, p: &Placement) -> Result<Scene, RunError> {
    let c = 3.0 * p.spacing;
    let text = format!(
        "name = \"cantilever\"\n[body]\nshape = \"rectangle\"\nwidth = {}\nheight = {h}\norigin = [{}, 0.0]\n{}{}[[groups]]\nname = \"root\"\nselect = {{ by = \"box\", min = [{}, -1.0], max = [0.0, {}] }}\nfix = [\"x\", \"y\"]\n",
        length + c,
        -c,
        discretisation(p),
        material(),
        -c - 1.0,
        h + 1.0
    );
    Ok(Scene::from_toml_str(&text, &[])?)
}

/// The cantilever's tip stiffness / Timoshenko's: a tip load P spread over the particles
/// within one spacing of the free end in proportion to their volume, the tip deflection the
/// load-weighted mean (work-conjugate) deflection, and Timoshenko's δ = P·L³/(3EI) +
/// P·L/(κGA) (κ = 5/6) with L the load's centroid. Returns (ratio, model).
pub fn cantilever_stiffness(h: f64, length: f64, p: &Placement) -> Result<(f64, Model), RunError> {
    let model = prepare_model(&cantilever_scene(h, length, p)?, Hexagonal)?;
    let x0 = &model.particles.x0;
    let tip = TipLoad::new(x0, &model.particles.volume, length, p.spacing);
    let mut f = vec![Vector2::zeros(); x0.len()];
    for &(i, share) in &tip.shares {
        f[i].y = share;
    }
    let u = static_force_response(&model.mech, x0, &model.constrained, &f)?;
    let delta = tip.deflection(|i| u[i].y);
    let theory = tip.timoshenko(THICKNESS * h.powi(3) / 12.0, THICKNESS * h);
    Ok((theory / delta, model))
}

/// A cantilever's tip load: [`TipLoad::LOAD`] spread over the particles within one spacing
/// of the free end x = `length` in proportion to their volume.
struct TipLoad {
    /// (particle, its share of the load in N).
    shares: Vec<(usize, f64)>,
    /// The load's centroid along x (m): the lever arm from the root at x = 0.
    arm: f64,
}

impl TipLoad {
    const LOAD: f64 = 1000.0;

    fn new<const D: usize>(
        x0: &[nalgebra::SVector<f64, D>],
        volume: &[f64],
        length: f64,
        spacing: f64,
    ) -> TipLoad {
        let tip: Vec<usize> = (0..x0.len())
            .filter(|&i| x0[i][0] >= length - 1.01 * spacing)
            .collect();
        let vt: f64 = tip.iter().map(|&i| volume[i]).sum();
        TipLoad {
            shares: tip
                .iter()
                .map(|&i| (i, Self::LOAD * volume[i] / vt))
                .collect(),
            arm: tip.iter().map(|&i| x0[i][0] * volume[i]).sum::<f64>() / vt,
        }
    }

    /// The load-weighted (work-conjugate) mean of the deflection `u` along the load.
    fn deflection(&self, u: impl Fn(usize) -> f64) -> f64 {
        self.shares.iter().map(|&(i, f)| u(i) * f).sum::<f64>() / Self::LOAD
    }

    /// Timoshenko's tip deflection P·a³/(3EI) + P·a/(κGA), κ = 5/6, of a section with second
    /// moment `inertia` and area `area`.
    fn timoshenko(&self, inertia: f64, area: f64) -> f64 {
        let (load, arm) = (Self::LOAD, self.arm);
        let shear = E / (2.0 * (1.0 + NU));
        load * arm.powi(3) / (3.0 * E * inertia) + load * arm / (5.0 / 6.0 * shear * area)
    }
}

/// A plate `width` × `height` (y ∈ [0, height]) held in y over its two bottom rows, its
/// bottom-centre particle held in x, its two top rows pulled 1e-4·height in y.
pub fn plate_scene(width: f64, height: f64, p: &Placement) -> Result<Scene, RunError> {
    let text = format!(
        "name = \"plate\"\n[body]\nshape = \"rectangle\"\nwidth = {width}\nheight = {height}\n{}{}[[groups]]\nname = \"bottom\"\nselect = {{ by = \"edge\", edge = \"bottom\", rows = 2 }}\nfix = [\"y\"]\n[[groups]]\nname = \"anchor\"\nselect = {{ by = \"nearest\", point = [{}, 0.0] }}\nfix = [\"x\"]\n[[groups]]\nname = \"top\"\nselect = {{ by = \"edge\", edge = \"top\", rows = 2 }}\nload = {{ component = \"y\", displacement = {} }}\n[loading]\nend_periods = 4.0\n",
        discretisation(p),
        material(),
        0.5 * width,
        1e-4 * height
    );
    Ok(Scene::from_toml_str(&text, &[])?)
}

/// (E/E_input, ν/ν_input) of a plate in uniaxial tension as an engineer measures them:
/// σ = F/(W·t) from the reaction of the pulled rows, the strains from an affine fit of the
/// displacements over the middle half of the plate.
pub fn plate_modulus(width: f64, height: f64, p: &Placement) -> Result<(f64, f64), RunError> {
    let model = prepare_model(&plate_scene(width, height, p)?, Hexagonal)?;
    let (u, force) = pulled(&model)?;
    let x0 = &model.particles.x0;
    // affine fit u ≈ G·x + c over the middle half
    let (cx, cy) = (0.5 * width, 0.5 * height);
    let mut ata = Matrix3::zeros();
    let mut atb = [Vector3::zeros(), Vector3::zeros()];
    for (x, ui) in x0.iter().zip(&u) {
        if (x.x - cx).abs() <= 0.25 * width && (x.y - cy).abs() <= 0.25 * height {
            let row = Vector3::new(x.x, x.y, 1.0);
            ata += row * row.transpose();
            atb[0] += row * ui.x;
            atb[1] += row * ui.y;
        }
    }
    let inv = ata.try_inverse().expect("the middle half holds particles");
    let (exx, eyy) = ((inv * atb[0])[0], (inv * atb[1])[1]);
    let sigma = force / (width * THICKNESS);
    Ok((sigma / eyy / E, -exx / eyy / NU))
}

/// The static displacements of a model at its full prescribed displacements, and the
/// reaction (along y) of its group "top".
fn pulled(model: &Model) -> Result<(Vec<Vector2<f64>>, f64), RunError> {
    let n = model.particles.len();
    let mut ubar = vec![Vector2::zeros(); n];
    for pr in &model.prescribed {
        ubar[pr.particle as usize][pr.component as usize] = pr.amplitude;
    }
    let x0 = &model.particles.x0;
    let u = static_response(&model.mech, x0, &model.constrained, &ubar)?;
    let mut f = vec![Vector2::zeros(); n];
    LinearOperator::new(&model.mech, x0).internal_forces(&u, &mut f);
    let top = model
        .groups
        .iter()
        .find(|g| g.name == "top")
        .expect("group");
    let force = -top.members.iter().map(|&i| f[i as usize].y).sum::<f64>();
    Ok((u, force))
}

/// A square plate of side `width` with a central circular hole of radius `radius`, held and
/// pulled like [`plate_scene`] (uniaxial tension along y, 1e-4 strain).
pub fn hole_plate_scene(width: f64, radius: f64, p: &Placement) -> Result<Scene, RunError> {
    let text = format!(
        "name = \"plate_with_hole\"\n[body]\nshape = \"rectangle\"\nwidth = {width}\nheight = {width}\n[[cutouts]]\nshape = \"disc\"\ncentre = [{c}, {c}]\ndiameter = {d}\n{}{}[[groups]]\nname = \"bottom\"\nselect = {{ by = \"edge\", edge = \"bottom\", rows = 2 }}\nfix = [\"y\"]\n[[groups]]\nname = \"anchor\"\nselect = {{ by = \"nearest\", point = [{c}, 0.0] }}\nfix = [\"x\"]\n[[groups]]\nname = \"top\"\nselect = {{ by = \"edge\", edge = \"top\", rows = 2 }}\nload = {{ component = \"y\", displacement = {u} }}\n[loading]\nend_periods = 4.0\n",
        discretisation(p),
        material(),
        c = 0.5 * width,
        d = 2.0 * radius,
        u = 1e-4 * width
    );
    Ok(Scene::from_toml_str(&text, &[])?)
}

/// What the plate with a hole shows in the recovered stress (`run::stress_recovery`), all
/// divided by the remote stress σ = F/(W·t).
#[derive(Clone, Copy, Debug)]
pub struct HoleStress {
    /// σyy of the particles nearest the hole's two sides (x = centre ± R, on the hole's
    /// axis), their mean: Kirsch's 3, Howland's 3.03 at 2R/W = 0.1.
    pub hoop: f64,
    /// The largest |σ·n·n| (normal stress on the hole's edge, n radial) among the particles
    /// whose Voronoi cell meets the hole.
    pub max_normal: f64,
    /// The largest |σ_rθ| among them.
    pub max_shear: f64,
}

/// Solve the plate with a hole statically and read [`HoleStress`].
pub fn hole_stress(width: f64, radius: f64, p: &Placement) -> Result<HoleStress, RunError> {
    use crate::run::stress_recovery::elastic_stress;
    let model = prepare_model(&hole_plate_scene(width, radius, p)?, Hexagonal)?;
    let n = model.particles.len();
    let (u, force) = pulled(&model)?;
    let remote = force / (width * THICKNESS);
    let x0 = &model.particles.x0;
    let x: Vec<Vector2<f64>> = x0.iter().zip(&u).map(|(a, b)| a + b).collect();
    let sigma = elastic_stress(&model, &x);
    let c = Vector2::new(0.5 * width, 0.5 * width);
    let nearest = |q: Vector2<f64>| {
        (0..n)
            .min_by(|&a, &b| (x0[a] - q).norm().total_cmp(&(x0[b] - q).norm()))
            .expect("particles")
    };
    let sides = [
        nearest(c + Vector2::new(radius, 0.0)),
        nearest(c - Vector2::new(radius, 0.0)),
    ];
    let hoop = sides.iter().map(|&i| sigma[i][(1, 1)]).sum::<f64>() / 2.0 / remote;
    // particles whose cell meets the hole: within a spacing of its edge
    let (mut max_normal, mut max_shear) = (0.0f64, 0.0f64);
    for i in 0..n {
        let r = x0[i] - c;
        if r.norm() > radius + p.spacing {
            continue;
        }
        let nr = r.normalize();
        let t = Vector2::new(-nr.y, nr.x);
        max_normal = max_normal.max((nr.dot(&(sigma[i] * nr)) / remote).abs());
        max_shear = max_shear.max((t.dot(&(sigma[i] * nr)) / remote).abs());
    }
    Ok(HoleStress {
        hoop,
        max_normal,
        max_shear,
    })
}

/// (E/E_input, ν/ν_input) of an FCC block W × W × H (H along z; W = `width`) in uniaxial
/// tension, measured as on a testing machine: the particles within 1.5·L0 of the bottom
/// face held in z, those within 1.5·L0 of the top face pulled 1e-4·H in z, the side faces
/// free; σ = F/W² from the reaction of the pulled particles, ε_zz and the lateral strains
/// (mean of ε_xx and ε_yy) from an affine fit of the displacements over the middle half of
/// the block. `surface` as `discretisation.surface` of a 3D scene
/// (`run::generate::fcc_surface_treatment`: "voronoi_fit" clips the cells to the box).
pub fn fcc_block_modulus(
    width: f64,
    height: f64,
    lattice: &crate::discretise::fcc::FccLattice,
    surface: crate::scene::Surface,
) -> Result<(f64, f64), RunError> {
    use crate::geometry::Shape3;
    use crate::run::generate::fcc_surface_treatment as surface_treatment;
    let shape = Shape3::Box {
        origin: Vector3::zeros(),
        size: Vector3::new(width, width, height),
    };
    let mut p = lattice.fill(&shape);
    surface_treatment(&mut p, &shape, surface, E, NU);
    block_moduli(&p, width, height, 1.5 * lattice.spacing)
}

/// [`fcc_block_modulus`] for random particles in 3D (SPPM, `discretise::random3`): the block
/// W × W × H of `recipe`'s particles with each particle's least-squares (a_i, b_i) fitted to
/// the isotropic D of (E0·`e_fit`, `nu_fit`) (3.20), held and pulled over the rows within
/// 1.5·L0 of its ends; returns (E/E0, ν/ν0) of the body.
pub fn random_block_modulus(
    width: f64,
    height: f64,
    recipe: &crate::discretise::random3::RandomSolid,
    e_fit: f64,
    nu_fit: f64,
) -> Result<(f64, f64), RunError> {
    use crate::geometry::Shape3;
    let shape = Shape3::Box {
        origin: Vector3::zeros(),
        size: Vector3::new(width, width, height),
    };
    let p = fitted_random_solid(&shape, recipe, E * e_fit, nu_fit)?;
    block_moduli(&p, width, height, 1.5 * recipe.spacing)
}

/// `recipe`'s random particles in `shape`, each with its least-squares (a_i, b_i) fitted to
/// the isotropic D of (e, nu) (3.20); `Err` when a particle has no fit.
fn fitted_random_solid(
    shape: &crate::geometry::Shape3,
    recipe: &crate::discretise::random3::RandomSolid,
    e: f64,
    nu: f64,
) -> Result<crate::discretise::Particles<3, { crate::discretise::random3::SLOTS_3D }>, RunError> {
    use crate::discretise::random3::{self, SLOTS_3D};
    use crate::model::dimension::{Dim, Dimension};
    let (mut p, _) = random3::fill::<SLOTS_3D>(shape, recipe).map_err(RunError::Setup)?;
    let d = <Dim<3> as Dimension<3>>::elasticity(e, nu, crate::scene::Plane::Stress);
    let (mut a, mut b) = (vec![0.0; p.len()], vec![0.0; p.len()]);
    let fit = crate::run::generate::moduli::fit_moduli_3d(&p, &d, &mut a, &mut b);
    if fit.unfitted > 0 {
        return Err(RunError::Setup(format!(
            "{} random particles have no moduli fit",
            fit.unfitted
        )));
    }
    (p.a, p.b) = (a, b);
    Ok(p)
}

/// The box of a 3D prism cantilever: square section h × h (y, z ∈ [0, h]), free length
/// `length` along x, and 3·L0 behind the root (x ∈ [−3·L0, 0]) to clamp.
pub fn prism_cantilever_box(h: f64, length: f64, spacing: f64) -> crate::geometry::Shape3 {
    crate::geometry::Shape3::Box {
        origin: Vector3::new(-3.0 * spacing, 0.0, 0.0),
        size: Vector3::new(length + 3.0 * spacing, h, h),
    }
}

/// Tip stiffness / Timoshenko's of a 3D prism cantilever of particles `p` filling
/// [`prism_cantilever_box`]: the particles at x ≤ 0 held in x, y and z; a tip load P along z
/// spread over the particles within one spacing of the free end in proportion to their
/// volume; the tip deflection the load-weighted (work-conjugate) mean; Timoshenko's
/// δ = P·a³/(3EI) + P·a/(κGA) with a the load's centroid, I = h⁴/12, A = h², κ = 5/6.
pub fn prism_cantilever_stiffness<const K: usize>(
    p: &crate::discretise::Particles<3, K>,
    h: f64,
    length: f64,
    spacing: f64,
) -> Result<f64, RunError> {
    use crate::solver::mechanics::Mechanics;
    let n = p.len();
    let mech = Mechanics::new(p, &vec![2400.0; n]);
    let constrained: Vec<[bool; 3]> = p.x0.iter().map(|x| [x.x <= 0.0; 3]).collect();
    let tip = TipLoad::new(&p.x0, &p.volume, length, spacing);
    let mut f = vec![Vector3::zeros(); n];
    for &(i, share) in &tip.shares {
        f[i].z = share;
    }
    let u = static_force_response(&mech, &p.x0, &constrained, &f)?;
    Ok(tip.timoshenko(h.powi(4) / 12.0, h * h) / tip.deflection(|i| u[i].z))
}

/// [`prism_cantilever_stiffness`] of an FCC lattice with the boundary treatment `surface`.
pub fn fcc_prism_cantilever(
    h: f64,
    length: f64,
    lattice: &crate::discretise::fcc::FccLattice,
    surface: crate::scene::Surface,
) -> Result<f64, RunError> {
    use crate::run::generate::fcc_surface_treatment as surface_treatment;
    let shape = prism_cantilever_box(h, length, lattice.spacing);
    let mut p = lattice.fill(&shape);
    surface_treatment(&mut p, &shape, surface, E, NU);
    prism_cantilever_stiffness(&p, h, length, lattice.spacing)
}

/// [`prism_cantilever_stiffness`] of random particles (`recipe`), each with least-squares
/// moduli fitted to the calibrated target (E*, ν*) a run fits them to
/// (`model::sppm_calibration::fit_target_3d`).
pub fn random_prism_cantilever(
    h: f64,
    length: f64,
    recipe: &crate::discretise::random3::RandomSolid,
) -> Result<f64, RunError> {
    let shape = prism_cantilever_box(h, length, recipe.spacing);
    let (e_fit, nu_fit) = crate::model::sppm_calibration::fit_target_3d(E, NU, recipe.min_distance)
        .map_err(RunError::Setup)?;
    let p = fitted_random_solid(&shape, recipe, e_fit, nu_fit)?;
    prism_cantilever_stiffness(&p, h, length, recipe.spacing)
}

/// (E/E0, ν/ν0) of a 3D block W × W × H (z along H, lower corner at the origin) of particles
/// with their moduli, against this module's [`E`] and [`NU`]: the rows within `band` of z = 0
/// held in z, those within `band` of z = H pulled to a strain of 1e-4 (sides free), the
/// static solution read by [`prism_moduli`].
pub fn block_moduli<const K: usize>(
    p: &crate::discretise::Particles<3, K>,
    width: f64,
    height: f64,
    band: f64,
) -> Result<(f64, f64), RunError> {
    use crate::solver::mechanics::Mechanics;
    let n = p.len();
    let mech = Mechanics::new(p, &vec![2400.0; n]);
    let strain = 1e-4;
    let mut constrained = vec![[false; 3]; n];
    let mut ubar = vec![Vector3::zeros(); n];
    let mut top = Vec::new();
    for i in 0..n {
        let z = p.x0[i].z;
        if z < band {
            constrained[i][2] = true;
        } else if z > height - band {
            constrained[i][2] = true;
            ubar[i].z = strain * height;
            top.push(i);
        }
    }
    let u = static_response(&mech, &p.x0, &constrained, &ubar)?;
    let mut f = vec![Vector3::zeros(); n];
    LinearOperator::new(&mech, &p.x0).internal_forces(&u, &mut f);
    let force = -top.iter().map(|&i| f[i].z).sum::<f64>();
    let (e, nu) = prism_moduli(&p.x0, &u, force, width, height)
        .ok_or_else(|| RunError::Setup("the middle half of the block holds no particles".into()))?;
    Ok((e / E, nu / NU))
}

/// (E, ν) of a prism W × W × H (z along H, lower corner at the origin) in uniaxial tension
/// along z as a testing machine reads them: σ = `force`/W², the strains from an affine fit
/// u ≈ G·x + c of the displacements `u` of the particles at `x0` over the middle half of the
/// prism (ν the mean of the two lateral ratios); `None` when the middle half cannot carry the
/// fit.
pub fn prism_moduli(
    x0: &[Vector3<f64>],
    u: &[Vector3<f64>],
    force: f64,
    width: f64,
    height: f64,
) -> Option<(f64, f64)> {
    use nalgebra::{SMatrix, SVector};
    let mut ata = SMatrix::<f64, 4, 4>::zeros();
    let mut atb = [SVector::<f64, 4>::zeros(); 3];
    for (x, ui) in x0.iter().zip(u) {
        let inside = (x.x - 0.5 * width).abs() <= 0.25 * width
            && (x.y - 0.5 * width).abs() <= 0.25 * width
            && (x.z - 0.5 * height).abs() <= 0.25 * height;
        if inside {
            let row = SVector::<f64, 4>::new(x.x, x.y, x.z, 1.0);
            ata += row * row.transpose();
            for d in 0..3 {
                atb[d] += row * ui[d];
            }
        }
    }
    let inv = ata.try_inverse()?;
    let (exx, eyy, ezz) = ((inv * atb[0])[0], (inv * atb[1])[1], (inv * atb[2])[2]);
    Some((force / (width * width) / ezz, -0.5 * (exx + eyy) / ezz))
}
