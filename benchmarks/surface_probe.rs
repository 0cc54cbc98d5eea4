//! Probe: a cantilever with a patch-consistent force correction on its boundary particles.
//! For each particle i, G_i maps a homogeneous strain to the bond force on i and
//! T_i = −σ(ε)·a_i is the continuum's force on i's clipped cell (a_i the outward area
//! vector of the cell's free faces). The correction −(G_i − T_i)·ε_i, with ε_i the affine
//! fit over i's two rings, makes every homogeneous strain load every particle as the
//! continuum does (`CORRECT=1`). By default: the quadratic-consistent stabilisation energy
//! (`KAPPAS=k1,k2,..`, `RINGS=2`, `QUAD=1` for the quadratic fit, `HS=10,20` depths in
//! spacings, `VOR=1` for `voronoi` constants, `FS=1` for the free-surface constants).
//! `OMEGA=1` prints ω_max of M⁻¹K (power iteration) before each solve.
//! `GHOST=traction` (or `taylor`) replaces the model by ghost particles, `GQ=1` with the
//! quadratic fit and second-order Taylor; `CENTROID=k` moves the clipped particles to their
//! cells' centroids k times; `ROTS=..`, `OFFS=x,y,..` pick the cases; `AXIAL=1` also prints
//! the axial stiffness; `DBG=1` prints the patch checks.
//! `BAL=1` adds the least-norm per-bond axial moduli that balance the free-surface states
//! (`BAL=2` also new bonds to the second neighbours of short particles, `FLOOR=f` holds the
//! moduli ≥ f·a);
//! `DYN=1` integrates the model with the stabilisation's diagonal implicit; `RANDOM=seed`
//! uses random particles (`FSCAL=1`: free-surface constants at the calibrated E*).
//! docs/surfaces.md, "Treatments of the surface relaxation measured".

use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{Matrix2x3, Vector2, Vector3};
use sppm::discretise::voronoi::clipped_cells;
use sppm::discretise::NONE;
use sppm::geometry::Shape2;
use sppm::run::{prepare_model, Hexagonal, Model, RandomPlane};
use sppm::solver::linear::LinearOperator;
use sppm::study::elastic_checks::{cantilever_scene, Placement, E, NU, THICKNESS};

const L0: f64 = 0.001;
static QUAD: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn sigma(e: &Vector3<f64>) -> Vector3<f64> {
    let c = E / (1.0 - NU * NU);
    Vector3::new(
        c * (e[0] + NU * e[1]),
        c * (NU * e[0] + e[1]),
        c * 0.5 * (1.0 - NU) * e[2],
    )
}

fn affine(e: &Vector3<f64>, x: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(e[0] * x.x + 0.5 * e[2] * x.y, 0.5 * e[2] * x.x + e[1] * x.y)
}

static PEN: std::sync::Mutex<f64> = std::sync::Mutex::new(0.0);

/// Ghost particles: every empty lattice slot of a real particle holds a ghost at the lattice
/// site, displaced as u_b + H_b·(x_g − x_b) from its nearest real particle b, H_b the
/// affine fit over b's two rings (with `traction`, its normal derivative replaced by the one
/// that makes σ·n = 0 on b's nearest face). Every real particle then has six bonds and the
/// bulk constants.
struct Ghosts {
    dirs: [Vector2<f64>; 6],
    /// Per real particle and slot: Ok(real j) or Err(ghost g).
    stencil: Vec<[Result<usize, usize>; 6]>,
    /// Per ghost: (base b, x_g − x_b).
    ghost: Vec<(usize, Vector2<f64>)>,
    /// Per real particle: the fit weights (k, [value, ∂x, ∂y, ∂xx, ∂xy, ∂yy]) and its face normal.
    fit: Vec<(Vec<(usize, [f64; 6])>, Vector2<f64>)>,
    a: f64,
    b: f64,
    traction: bool,
}

impl Ghosts {
    fn new(model: &sppm::run::Model, h: f64, length: f64, traction: bool) -> Ghosts {
        let x0 = &model.particles.x0;
        let nb = &model.particles.neighbours;
        let n = x0.len();
        let full = (0..n).find(|&i| nb[i].iter().all(|&j| j != NONE)).unwrap();
        let dirs: [Vector2<f64>; 6] =
            std::array::from_fn(|k| (x0[nb[full][k] as usize] - x0[full]).normalize());
        for i in 0..n {
            for k in 0..6 {
                if nb[i][k] != NONE {
                    let d = (x0[nb[i][k] as usize] - x0[i]) / L0;
                    assert!((d - dirs[k]).norm() < 1e-6, "slot directions differ");
                }
            }
        }
        let mut sites: std::collections::HashMap<(i64, i64), usize> = Default::default();
        let mut gpos: Vec<Vector2<f64>> = Vec::new();
        let mut stencil = vec![[Ok(0usize); 6]; n];
        let key = |x: Vector2<f64>| {
            (
                (x.x / L0 * 1e5).round() as i64,
                (x.y / L0 * 1e5).round() as i64,
            )
        };
        for i in 0..n {
            for k in 0..6 {
                stencil[i][k] = if nb[i][k] != NONE {
                    Ok(nb[i][k] as usize)
                } else {
                    let xg = x0[i] + dirs[k] * L0;
                    let id = *sites.entry(key(xg)).or_insert_with(|| {
                        gpos.push(xg);
                        gpos.len() - 1
                    });
                    Err(id)
                };
            }
        }
        let c3 = 3.0 * L0;
        let ghost: Vec<(usize, Vector2<f64>)> = gpos
            .iter()
            .map(|&xg| {
                let b = (0..n)
                    .min_by(|&p, &q| {
                        (x0[p] - xg)
                            .norm()
                            .partial_cmp(&(x0[q] - xg).norm())
                            .unwrap()
                    })
                    .unwrap();
                (b, xg - x0[b])
            })
            .collect();
        let fit = (0..n)
            .map(|i| {
                let mut patch = vec![i];
                let mut front = vec![i];
                for _ in 0..2 {
                    let mut next = Vec::new();
                    for &q in &front {
                        for &j in &nb[q] {
                            if j != NONE && !patch.contains(&(j as usize)) {
                                patch.push(j as usize);
                                next.push(j as usize);
                            }
                        }
                    }
                    front = next;
                }
                let quad = std::env::var("GQ").is_ok();
                let basis = |d: Vector2<f64>| -> nalgebra::DVector<f64> {
                    if quad {
                        nalgebra::DVector::from_vec(vec![
                            1.0,
                            d.x,
                            d.y,
                            d.x * d.x,
                            d.x * d.y,
                            d.y * d.y,
                        ])
                    } else {
                        nalgebra::DVector::from_vec(vec![1.0, d.x, d.y, 0.0, 0.0, 0.0])
                    }
                };
                let mut nm = nalgebra::DMatrix::<f64>::zeros(6, 6);
                for &k in &patch {
                    let r = basis((x0[k] - x0[i]) / L0);
                    nm += &r * r.transpose();
                }
                if !quad {
                    for q in 3..6 {
                        nm[(q, q)] = 1.0;
                    }
                }
                let ni = nm.try_inverse().unwrap();
                let w: Vec<(usize, [f64; 6])> = patch
                    .iter()
                    .map(|&k| {
                        let c = &ni * basis((x0[k] - x0[i]) / L0);
                        (
                            k,
                            [
                                c[0],
                                c[1] / L0,
                                c[2] / L0,
                                2.0 * c[3] / (L0 * L0),
                                c[4] / (L0 * L0),
                                2.0 * c[5] / (L0 * L0),
                            ],
                        )
                    })
                    .collect();
                // nearest face's outward normal
                let x = x0[i];
                let faces = [
                    (x.x + c3, Vector2::new(-1.0, 0.0)),
                    (length - x.x, Vector2::new(1.0, 0.0)),
                    (x.y, Vector2::new(0.0, -1.0)),
                    (h - x.y, Vector2::new(0.0, 1.0)),
                ];
                let nrm = faces
                    .iter()
                    .min_by(|p, q| p.0.partial_cmp(&q.0).unwrap())
                    .unwrap()
                    .1;
                (w, nrm)
            })
            .collect();
        Ghosts {
            dirs,
            stencil,
            ghost,
            fit,
            a: model.bulk.a,
            b: model.bulk.b,
            traction,
        }
    }

