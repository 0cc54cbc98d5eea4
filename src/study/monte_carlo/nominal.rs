//! The nominal strength σN of a run, defined per body: the dog-bone's mean stress over its
//! neck, a beam's flexural stress in three-point bending, a block's mean stress over its
//! section normal to the load. Any other body is refused: a σN read as force over an
//! arbitrary width would not be a stress of the specimen.

use crate::scene::{BodySpec, Edge, GroupSpec, Selection};
use crate::Scene;
use anyhow::bail;

/// How σN is read from the peak force P of a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Nominal {
    /// A dog-bone of size D (2D, or a prism of its section) of thickness t:
    /// σN = P/(0.6·D·t), the mean stress over the neck.
    Dogbone { size: f64, thickness: f64 },
    /// A beam in three-point bending of span S between its supports, depth d (the full
    /// depth along the load, notch included) and thickness b: σN = 3·P·S/(2·b·d²), the
    /// flexural stress at mid-span of the unnotched section.
    Beam {
        span: f64,
        depth: f64,
        thickness: f64,
    },
    /// A block pulled or pushed through whole faces: σN = P/A, A its mean section normal to
    /// the load (volume over extent along the load; the section itself for a prism without
    /// cutouts). `width` is its smallest extent normal to the load.
    Block { area: f64, width: f64 },
}

/// The bodies and loadings [`Nominal::of`] reads, for messages.
pub const SUPPORTED: &str = "a dogbone (σN = P/(0.6·D·t)), a notched_beam or any beam in \
     three-point bending (one loaded group between two supports that hold the loaded \
     component: σN = 3·P·S/(2·b·d²)), or a block loaded through whole faces (loaded groups \
     selected by `edge` normal to the load: σN = P/A)";

impl Nominal {
    /// How σN is read for `scene`; an error naming the body when it is none of
    /// [`SUPPORTED`].
    pub fn of(scene: &Scene) -> anyhow::Result<Nominal> {
        let b = thickness(scene);
        if let Some(size) = super::sizes::dogbone_size(&scene.body) {
            return Ok(Nominal::Dogbone { size, thickness: b });
        }
        let load = loaded_component(scene);
        match (three_point_span(scene), is_notched_beam(&scene.body)) {
            (Some(span), _) => {
                let (lo, hi) = scene.shape().bounding_box();
                return Ok(Nominal::Beam {
                    span,
                    depth: hi.y - lo.y,
                    thickness: b,
                });
            }
            (None, true) => bail!(
                "body `{}`: σN of a notched beam is its flexural stress in three-point bending, \
                 3·P·S/(2·b·d²), with the span S between its supports; the scene needs one \
                 group loaded in y at an x strictly between two groups that fix y, each \
                 selected by `box`, `nearest` or a `strip` on the top or bottom edge",
                body_kind(&scene.body)
            ),
            (None, false) => {}
        }
        let through_faces = load.is_some()
            && scene
                .groups
                .iter()
                .filter(|g| g.load.is_some())
                .all(|g| face_normal_to(g, load.unwrap_or(1)));
        if through_faces && !matches!(scene.body, BodySpec::Disc { .. }) {
            return Ok(block(scene, load.unwrap_or(1)));
        }
        bail!(
            "body `{}`: the size-effect study reads σN of {SUPPORTED}; this scene is none of \
             these, so its σN is not defined",
            body_kind(&scene.body)
        )
    }

    /// σN (Pa) of the peak force `peak_force_n` (its magnitude).
    pub fn strength(&self, peak_force_n: f64) -> f64 {
        let p = peak_force_n.abs();
        match *self {
            Nominal::Dogbone { size, thickness } => p / (0.6 * size * thickness),
            Nominal::Beam {
                span,
                depth,
                thickness,
            } => 3.0 * p * span / (2.0 * thickness * depth * depth),
            Nominal::Block { area, .. } => p / area,
        }
    }

    /// The size D (m) of the size effect: the dog-bone's D, the beam's depth d, the block's
    /// smallest extent normal to the load.
    pub fn size(&self) -> f64 {
        match *self {
            Nominal::Dogbone { size, .. } => size,
            Nominal::Beam { depth, .. } => depth,
            Nominal::Block { width, .. } => width,
        }
    }

