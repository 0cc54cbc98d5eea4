//! Probe: a cantilever with a patch-consistent force correction on its boundary particles.
//! For each particle i, G_i maps a homogeneous strain to the bond force on i and
//! T_i = −σ(ε)·a_i is the continuum's force on i's clipped cell (a_i the outward area
//! vector of the cell's free faces). The correction −(G_i − T_i)·ε_i, with ε_i the affine
//! fit over i's two rings, makes every homogeneous strain load every particle as the
//! continuum does (`CORRECT=1`). By default: the quadratic-consistent stabilisation energy
//! (`KAPPAS=k1,k2,..`, `RINGS=2`, `QUAD=1` for the quadratic fit, `HS=10,20` depths in
//! spacings, `VOR=1` for `voronoi` constants, `FS=1` for the free-surface constants).
//! `OMEGA=1` prints ω_max of M⁻¹K (power iteration) before each solve.
//! docs/surfaces.md, "Treatments of the surface relaxation measured".

use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{Matrix2x3, Vector2, Vector3};
use sppm::discretise::voronoi::clipped_cells;
use sppm::discretise::NONE;
use sppm::geometry::Shape2;
use sppm::run::{prepare_model, Hexagonal};
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

/// Constants of each single-face boundary particle that make its own stress exact in the
/// free-surface state (uniaxial stress along the face): σ_tt = E·ε, σ_nn = 0.
fn free_surface_constants(model: &mut sppm::run::Model, h: f64, length: f64) {
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
        let bonds: Vec<(Vector2<f64>, f64)> = (0..6)
            .filter(|&k| model.particles.neighbours[i][k] != NONE)
            .map(|k| {
                let j = model.particles.neighbours[i][k] as usize;
                ((x0[j] - x0[i]).normalize(), model.particles.l0[i][k])
            })
            .collect();
        let (am, bm) =
            sppm::model::micro_modulus::stiffness_basis(&bonds, model.particles.volume[i]);
        // ε = t⊗t − ν n⊗n in [εxx, εyy, γ]
        let epsm = t * t.transpose() - NU * n * n.transpose();
        let eps = Vector3::new(epsm[(0, 0)], epsm[(1, 1)], 2.0 * epsm[(0, 1)]);
        let (sa, sb) = (am * eps, bm * eps);
        let proj = |v: &Vector3<f64>, d: &Vector2<f64>| {
            d.x * d.x * v[0] + d.y * d.y * v[1] + 2.0 * d.x * d.y * v[2]
        };
        let mat =
            nalgebra::Matrix2::new(proj(&sa, &t), proj(&sb, &t), proj(&sa, &n), proj(&sb, &n));
        if let Some(inv) = mat.try_inverse() {
            let ab = inv * Vector2::new(E, 0.0);
            model.mech.a[i] = ab[0];
            model.mech.b[i] = ab[1];
            changed += 1;
        }
    }
    if std::env::var("DBG").is_ok() {
        println!("free-surface constants on {changed} particles");
    }
}

fn run(h: f64, rot: f64, off: [f64; 2], surface: &'static str, correct: bool, rings: usize) -> f64 {
    let pen = *PEN.lock().unwrap();
    let length = 10.0 * h;
    let p = Placement {
        spacing: L0,
        rotation_deg: rot,
        offset: [off[0] * L0, off[1] * L0],
        surface,
    };
    let mut model = prepare_model(&cantilever_scene(h, length, &p).unwrap(), Hexagonal).unwrap();
    if std::env::var("FS").is_ok() {
        free_surface_constants(&mut model, h, length);
    }
    let model = model;
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
    let mut trips: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut u = vec![Vector2::zeros(); n];
    let mut f = vec![Vector2::zeros(); n];
    for j in 0..2 * n {
        if map[j] == usize::MAX {
            continue;
        }
        u[j / 2][j % 2] = 1.0;
        op.internal_forces(&u, &mut f);
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
    let sol = lu.solve(&rhs);
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
    let offsets = [[0.0, 0.0], [0.37, 0.61], [0.83, 0.12]];
    if std::env::var("CORRECT").is_ok() {
        // treatment 1: base, affine fit (voronoi_fit, voronoi), quadratic fit (the same)
        use std::sync::atomic::Ordering::Relaxed;
        for hl in [10.0, 20.0] {
            for rot in [0.0, 15.0, 30.0] {
                for off in offsets {
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
        for rot in [0.0, 15.0, 30.0] {
            for off in offsets {
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