    /// Second derivatives [u_xx, u_xy, u_yy] of each component at particle i.
    fn curvature(&self, u: &[Vector2<f64>], i: usize) -> [Vector2<f64>; 3] {
        let mut c = [Vector2::zeros(); 3];
        for &(k, w) in &self.fit[i].0 {
            c[0] += u[k] * w[3];
            c[1] += u[k] * w[4];
            c[2] += u[k] * w[5];
        }
        c
    }

    fn gradient(&self, u: &[Vector2<f64>], i: usize) -> nalgebra::Matrix2<f64> {
        let mut hm = nalgebra::Matrix2::zeros();
        for &(k, w) in &self.fit[i].0 {
            let (gx, gy) = (w[1], w[2]);
            hm[(0, 0)] += gx * u[k].x;
            hm[(0, 1)] += gy * u[k].x;
            hm[(1, 0)] += gx * u[k].y;
            hm[(1, 1)] += gy * u[k].y;
        }
        if self.traction {
            let nrm = self.fit[i].1;
            let t = Vector2::new(-nrm.y, nrm.x);
            let q = hm * t;
            let ls = E * NU / (1.0 - NU * NU);
            let mu = E / (2.0 * (1.0 + NU));
            let gn = -ls / (ls + 2.0 * mu) * t.dot(&q);
            let gt = -nrm.dot(&q);
            let g = nrm * gn + t * gt;
            hm = q * t.transpose() + g * nrm.transpose();
        }
        hm
    }

    fn forces(&self, u: &[Vector2<f64>], f: &mut [Vector2<f64>]) {
        let n = u.len();
        let mut ug = vec![Vector2::zeros(); self.ghost.len()];
        let mut thg = vec![0.0; self.ghost.len()];
        for (g, &(b, dx)) in self.ghost.iter().enumerate() {
            let hm = self.gradient(u, b);
            let c = self.curvature(u, b);
            ug[g] = u[b]
                + hm * dx
                + 0.5 * (c[0] * dx.x * dx.x + c[1] * 2.0 * dx.x * dx.y + c[2] * dx.y * dx.y);
            // gradient at the ghost: H_b + ∇∇u·dx
            let mut hg = hm;
            for comp in 0..2 {
                hg[(comp, 0)] += c[0][comp] * dx.x + c[1][comp] * dx.y;
                hg[(comp, 1)] += c[1][comp] * dx.x + c[2][comp] * dx.y;
            }
            thg[g] = self.dirs.iter().map(|d| d.dot(&(hg * d))).sum();
        }
        let disp = |s: &Result<usize, usize>| match *s {
            Ok(j) => u[j],
            Err(g) => ug[g],
        };
        let theta: Vec<f64> = (0..n)
            .map(|i| {
                (0..6)
                    .map(|k| self.dirs[k].dot(&(disp(&self.stencil[i][k]) - u[i])) / L0)
                    .sum()
            })
            .collect();
        for i in 0..n {
            let mut acc = Vector2::zeros();
            for k in 0..6 {
                let sk = &self.stencil[i][k];
                let s = self.dirs[k].dot(&(disp(sk) - u[i])) / L0;
                let thj = match *sk {
                    Ok(j) => theta[j],
                    Err(g) => thg[g],
                };
                let fb = 0.5 * (2.0 * self.a * s + self.b * theta[i] + self.b * thj);
                acc += self.dirs[k] * fb;
            }
            f[i] = acc;
        }
    }
}