    /// The formula with its values, as size_effect.json and the command line state it.
    pub fn describe(&self) -> String {
        match *self {
            Nominal::Dogbone { size, thickness } => format!(
                "dog-bone: σN = P/(0.6·D·t), D = {size} m, t = {thickness} m"
            ),
            Nominal::Beam {
                span,
                depth,
                thickness,
            } => format!(
                "beam in three-point bending: σN = 3·P·S/(2·b·d²), S = {span} m (between the supports), d = {depth} m, b = {thickness} m"
            ),
            Nominal::Block { area, width } => format!(
                "block: σN = P/A, A = {area} m² (mean section normal to the load), D = {width} m"
            ),
        }
    }
}

/// The body's kind as the scene writes it: `notched_beam`, `prism` of a `notched_beam`.
pub fn body_kind(body: &BodySpec) -> String {
    match body {
        BodySpec::Prism { section, .. } => format!("prism of {}", section.name()),
        b => b.name().to_string(),
    }
}

fn is_notched_beam(body: &BodySpec) -> bool {
    match body {
        BodySpec::NotchedBeam { .. } => true,
        BodySpec::Prism { section, .. } => is_notched_beam(section),
        _ => false,
    }
}

/// The thickness: `material.thickness` in 2D, the extent along z of a solid.
fn thickness(scene: &Scene) -> f64 {
    match scene.solid() {
        Some(s) => {
            let (lo, hi) = s.bounding_box();
            hi.z - lo.z
        }
        None => scene.material.thickness(),
    }
}

/// The component of the first loaded group (0, 1, 2 for x, y, z).
fn loaded_component(scene: &Scene) -> Option<usize> {
    scene
        .groups
        .iter()
        .find_map(|g| g.load.as_ref())
        .map(|l| l.component.index())
}

/// The x-position of a group that sits at one place along a beam: the middle of a box, the
/// point of `nearest`, the centre of a strip on the top or bottom edge.
fn x_position(scene: &Scene, g: &GroupSpec) -> Option<f64> {
    match &g.select {
        Selection::Box { min, max } => Some(0.5 * (min[0] + max[0])),
        Selection::Nearest { point } => Some(point[0]),
        Selection::Strip {
            edge: edge @ (Edge::Top | Edge::Bottom),
            centre,
            ..
        } => crate::discretise::groups::strip_centre_on(*centre, *edge, &scene.shape()),
        _ => None,
    }
}

/// The span S of a three-point bending test: one group loaded in y at an x strictly between
/// the outermost groups that fix y (without a load of their own); S is the distance between
/// those two supports. `None` when the scene's groups are not such a test.
pub fn three_point_span(scene: &Scene) -> Option<f64> {
    let loaded: Vec<&GroupSpec> = scene.groups.iter().filter(|g| g.load.is_some()).collect();
    let [load] = loaded.as_slice() else {
        return None;
    };
    if load.load.as_ref()?.component.index() != 1 {
        return None;
    }
    let x_load = x_position(scene, load)?;
    let supports: Vec<f64> = scene
        .groups
        .iter()
        .filter(|g| g.load.is_none() && g.fix.iter().any(|a| a.index() == 1))
        .filter_map(|g| x_position(scene, g))
        .collect();
    let lo = supports.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = supports.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo < x_load && x_load < hi).then_some(hi - lo)
}

/// Whether group `g` is a whole face normal to component `k` (an `edge` selection: bottom or
/// top for y, left or right for x, front or back for z).
fn face_normal_to(g: &GroupSpec, k: usize) -> bool {
    match &g.select {
        Selection::Edge { edge, .. } => matches!(
            (edge, k),
            (Edge::Left | Edge::Right, 0)
                | (Edge::Top | Edge::Bottom, 1)
                | (Edge::Front | Edge::Back, 2)
        ),
        _ => false,
    }
}

