//! The maps of a 3D run draw a section, not every particle: a person reads a crack or a
//! stress field on a plane at a glance, and a map of 10⁶ particles stays a small file. The
//! section is the mid-plane normal to z for a body with a section along z (a prism: the
//! dog-bone, a beam; a cylinder along z: the split cylinder's disc, its split through the
//! loaded diameter), else the mid-plane of the body's bounding box normal to its shortest
//! extent (ties: z before y before x; the x–z plane of a box loaded along z). Its particles
//! are those within half a spacing of the plane; the title names the plane, the axes their
//! coordinates.

use crate::run::Outcome;

/// A 3D outcome's section: the particles within half a spacing of the mid-plane, the plane's
/// normal axis and position, and its in-plane axes (u, v).
pub struct Section {
    pub keep: Vec<usize>,
    pub normal: usize,
    pub mid: f64,
    pub u: usize,
    pub v: usize,
}

/// The section of a 3D outcome (the module doc says which plane).
pub fn section(o: &Outcome) -> Section {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for x in &o.x0 {
        for d in 0..3 {
            lo[d] = lo[d].min(x[d]);
            hi[d] = hi[d].max(x[d]);
        }
    }
    let extent = |d: usize| hi[d] - lo[d];
    // the normal: z for a body with a section along z (a prism, a cylinder along z: its
    // section as in 2D), else the shortest extent, ties to z, then y, then x
    let normal = if o.scene.section_along_z().is_some() {
        2
    } else {
        [2, 1, 0]
            .into_iter()
            .min_by(|&a, &b| extent(a).total_cmp(&extent(b)).then(b.cmp(&a)))
            .expect("three axes")
    };
    let (u, v) = match normal {
        2 => (0, 1),
        1 => (0, 2),
        _ => (1, 2),
    };
    let mid = 0.5 * (lo[normal] + hi[normal]);
    let half = 0.5 * o.summary.spacing_m;
    let keep = (0..o.x0.len())
        .filter(|&i| (o.x0[i][normal] - mid).abs() <= half)
        .collect();
    Section {
        keep,
        normal,
        mid,
        u,
        v,
    }
}

/// The view of a 3D outcome on its section (particles, displacements, stresses, damage and
/// groups restricted to the slab, coordinates in the plane first); a 2D outcome as it is.
pub fn section_view(o: &Outcome) -> Outcome {
    if o.dim != 3 || o.x0.is_empty() {
        return o.clone();
    }
    let Section {
        keep,
        normal,
        mid,
        u,
        v,
    } = section(o);
    let names = ["x", "y", "z"];
    let mut index = vec![u32::MAX; o.x0.len()];
    for (k, &i) in keep.iter().enumerate() {
        index[i] = k as u32;
    }
    let order = [u, v, normal];
    let permute = |p: &[f64; 3]| [p[order[0]], p[order[1]], p[order[2]]];
    // a Voigt stress [xx, yy, zz, yz, xz, xy] in the permuted axes
    let voigt = |s: &[f64; 6]| {
        let t = [[s[0], s[5], s[4]], [s[5], s[1], s[3]], [s[4], s[3], s[2]]];
        let at = |r: usize, c: usize| t[order[r]][order[c]];
        [at(0, 0), at(1, 1), at(2, 2), at(1, 2), at(0, 2), at(0, 1)]
    };
    let mut view = o.clone();
    view.x0 = keep.iter().map(|&i| permute(&o.x0[i])).collect();
    view.displacement = keep.iter().map(|&i| permute(&o.displacement[i])).collect();
    view.stress = keep.iter().map(|&i| voigt(&o.stress[i])).collect();
    view.volume = keep.iter().map(|&i| o.volume[i]).collect();
    view.damage = o
        .damage
        .as_ref()
        .map(|d| keep.iter().map(|&i| d[i]).collect());
    view.moduli_residual = None;
    view.cells = None;
    for g in &mut view.groups {
        g.members = g
            .members
            .iter()
            .filter(|&&i| index[i as usize] != u32::MAX)
            .map(|&i| index[i as usize])
            .collect();
    }
    view.fields.clear();
    if normal != 2 {
        // the cutouts lie in the x–y plane
        view.scene.cutouts.clear();
    }
    view.axes = [names[u], names[v]];
    view.summary.scene = format!(
        "{} — section {} = {:.1} mm ({} particles)",
        o.summary.scene,
        names[normal],
        mid * 1e3,
        keep.len()
    );
    view
}