/// Per-bond changes Δα of the axial modulus ½(a_i + a_j) on every bond with an end that has
/// missing bonds, of least norm (SVD pseudo-inverse), such that the free-surface state of the
/// nearest face (uniaxial stress along it) is balanced at every particle those bonds touch.
/// Adds the bonds' stiffness changes to `trips` (symmetric: an energy ½·Δα·S²).
fn bond_balance<const K: usize>(
    model: &Model<K, 2>,
    op: &mut LinearOperator<2, K>,
    h: f64,
    length: f64,
    map: &[usize],
    trips: &mut Vec<Triplet<usize, usize, f64>>,
) {
    let x0 = &model.particles.x0;
    let nb = &model.particles.neighbours;
    let n = x0.len();
    let c3 = 3.0 * L0;
    // the two free-surface states: faces normal to y (stress along x), faces normal to x
    let states = [Vector3::new(1.0, -NU, 0.0), Vector3::new(-NU, 1.0, 0.0)];
    let mut forces = [vec![Vector2::zeros(); n], vec![Vector2::zeros(); n]];
    for (s, e) in states.iter().enumerate() {
        let ua: Vec<Vector2<f64>> = x0.iter().map(|x| affine(e, x)).collect();
        op.internal_forces(&ua, &mut forces[s]);
    }
    let short = |i: usize| nb[i].iter().any(|&j| j == NONE);
    let free = |i: usize| map[2 * i] != usize::MAX || map[2 * i + 1] != usize::MAX;
    // unknown bonds (i < j)
    let mut bonds: Vec<(usize, usize, Vector2<f64>, f64)> = Vec::new();
    for i in 0..n {
        for &j in &nb[i] {
            if j == NONE {
                continue;
            }
            let j = j as usize;
            let away = |q: usize| x0[q].x > 2.0 * L0 && x0[q].x < length - 2.0 * L0;
            if i < j && (short(i) || short(j)) && free(i) && free(j) && away(i) && away(j) {
                let d = x0[j] - x0[i];
                bonds.push((i, j, d / d.norm(), d.norm()));
            }
        }
    }
    let existing = bonds.len();
    if std::env::var("BAL").map(|v| v == "2").unwrap_or(false) {
        // new bonds from each short particle to the particles within 2.05·L0 it has no bond to
        let away = |q: usize| x0[q].x > 2.0 * L0 && x0[q].x < length - 2.0 * L0;
        for i in 0..n {
            if !short(i) || !free(i) || !away(i) {
                continue;
            }
            for j in 0..n {
                if j == i || !free(j) || !away(j) || nb[i].contains(&(j as u32)) {
                    continue;
                }
                let d = x0[j] - x0[i];
                if d.norm() > 2.05 * L0 || (short(j) && j < i) {
                    continue;
                }
                bonds.push((i, j, d / d.norm(), d.norm()));
            }
        }
    }
    // equations: particles touched, states of the faces within 1.5 L0
    let mut rows: Vec<(usize, usize)> = Vec::new();
    let mut touched: Vec<usize> = bonds.iter().flat_map(|b| [b.0, b.1]).collect();
    touched.sort();
    touched.dedup();
    for &i in &touched {
        if !free(i) || x0[i].x <= 2.5 * L0 || x0[i].x >= length - 2.5 * L0 {
            continue;
        }
        let x = x0[i];
        let near_y = x.y < 1.5 * L0 || h - x.y < 1.5 * L0;
        let near_x = x.x + c3 < 1.5 * L0 || length - x.x < 1.5 * L0;
        let mut st = Vec::new();
        if near_y {
            st.push(0);
        }
        if near_x {
            st.push(1);
        }
        if st.is_empty() {
            // an interior particle: balanced in the state of its nearest face
            let dy = x.y.min(h - x.y);
            let dx = (x.x + c3).min(length - x.x);
            st = vec![if dy <= dx { 0 } else { 1 }];
        }
        for s in st {
            rows.push((i, s));
        }
    }
    let (nr, nc) = (2 * rows.len(), bonds.len());
    let mut a = nalgebra::DMatrix::<f64>::zeros(nr, nc);
    let mut r = nalgebra::DVector::<f64>::zeros(nr);
    for (q, &(i, s)) in rows.iter().enumerate() {
        let e = states[s];
        let em = nalgebra::Matrix2::new(e[0], 0.5 * e[2], 0.5 * e[2], e[1]);
        for (c, &(bi, bj, nij, _)) in bonds.iter().enumerate() {
            if bi != i && bj != i {
                continue;
            }
            let nn = if bi == i { nij } else { -nij };
            let st = nn.dot(&(em * nn));
            a[(2 * q, c)] += st * nn.x;
            a[(2 * q + 1, c)] += st * nn.y;
        }
        r[2 * q] = -forces[s][i].x;
        r[2 * q + 1] = -forces[s][i].y;
    }
    // least-norm Δα with every modulus kept ≥ floor·a_bulk (`FLOOR`, default none): the
    // columns that fall below are fixed at the floor and the rest solved again
    let floor: Option<f64> = std::env::var("FLOOR").ok().map(|v| v.parse().unwrap());
    let base: Vec<f64> = bonds
        .iter()
        .enumerate()
        .map(|(c, &(i, j, _, _))| {
            if c < existing {
                0.5 * (model.mech.a[i] + model.mech.a[j])
            } else {
                0.0
            }
        })
        .collect();
    let mut fixed: Vec<Option<f64>> = vec![None; nc];
    let mut dalpha = nalgebra::DVector::<f64>::zeros(nc);
    for _ in 0..40 {
        let free_cols: Vec<usize> = (0..nc).filter(|&c| fixed[c].is_none()).collect();
        let mut rr = r.clone();
        for c in 0..nc {
            if let Some(v) = fixed[c] {
                rr -= a.column(c) * v;
            }
        }
        let sub = nalgebra::DMatrix::from_fn(nr, free_cols.len(), |q, k| a[(q, free_cols[k])]);
        let svd = sub.svd(true, true);
        let tol = 1e-9 * svd.singular_values.max();
        let x = svd.solve(&rr, tol).unwrap();
        for c in 0..nc {
            dalpha[c] = fixed[c].unwrap_or(0.0);
        }
        for (k, &c) in free_cols.iter().enumerate() {
            dalpha[c] = x[k];
        }
        let Some(fl) = floor else { break };
        let mut any = false;
        for c in 0..nc {
            let lb = fl * model.bulk.a - base[c];
            if fixed[c].is_none() && dalpha[c] < lb - 1e-12 * model.bulk.a {
                fixed[c] = Some(lb);
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    let res = (&a * &dalpha - &r).norm() / r.norm().max(1e-300);
    let mut worst: f64 = f64::INFINITY;
    for (c, &(i, j, nij, l)) in bonds.iter().enumerate() {
        let base = if c < existing {
            0.5 * (model.mech.a[i] + model.mech.a[j])
        } else {
            0.0
        };
        worst = worst.min((base + dalpha[c]) / model.bulk.a);
        let k = dalpha[c] / l;
        let nn = nij * nij.transpose();
        for (p, q, sign) in [(i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)] {
            for r0 in 0..2 {
                for c0 in 0..2 {
                    let (ri, ci) = (map[2 * p + r0], map[2 * q + c0]);
                    if ri != usize::MAX && ci != usize::MAX {
                        trips.push(Triplet::new(ri, ci, sign * k * nn[(r0, c0)]));
                    }
                }
            }
        }
    }
    if std::env::var("DBG").is_ok() {
        println!(
            "balance: {} bonds ({} new), {} equations, residual {res:.2e}, smallest α/a_bulk {worst:.3}, largest |Δα|/a_bulk {:.3}",
            nc,
            nc - existing,
            nr,
            dalpha.amax() / model.bulk.a
        );
    }
}

/// Central differences on the assembled model, the stabilisation's diagonal taken at the
/// average of n+1 and n−1 (unconditionally stable for that part), the rest explicit, at
/// 0.9 × the untreated model's stable step; prints the growth of the energy norm over
/// 20,000 steps from a seeded random start.
fn dynamic_check(
    trips: &[Triplet<usize, usize, f64>],
    split: usize,
    m: usize,
    map: &[usize],
    mass: &[f64],
    n: usize,
) {
    let kb = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &trips[..split]).unwrap();
    let mut dp = vec![0.0; m];
    let mut off: Vec<Triplet<usize, usize, f64>> = Vec::new();
    for t in &trips[split..] {
        if t.row == t.col {
            dp[t.row] += t.val;
        } else {
            off.push(*t);
        }
    }
    let ko = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &off).unwrap();
    let mut mm = vec![0.0; m];
    for i in 0..n {
        for c in 0..2 {
            if map[2 * i + c] != usize::MAX {
                mm[map[2 * i + c]] = mass[i];
            }
        }
    }
    // ω_max of the untreated model
    let mut v = Mat::<f64>::from_fn(m, 1, |r, _| 1.0 + ((r * 7919) % 13) as f64 * 0.1);
    let mut lam = 0.0;
    for _ in 0..600 {
        let kv = &kb * &v;
        let w = Mat::<f64>::from_fn(m, 1, |r, _| kv[(r, 0)] / mm[r]);
        let nv = (0..m).map(|r| v[(r, 0)].powi(2)).sum::<f64>().sqrt();
        let nw = (0..m).map(|r| w[(r, 0)].powi(2)).sum::<f64>().sqrt();
        lam = nw / nv;
        v = Mat::<f64>::from_fn(m, 1, |r, _| w[(r, 0)] / nw);
    }
    let dt = 0.9 * 2.0 / lam.sqrt();
    let mut u0 = Mat::<f64>::from_fn(m, 1, |r, _| {
        (((r * 2654435761) % 1000) as f64 / 1000.0 - 0.5) * 1e-9
    });
    let mut u1 = u0.clone();
    let norm = |u: &Mat<f64>| (0..m).map(|r| u[(r, 0)].powi(2)).sum::<f64>().sqrt();
    let start = norm(&u1);
    let mut peak: f64 = 0.0;
    for step in 0..20000 {
        let kbu = &kb * &u1;
        let kou = &ko * &u1;
        let u2 = Mat::<f64>::from_fn(m, 1, |r, _| {
            let rhs = mm[r] * (2.0 * u1[(r, 0)] - u0[(r, 0)]) / (dt * dt)
                - kbu[(r, 0)]
                - kou[(r, 0)]
                - 0.5 * dp[r] * u0[(r, 0)];
            rhs / (mm[r] / (dt * dt) + 0.5 * dp[r])
        });
        u0 = u1;
        u1 = u2;
        let g = norm(&u1) / start;
        peak = peak.max(g);
        if !g.is_finite() || g > 1e6 {
            println!("dynamic: unstable at step {step} (dt {dt:.3e})");
            return;
        }
    }
    println!("dynamic: 20000 steps at dt {dt:.3e}, largest |u|/|u0| {peak:.3e}");
}

/// Move every particle whose cell the outline clips to its clipped cell's centroid
/// (`CENTROID=k`: k sweeps), then refresh the bond lengths, volumes and `voronoi_fit`
/// constants of every particle whose bonds or cell changed.
fn centroid_shift(model: &mut sppm::run::Model, h: f64, length: f64, sweeps: usize) {
    let c3 = 3.0 * L0;
    let shape = Shape2::Rectangle {
        origin: Vector2::new(-c3, 0.0),
        width: length + c3,
        height: h,
    };
    let tol = 1e-9 * L0;
    let on = |m: Vector2<f64>| {
        (m.x + c3).abs() < tol
            || (m.x - length).abs() < tol
            || m.y.abs() < tol
            || (m.y - h).abs() < tol
    };
    let n = model.particles.x0.len();
    let x_orig = model.particles.x0.clone();
    for _ in 0..sweeps {
        let x0 = model.particles.x0.clone();
        let cells = clipped_cells(&x0, &shape).unwrap();
        for i in 0..n {
            let poly = &cells[i].0;
            let clipped = (0..poly.len()).any(|k| on(0.5 * (poly[k] + poly[(k + 1) % poly.len()])));
            if !clipped {
                continue;
            }
            let (mut a2, mut c) = (0.0, Vector2::zeros());
            for k in 0..poly.len() {
                let (p0, p1) = (poly[k], poly[(k + 1) % poly.len()]);
                let cr = p0.x * p1.y - p1.x * p0.y;
                a2 += cr;
                c += (p0 + p1) * cr;
            }
            model.particles.x0[i] = c / (3.0 * a2);
        }
    }
    let x0 = model.particles.x0.clone();
    let cells = clipped_cells(&x0, &shape).unwrap();
    let d = sppm::model::micro_modulus::elasticity_matrix(E, NU, sppm::scene::Plane::Stress);
    let rho = model.mech.mass[n / 2] / model.particles.volume[n / 2];
    let moved: Vec<bool> = (0..n).map(|i| (x0[i] - x_orig[i]).norm() > 1e-12).collect();
    let mut refit = 0;
    let mut max_move: f64 = 0.0;
    for i in 0..n {
        max_move = max_move.max((x0[i] - x_orig[i]).norm() / L0);
        let vol = cells[i].1 * THICKNESS;
        let nb = model.particles.neighbours[i];
        let touched = moved[i] || nb.iter().any(|&j| j != NONE && moved[j as usize]);
        let changed = touched || (vol - model.particles.volume[i]).abs() > 1e-12 * vol;
        if !changed {
            continue;
        }
        let mut bonds = Vec::new();
        for k in 0..6 {
            if nb[k] == NONE {
                continue;
            }
            let dx = x0[nb[k] as usize] - x0[i];
            let l = dx.norm();
            model.particles.l0[i][k] = l;
            model.mech.inv_l0[i][k] = 1.0 / l;
            bonds.push((dx / l, l));
        }
        model.particles.volume[i] = vol;
        model.mech.mass[i] = rho * vol;
        if let Some(f) = sppm::model::micro_modulus::fit(&bonds, vol, &d) {
            model.mech.a[i] = f.moduli.a;
            model.mech.b[i] = f.moduli.b;
            refit += 1;
        }
    }
    if std::env::var("DBG").is_ok() {
        println!("centroid: refit {refit}, largest move {max_move:.3} L0");
    }
}

/// Constants of each single-face boundary particle that make its own stress exact in the
/// free-surface state (uniaxial stress along the face): σ_tt = E·ε, σ_nn = 0.
fn free_surface_constants<const K: usize>(model: &mut Model<K, 2>, h: f64, length: f64) {
    // random particles: the calibrated target (E*, ν*) their bulk is fitted to
    let (e_fs, nu_fs) = match &model.random {
        Some(r) if std::env::var("FSCAL").is_ok() => sppm::model::sppm_calibration::fit_target(
            E,
            NU,
            sppm::scene::Plane::Stress,
            r.generation.min_distance,
        )
        .unwrap(),
        _ => (E, NU),
    };
    let c3 = 3.0 * L0;
    let shape = Shape2::Rectangle {
        origin: Vector2::new(-c3, 0.0),
        width: length + c3,
        height: h,
    };
    let x0 = model.particles.x0.clone();
    let cells = clipped_cells(&x0, &shape).unwrap();
    let tol = 1e-9 * L0;
    let mut changed = 0;
    for i in 0..x0.len() {
        let poly = &cells[i].0;
        let mut normals: Vec<Vector2<f64>> = Vec::new();
        for k in 0..poly.len() {
            let (v0, v1) = (poly[k], poly[(k + 1) % poly.len()]);
            let mid = 0.5 * (v0 + v1);
            let on = (mid.x + c3).abs() < tol
                || (mid.x - length).abs() < tol
                || mid.y.abs() < tol
                || (mid.y - h).abs() < tol;
            if on && (v1 - v0).norm() > 1e-6 * L0 {
                let d = (v1 - v0).normalize();
                normals.push(Vector2::new(d.y, -d.x));
            }
        }
        if normals.is_empty() || normals.iter().any(|m| (m - normals[0]).norm() > 1e-6) {
            continue;
        }
        let n = normals[0];
        let t = Vector2::new(-n.y, n.x);
        let bonds: Vec<(Vector2<f64>, f64)> = (0..K)
            .filter(|&k| model.particles.neighbours[i][k] != NONE)
            .map(|k| {
                let j = model.particles.neighbours[i][k] as usize;
                ((x0[j] - x0[i]).normalize(), model.particles.l0[i][k])
            })
            .collect();
        let (am, bm) =
            sppm::model::micro_modulus::stiffness_basis(&bonds, model.particles.volume[i]);
        // ε = t⊗t − ν n⊗n in [εxx, εyy, γ]
        let epsm = t * t.transpose() - nu_fs * n * n.transpose();
        let eps = Vector3::new(epsm[(0, 0)], epsm[(1, 1)], 2.0 * epsm[(0, 1)]);
        let (sa, sb) = (am * eps, bm * eps);
        let proj = |v: &Vector3<f64>, d: &Vector2<f64>| {
            d.x * d.x * v[0] + d.y * d.y * v[1] + 2.0 * d.x * d.y * v[2]
        };
        let mat =
            nalgebra::Matrix2::new(proj(&sa, &t), proj(&sb, &t), proj(&sa, &n), proj(&sb, &n));
        if let Some(inv) = mat.try_inverse() {
            let ab = inv * Vector2::new(e_fs, 0.0);
            model.mech.a[i] = ab[0];
            model.mech.b[i] = ab[1];
            changed += 1;
        }
    }
    if std::env::var("DBG").is_ok() {
        println!("free-surface constants on {changed} particles");
    }
}

/// The cantilever of `cantilever_scene` with random particles of seed `seed`.
fn random_cantilever(h: f64, length: f64, seed: u64) -> sppm::scene::Scene {
    let c = 3.0 * L0;
    let text = format!(
        "name = \"cantilever\"\nseed = {seed}\n[body]\nshape = \"rectangle\"\nwidth = {}\nheight = {h}\norigin = [{}, 0.0]\n[discretisation]\nlattice = \"random\"\nspacing = {L0}\n[material]\nE = {E}\nnu = {NU}\nrho = 2400.0\nthickness = {THICKNESS}\nplane = \"stress\"\n[[groups]]\nname = \"root\"\nselect = {{ by = \"box\", min = [{}, -1.0], max = [0.0, {}] }}\nfix = [\"x\", \"y\"]\n",
        length + c,
        -c,
        -c - 1.0,
        h + 1.0
    );
    sppm::scene::Scene::from_toml_str(&text, &[]).unwrap()
}

fn run(h: f64, rot: f64, off: [f64; 2], surface: &'static str, correct: bool, rings: usize) -> f64 {
    let length = 10.0 * h;
    if let Ok(seed) = std::env::var("RANDOM") {
        let mut model = prepare_model(
            &random_cantilever(h, length, seed.parse().unwrap()),
            RandomPlane::default(),
        )
        .unwrap();
        if std::env::var("FS").is_ok() {
            free_surface_constants(&mut model, h, length);
        }
        return solve_model(model, h, length, correct, rings, None);
    }
    let p = Placement {
        spacing: L0,
        rotation_deg: rot,
        offset: [off[0] * L0, off[1] * L0],
        surface,
    };
    let mut model = prepare_model(&cantilever_scene(h, length, &p).unwrap(), Hexagonal).unwrap();
    if let Ok(k) = std::env::var("CENTROID") {
        centroid_shift(&mut model, h, length, k.parse().unwrap());
    }
    if std::env::var("FS").is_ok() {
        free_surface_constants(&mut model, h, length);
    }
    let ghosts = std::env::var("GHOST")
        .ok()
        .map(|v| Ghosts::new(&model, h, length, v == "traction"));
    solve_model(model, h, length, correct, rings, ghosts)
}

fn solve_model<const K: usize>(
    model: Model<K, 2>,
    h: f64,
    length: f64,
    correct: bool,
    rings: usize,
    ghosts: Option<Ghosts>,
) -> f64 {
    let pen = *PEN.lock().unwrap();
    let x0 = &model.particles.x0;
    let n = x0.len();
    let nb = &model.particles.neighbours;
    let mut op = LinearOperator::new(&model.mech, x0);
    // free dof numbering
    let mut map = vec![usize::MAX; 2 * n];
    let mut m = 0;
    for i in 0..n {
        for c in 0..2 {
            if !model.constrained[i][c] {
                map[2 * i + c] = m;
                m += 1;
            }
        }
    }
    if let Some(g) = &ghosts {
        if std::env::var("DBG").is_ok() {
            let ur: Vec<Vector2<f64>> = (0..n)
                .map(|i| Vector2::new(((i * 37) % 11) as f64 * 1e-6, ((i * 53) % 7) as f64 * 1e-6))
                .collect();
            let mut f1 = vec![Vector2::zeros(); n];
            let mut f2 = vec![Vector2::zeros(); n];
            g.forces(&ur, &mut f1);
            op.internal_forces(&ur, &mut f2);
            let mut worst: f64 = 0.0;
            let mut scale: f64 = 0.0;
            for i in 0..n {
                let inner = (0..6).all(|k| g.stencil[i][k].is_ok())
                    && (0..6).all(|k| match g.stencil[i][k] {
                        Ok(j) => (0..6).all(|m| g.stencil[j][m].is_ok()),
                        Err(_) => false,
                    });
                if inner {
                    worst = worst.max((f1[i] - f2[i]).norm());
                    scale = scale.max(f2[i].norm());
                }
            }
            println!(
                "ghost force check: interior worst {worst:.3e} of {scale:.3e}; ghosts {}",
                g.ghost.len()
            );
            let ua: Vec<Vector2<f64>> = x0
                .iter()
                .map(|x| affine(&Vector3::new(1e-4, -NU * 1e-4, 0.0), x))
                .collect();
            g.forces(&ua, &mut f1);
            let mut w2 = (0.0, 0);
            for i in 0..n {
                if x0[i].x > 4.0 * L0 && x0[i].x < length - 4.0 * L0 && f1[i].norm() > w2.0 {
                    w2 = (f1[i].norm(), i);
                }
            }
            let kap = 1e-2;
            let ub: Vec<Vector2<f64>> = x0
                .iter()
                .map(|x| {
                    let yc = x.y - 0.5 * h;
                    Vector2::new(
                        -kap * x.x * yc,
                        0.5 * kap * x.x * x.x + 0.5 * NU * kap * yc * yc,
                    )
                })
                .collect();
            let mut fb = vec![Vector2::zeros(); n];
            g.forces(&ub, &mut fb);
            let mut fb2 = vec![Vector2::zeros(); n];
            op.internal_forces(&ub, &mut fb2);
            let (mut wb, mut wb2, mut wi) = ((0.0, 0), 0.0f64, 0.0f64);
            for i in 0..n {
                if x0[i].x > 4.0 * L0 && x0[i].x < length - 4.0 * L0 {
                    if fb[i].norm() > wb.0 {
                        wb = (fb[i].norm(), i);
                    }
                    wb2 = wb2.max(fb2[i].norm());
                    if x0[i].y > 2.0 * L0 && x0[i].y < h - 2.0 * L0 {
                        wi = wi.max(fb[i].norm());
                    }
                }
            }
            println!("bending patch: ghosts worst {:.3e} at {:?}, interior {:.3e}; untreated worst {:.3e}; E·κ·L0·t·L0 = {:.3e}", wb.0, x0[wb.1], wi, wb2, E * kap * L0 * THICKNESS * L0);
            println!(
                "uniaxial patch: worst {:.3e} at {:?} normal {:?}",
                w2.0, x0[w2.1], g.fit[w2.1].1
            );
        }
    }
    let mut trips: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut u = vec![Vector2::zeros(); n];
    let mut f = vec![Vector2::zeros(); n];
    for j in 0..2 * n {
        if map[j] == usize::MAX {
            continue;
        }
        u[j / 2][j % 2] = 1.0;
        match &ghosts {
            Some(g) => g.forces(&u, &mut f),
            None => op.internal_forces(&u, &mut f),
        }
        u[j / 2][j % 2] = 0.0;
        for (r, fr) in f.iter().enumerate() {
            for c in 0..2 {
                let v = fr[c];
                if v != 0.0 && map[2 * r + c] != usize::MAX {
                    trips.push(Triplet::new(map[2 * r + c], map[j], -v));
                }
            }
        }
    }
    if std::env::var("BAL").is_ok() {
        bond_balance(&model, &mut op, h, length, &map, &mut trips);
    }
    let split = trips.len();
    if correct || pen > 0.0 {
        let c3 = 3.0 * L0;
        let shape = Shape2::Rectangle {
            origin: Vector2::new(-c3, 0.0),
            width: length + c3,
            height: h,
        };
        let cells = clipped_cells(x0, &shape).unwrap();
        let (xl, xh, yl, yh) = (-c3, length, 0.0, h);
        let tol = 1e-9 * L0;
        // G_i per strain
        let mut g = vec![Matrix2x3::<f64>::zeros(); n];
        for s in 0..3 {
            let mut e = Vector3::zeros();
            e[s] = 1.0;
            let ua: Vec<Vector2<f64>> = x0.iter().map(|x| affine(&e, x)).collect();
            op.internal_forces(&ua, &mut f);
            for i in 0..n {
                g[i].set_column(s, &f[i]);
            }
        }
        let mut corrected = 0;
        for i in 0..n {
            let poly = &cells[i].0;
            let mut a = Vector2::zeros();
            for k in 0..poly.len() {
                let (v0, v1) = (poly[k], poly[(k + 1) % poly.len()]);
                let mid = 0.5 * (v0 + v1);
                let on = (mid.x - xl).abs() < tol
                    || (mid.x - xh).abs() < tol
                    || (mid.y - yl).abs() < tol
                    || (mid.y - yh).abs() < tol;
                if on {
                    let d = v1 - v0;
                    a += Vector2::new(d.y, -d.x) * THICKNESS;
                }
            }
            let mut t = Matrix2x3::zeros();
            for s in 0..3 {
                let mut e = Vector3::zeros();
                e[s] = 1.0;
                let sg = sigma(&e);
                t.set_column(
                    s,
                    &-Vector2::new(sg[0] * a.x + sg[2] * a.y, sg[2] * a.x + sg[1] * a.y),
                );
            }
            let mm = g[i] - t;
            if pen > 0.0 {
                if a.norm() == 0.0 && nb[i].iter().all(|&j| j != NONE) {
                    continue;
                }
                // penalty ½k|u_i − fit_i|², fit = affine fit over the 1..rings neighbours of i
                let mut patch = vec![i];
                let mut front = vec![i];
                for _ in 0..rings {
                    let mut next = Vec::new();
                    for &q in &front {
                        for &j in &nb[q] {
                            if j != NONE && !patch.contains(&(j as usize)) {
                                patch.push(j as usize);
                                next.push(j as usize);
                            }
                        }
                    }
                    front = next;
                }
                let others = &patch[1..];
                let quadp = QUAD.load(std::sync::atomic::Ordering::Relaxed);
                let basis = |d: Vector2<f64>| -> nalgebra::DVector<f64> {
                    if quadp {
                        nalgebra::DVector::from_vec(vec![
                            1.0,
                            d.x,
                            d.y,
                            d.x * d.x,
                            d.x * d.y,
                            d.y * d.y,
                        ])
                    } else {
                        nalgebra::DVector::from_vec(vec![1.0, d.x, d.y])
                    }
                };
                let nbs = if quadp { 6 } else { 3 };
                let mut nm = nalgebra::DMatrix::<f64>::zeros(nbs, nbs);
                for &k in others {
                    let r = basis((x0[k] - x0[i]) / L0);
                    nm += &r * r.transpose();
                }
                let ev = nm.clone().symmetric_eigen().eigenvalues;
                let rc: f64 = std::env::var("RCOND")
                    .map(|v| v.parse().unwrap())
                    .unwrap_or(1e-3);
                if ev.min() < rc * ev.max() {
                    continue;
                }
                let Some(ni) = nm.try_inverse() else { continue };
                let mut w: Vec<(usize, f64)> = vec![(i, 1.0)];
                for &k in others {
                    w.push((k, -(&ni * basis((x0[k] - x0[i]) / L0))[0]));
                }
                let wmax: f64 = std::env::var("WMAX")
                    .map(|v| v.parse().unwrap())
                    .unwrap_or(4.0);
                if w[1..].iter().any(|x| x.1.abs() > wmax) {
                    continue;
                }
                if std::env::var("DBG").is_ok() {
                    let fld = |x: Vector2<f64>| {
                        Vector2::new(-x.y + (x.x / h).powi(2) * h, x.x + x.x * x.y / h)
                    };
                    let r: Vector2<f64> = w.iter().map(|&(k, wk)| fld(x0[k]) * wk).sum();
                    if r.norm() > 1e-9 * h {
                        println!("i {i} x {:?} resid {:?} n {}", x0[i], r, w.len());
                    }
                }
                let kk = pen * model.bulk.a / L0;
                for &(k1, w1) in &w {
                    for &(k2, w2) in &w {
                        for c in 0..2 {
                            let (r, cc) = (map[2 * k1 + c], map[2 * k2 + c]);
                            if r != usize::MAX && cc != usize::MAX {
                                trips.push(Triplet::new(r, cc, kk * w1 * w2));
                            }
                        }
                    }
                }
                corrected += 1;
                continue;
            }
            if mm.abs().max() < 1e-6 * g.iter().map(|x| x.abs().max()).fold(0.0, f64::max) {
                continue;
            }
            corrected += 1;
            if std::env::var("PATCH").is_ok() && (i == 1221 || i == 357) {
                let e = Vector3::new(1.0, -NU, 0.0);
                println!(
                    "i {i} a {:?} G e {:?} T e {:?} cell {:?}",
                    a,
                    g[i] * e,
                    t * e,
                    poly
                );
            }
            // patch: particles within `rings` bonds
            let mut patch = vec![i];
            let mut front = vec![i];
            for _ in 0..rings {
                let mut next = Vec::new();
                for &q in &front {
                    for &j in &nb[q] {
                        if j != NONE && !patch.contains(&(j as usize)) {
                            patch.push(j as usize);
                            next.push(j as usize);
                        }
                    }
                }
                front = next;
            }
            let quad = QUAD.load(std::sync::atomic::Ordering::Relaxed);
            let basis = |d: Vector2<f64>| -> nalgebra::DVector<f64> {
                let s = d / L0;
                if quad {
                    nalgebra::DVector::from_vec(vec![
                        1.0,
                        s.x,
                        s.y,
                        s.x * s.x,
                        s.x * s.y,
                        s.y * s.y,
                    ])
                } else {
                    nalgebra::DVector::from_vec(vec![1.0, s.x, s.y])
                }
            };
            let nb_ = basis(Vector2::zeros()).len();
            let mut nmat = nalgebra::DMatrix::<f64>::zeros(nb_, nb_);
            for &k in &patch {
                let r = basis(x0[k] - x0[i]);
                nmat += &r * r.transpose();
            }
            let ninvd = nmat.try_inverse().unwrap();
            let coef = |k: usize| -> Vector3<f64> {
                let c = &ninvd * basis(x0[k] - x0[i]);
                Vector3::new(c[0], c[1] / L0, c[2] / L0)
            };
            if std::env::var("PATCH").is_ok() && (i == 1221 || i == 357) {
                let e = Vector3::new(1.0, -NU, 0.0);
                let mut ei = Vector3::zeros();
                for &k in &patch {
                    let d = x0[k] - x0[i];
                    let _ = d;
                    let pk = coef(k);
                    let b = nalgebra::Matrix3x2::new(pk[1], 0.0, 0.0, pk[2], pk[2], pk[1]);
                    ei += b * affine(&e, &x0[k]);
                }
                println!("patch {} eps_i {:?} mm*eps {:?}", patch.len(), ei, mm * ei);
            }
            for &k in &patch {
                let pk = coef(k);
                // B_ik: strain (3) from u_k (2)
                let b = nalgebra::Matrix3x2::new(pk[1], 0.0, 0.0, pk[2], pk[2], pk[1]);
                let kc = mm * b; // 2×2: f_i = −kc·u_k → K += kc
                for r in 0..2 {
                    for c in 0..2 {
                        let (ri, ci) = (map[2 * i + r], map[2 * k + c]);
                        if ri != usize::MAX && ci != usize::MAX {
                            trips.push(Triplet::new(ri, ci, kc[(r, c)]));
                        }
                    }
                }
            }
        }
        let _ = corrected;
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &trips).unwrap();
    if std::env::var("PATCH").is_ok() {
        // K_total·u_aff on the free dofs against T·ε: (K u)_i = −f_i = −T_i ε → K u + T ε = 0
        let e = Vector3::new(1.0, -NU, 0.0);
        let mut ua = Mat::<f64>::zeros(m, 1);
        for i in 0..n {
            let v = affine(&e, &x0[i]);
            for c in 0..2 {
                if map[2 * i + c] != usize::MAX {
                    ua[(map[2 * i + c], 0)] = v[c];
                }
            }
        }
        let mut ku = Mat::<f64>::zeros(m, 1);
        for t in &trips {
            ku[(t.row, 0)] += t.val * ua[(t.col, 0)];
        }
        let ku2 = &a * &ua;
        let d = (0..m)
            .map(|r| (ku[(r, 0)] - ku2[(r, 0)]).abs())
            .fold(0.0, f64::max);
        println!("product check {d:.3e}");
        let mx = (0..m).map(|r| ku[(r, 0)].abs()).fold(0.0, f64::max);
        let mut worst = (0.0, 0);
        for i in 0..n {
            for c in 0..2 {
                let r = map[2 * i + c];
                let inner = x0[i].x > 4.0 * L0 && x0[i].x < length - 3.0 * L0;
                if inner && r != usize::MAX && ku[(r, 0)].abs() > worst.0 {
                    worst = (ku[(r, 0)].abs(), i);
                }
            }
        }
        {
            let i = worst.1;
            let uf: Vec<Vector2<f64>> = x0.iter().map(|x| affine(&e, x)).collect();
            let mut ff = vec![Vector2::zeros(); n];
            op.internal_forces(&uf, &mut ff);
            println!(
                "direct f_i {:?}  K row {:?} {:?}",
                ff[i],
                ku[(map[2 * i], 0)],
                ku[(map[2 * i + 1], 0)]
            );
            // columns touching row i
            let mut cols: Vec<(usize, f64)> = trips
                .iter()
                .filter(|t| t.row == map[2 * i + 1])
                .map(|t| (t.col, t.val))
                .collect();
            cols.sort_by_key(|c| c.0);
            let inv: std::collections::HashMap<usize, usize> = (0..2 * n)
                .filter(|&d| map[d] != usize::MAX)
                .map(|d| (map[d], d))
                .collect();
            for (c, v) in cols {
                let d = inv[&c];
                println!("  col p{} c{} x {:?} val {v:.4e}", d / 2, d % 2, x0[d / 2]);
            }
        }
        println!(
            "patch: max |K u_aff| {mx:.3e}, inner worst {:.3e} at particle {} x {:?}",
            worst.0, worst.1, x0[worst.1]
        );
    }
    if std::env::var("OMEGA").is_ok() {
        // ω_max² of M⁻¹K over the free dofs by power iteration
        let mut inv_m = vec![0.0; m];
        for i in 0..n {
            for c in 0..2 {
                if map[2 * i + c] != usize::MAX {
                    inv_m[map[2 * i + c]] = 1.0 / model.mech.mass[i];
                }
            }
        }
        let mut v = Mat::<f64>::from_fn(m, 1, |r, _| 1.0 + ((r * 7919) % 13) as f64 * 0.1);
        let mut lam = 0.0;
        for _ in 0..600 {
            let kv = &a * &v;
            let w = Mat::<f64>::from_fn(m, 1, |r, _| kv[(r, 0)] * inv_m[r]);
            let nv = (0..m).map(|r| v[(r, 0)] * v[(r, 0)]).sum::<f64>().sqrt();
            let nw = (0..m).map(|r| w[(r, 0)] * w[(r, 0)]).sum::<f64>().sqrt();
            lam = nw / nv;
            v = Mat::<f64>::from_fn(m, 1, |r, _| w[(r, 0)] / nw);
        }
        println!("omega_max {:.5e}", lam.sqrt());
    }
    if std::env::var("DYN").is_ok() {
        dynamic_check(&trips, split, m, &map, &model.mech.mass, n);
    }
    let lu = a.sp_lu().unwrap();
    // tip load as in cantilever_stiffness
    let vol = &model.particles.volume;
    let tip: Vec<usize> = (0..n).filter(|&i| x0[i].x >= length - 1.01 * L0).collect();
    let vt: f64 = tip.iter().map(|&i| vol[i]).sum();
    let load = 1000.0;
    let mut rhs = Mat::<f64>::zeros(m, 1);
    for &i in &tip {
        rhs[(map[2 * i + 1], 0)] = load * vol[i] / vt;
    }
    if std::env::var("AXIAL").is_ok() {
        let mut rx = Mat::<f64>::zeros(m, 1);
        for &i in &tip {
            rx[(map[2 * i], 0)] = load * vol[i] / vt;
        }
        let sx = lu.solve(&rx);
        let dx = tip
            .iter()
            .map(|&i| sx[(map[2 * i], 0)] * vol[i] / vt)
            .sum::<f64>();
        let arm = tip.iter().map(|&i| x0[i].x * vol[i]).sum::<f64>() / vt;
        println!(
            "axial: EA/L theory / measured = {:.4}",
            load * arm / (E * THICKNESS * h) / dx
        );
    }
    let sol = lu.solve(&rhs);
    if std::env::var("DBG").is_ok() {
        let r = &a * &sol;
        let res = (0..m)
            .map(|q| (r[(q, 0)] - rhs[(q, 0)]).powi(2))
            .sum::<f64>()
            .sqrt();
        let umax = (0..m).map(|q| sol[(q, 0)].abs()).fold(0.0, f64::max);
        println!("solve residual {res:.3e} (load 1000), max |u| {umax:.3e}");
    }
    let delta = tip
        .iter()
        .map(|&i| sol[(map[2 * i + 1], 0)] * load * vol[i] / vt)
        .sum::<f64>()
        / load;
    let arm = tip.iter().map(|&i| x0[i].x * vol[i]).sum::<f64>() / vt;
    let inertia = THICKNESS * h.powi(3) / 12.0;
    let shear = E / (2.0 * (1.0 + NU));
    let theory =
        load * arm.powi(3) / (3.0 * E * inertia) + load * arm / (5.0 / 6.0 * shear * THICKNESS * h);
    100.0 * (theory / delta - 1.0)
}

fn main() {
    if std::env::var("PATCH").is_ok() {
        for rot in [0.0, 15.0] {
            let r = run(10.0 * L0, rot, [0.0, 0.0], "voronoi_fit", true, 2);
            println!("{rot}: {r}");
        }
        return;
    }
    let offsets: Vec<[f64; 2]> = std::env::var("OFFS")
        .map(|v| {
            let x: Vec<f64> = v.split(',').map(|x| x.parse().unwrap()).collect();
            x.chunks(2).map(|c| [c[0], c[1]]).collect()
        })
        .unwrap_or(vec![[0.0, 0.0], [0.37, 0.61], [0.83, 0.12]]);
    let rots: Vec<f64> = std::env::var("ROTS")
        .map(|v| v.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(vec![0.0, 15.0, 30.0]);
    if std::env::var("CORRECT").is_ok() {
        // treatment 1: base, affine fit (voronoi_fit, voronoi), quadratic fit (the same)
        use std::sync::atomic::Ordering::Relaxed;
        for hl in [10.0, 20.0] {
            for rot in [0.0, 15.0, 30.0] {
                for &off in &offsets {
                    let h = hl * L0;
                    QUAD.store(false, Relaxed);
                    let base = run(h, rot, off, "voronoi_fit", false, 2);
                    let lf = run(h, rot, off, "voronoi_fit", true, 2);
                    let lv = run(h, rot, off, "voronoi", true, 2);
                    QUAD.store(true, Relaxed);
                    let qf = run(h, rot, off, "voronoi_fit", true, 2);
                    let qv = run(h, rot, off, "voronoi", true, 2);
                    println!(
                        "| {hl} | {rot}° | ({}, {}) | {base:+.2} | {lf:+.2} | {lv:+.2} | {qf:+.2} | {qv:+.2} |",
                        off[0], off[1]
                    );
                }
            }
        }
        return;
    }
    let kappas: Vec<f64> = std::env::var("KAPPAS")
        .map(|v| v.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(vec![0.1, 1.0, 10.0]);
    let rings: usize = std::env::var("RINGS")
        .map(|v| v.parse().unwrap())
        .unwrap_or(1);
    let hs: Vec<f64> = std::env::var("HS")
        .map(|v| v.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(vec![10.0]);
    QUAD.store(
        std::env::var("QUAD").is_ok(),
        std::sync::atomic::Ordering::Relaxed,
    );
    for &hl in &hs {
        for &rot in &rots {
            for &off in &offsets {
                let h = hl * L0;
                *PEN.lock().unwrap() = 0.0;
                let surf: &'static str = if std::env::var("VOR").is_ok() {
                    "voronoi"
                } else {
                    "voronoi_fit"
                };
                let base = run(h, rot, off, surf, false, 2);
                let mut row = format!("| {hl} | {rot}° | ({}, {}) | {base:+.2} |", off[0], off[1]);
                for &k in &kappas {
                    *PEN.lock().unwrap() = k;
                    let r = run(h, rot, off, surf, false, rings);
                    row += &format!(" {r:+.2} |");
                }
                println!("{row}");
            }
        }
    }
}