/// The block rule: A = V/ℓ (3D) or area·t/ℓ (2D), ℓ the extent along component `k`; the
/// width its smallest extent normal to `k`.
fn block(scene: &Scene, k: usize) -> Nominal {
    let (size, content) = match scene.solid() {
        Some(s) => {
            let (lo, hi) = s.bounding_box();
            (hi - lo, s.volume())
        }
        None => {
            let shape = scene.shape();
            let (lo, hi) = shape.bounding_box();
            let t = scene.material.thickness();
            let e = hi - lo;
            (
                nalgebra::Vector3::new(e.x, e.y, f64::INFINITY),
                shape.area() * t,
            )
        }
    };
    let width = (0..3)
        .filter(|&i| i != k)
        .map(|i| size[i])
        .fold(f64::INFINITY, f64::min);
    Nominal::Block {
        area: content / size[k],
        width,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    /// A 2D notched beam, 200 × 50 mm, 40 mm thick: supports at x = 25 mm (a point) and
    /// x = 175 mm (a strip on the bottom edge), the load a box at mid-span on top.
    fn beam_2d(dir: &str, support_fix: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("sppm-nominal-{dir}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let path = d.join("beam.toml");
        let text = format!(
            r#"name = "beam_2d"
[body]
shape = "notched_beam"
length = 0.2
depth = 0.05
notch_depth = 0.01
notch_width = 0.002
[discretisation]
lattice = "hexagonal"
spacing = 0.005
[material]
E = 30.0e9
nu = 0.2
rho = 2400.0
thickness = 0.04
[[groups]]
name = "left"
select = {{ by = "nearest", point = [0.025, 0.0] }}
fix = ["x", "y"]
[[groups]]
name = "right"
select = {{ by = "strip", edge = "bottom", width = 0.01, centre = 0.175 }}
fix = {support_fix}
[[groups]]
name = "load"
select = {{ by = "box", min = [0.095, 0.045], max = [0.105, 0.05] }}
load = {{ component = "y", displacement = -1.0e-4 }}
[loading]
end_periods = 10.0
"#
        );
        std::fs::write(&path, text).unwrap();
        path
    }

    /// The beam's σN is the flexural stress 3·P·S/(2·b·d²) with S between the supports'
    /// centres: 2D (S = 150 mm, b = 40 mm, d = 50 mm) and the 3D Grégoire beam (S = 125 mm,
    /// b = d = 50 mm, Hobbs's peak of 1280 N: 1.92 MPa).
    #[test]
    fn a_beam_reads_its_flexural_stress_over_the_span() {
        let path = beam_2d("ok", r#"["y"]"#);
        let s = Scene::from_file(&path, &[]).unwrap();
        let n = Nominal::of(&s).unwrap();
        assert_eq!(
            n,
            Nominal::Beam {
                span: 0.15,
                depth: 0.05,
                thickness: 0.04
            }
        );
        let sigma = n.strength(-2000.0);
        let expected = 3.0 * 2000.0 * 0.15 / (2.0 * 0.04 * 0.05 * 0.05);
        assert!((sigma / expected - 1.0).abs() < 1e-12, "{sigma} {expected}");
        assert_eq!(n.size(), 0.05, "D of a beam is its depth");
        let beam = Path::new("lattices/beam_3pb_notch05_3d.toml");
        let s = Scene::from_file(beam, &[]).unwrap();
        let sigma = super::super::nominal_strength(&s, 1280.0).unwrap();
        assert!((sigma / 1.92e6 - 1.0).abs() < 1e-9, "{sigma}");
        // the unnotched beam's rectangle section is a beam too, by its loading
        let s = Scene::from_file(Path::new("lattices/beam_3pb_unnotched_3d.toml"), &[]).unwrap();
        assert!(
            matches!(Nominal::of(&s).unwrap(), Nominal::Beam { span, .. } if (span - 0.125).abs() < 1e-12)
        );
        // a notched beam without a second support holding y has no span: refused, named
        let path = beam_2d("refused", r#"["x"]"#);
        let e = Nominal::of(&Scene::from_file(&path, &[]).unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("`notched_beam`") && e.contains("span"), "{e}");
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }

    /// A block pulled through its faces reads P/A over the section normal to the load (2D: the
    /// width times the thickness); a disc (the split cylinder) is refused with the body named.
    #[test]
    fn a_block_reads_p_over_a_and_other_bodies_are_refused() {
        let s = Scene::from_file(Path::new("lattices/uniaxial_tension.toml"), &[]).unwrap();
        let n = Nominal::of(&s).unwrap();
        let sigma = n.strength(1.0e5);
        assert!(
            (sigma / (1.0e5 / (0.15 * 0.15)) - 1.0).abs() < 1e-12,
            "{n:?}"
        );
        assert!((n.size() - 0.15).abs() < 1e-12, "the width across the load");
        let s = Scene::from_file(Path::new("lattices/split_cylinder.toml"), &[]).unwrap();
        let e = Nominal::of(&s).unwrap_err().to_string();
        assert!(
            e.contains("body `disc`") && e.contains("dogbone") && e.contains("notched_beam"),
            "{e}"
        );
        assert!(super::super::nominal_strength(&s, 1.0e5).is_err());
    }
}
