use super::*;
use crate::model::micro_modulus::{self, fcc, fcc_volume, fit_fcc, hexagonal, FccBond};
use crate::model::stress::StressSum;
use nalgebra::{Quaternion, UnitQuaternion, Vector2};
use rand::rngs::ChaCha20Rng;
use rand::{Rng, SeedableRng};

type D2 = Dim<2>;
type D3 = Dim<3>;

/// Verbatim copies of the 2D functions before the refactor, the reference for the
/// bit-identity tests.
mod reference {
    use crate::scene::Plane;
    use nalgebra::{Matrix2, Matrix3, SMatrix, Vector2, Vector3};

    pub fn strain_projector(n: &Vector2<f64>) -> Vector3<f64> {
        Vector3::new(n.x * n.x, n.y * n.y, n.x * n.y)
    }

    pub fn strain_fit<const K: usize>(dirs: &[Option<Vector2<f64>>; K]) -> [[f64; K]; 3] {
        let mut n = SMatrix::<f64, K, 3>::zeros();
        for (k, d) in dirs.iter().enumerate() {
            if let Some(d) = d {
                let v = strain_projector(d);
                for c in 0..3 {
                    n[(k, c)] = v[c];
                }
            }
        }
        let ntn: Matrix3<f64> = n.transpose() * n;
        let pinv = ntn
            .pseudo_inverse(1e-10 * ntn.norm().max(f64::MIN_POSITIVE))
            .unwrap_or_else(|_| Matrix3::zeros());
        let p = pinv * n.transpose();
        let mut out = [[0.0; K]; 3];
        for (c, row) in out.iter_mut().enumerate() {
            for (k, x) in row.iter_mut().enumerate() {
                *x = p[(c, k)];
            }
        }
        out
    }

    pub fn strain_tensor<const K: usize>(p: &[[f64; K]; 3], s: &[f64; K]) -> Matrix2<f64> {
        let mut e = [0.0; 3];
        for c in 0..3 {
            let mut acc = 0.0;
            for k in 0..K {
                acc += p[c][k] * s[k];
            }
            e[c] = acc;
        }
        Matrix2::new(e[0], 0.5 * e[2], 0.5 * e[2], e[1])
    }

    pub fn principal_values(t: &Matrix2<f64>) -> (f64, f64) {
        let (a, b, c) = (t[(0, 0)], t[(0, 1)], t[(1, 1)]);
        let m = 0.5 * (a + c);
        let r = (0.25 * (a - c) * (a - c) + b * b).sqrt();
        (m + r, m - r)
    }

    pub fn principal_strains(e: &Matrix2<f64>, nu: f64, plane: Plane) -> (f64, f64, f64) {
        let (e1, e2) = principal_values(e);
        let e3 = match plane {
            Plane::Strain => 0.0,
            Plane::Stress => -nu / (1.0 - nu) * (e1 + e2),
        };
        (e1, e2, e3)
    }

    pub fn out_of_plane_stress(sxx: f64, syy: f64, nu: f64, plane: Plane) -> f64 {
        match plane {
            Plane::Stress => 0.0,
            Plane::Strain => nu * (sxx + syy),
        }
    }

    pub fn equivalent_stress(s: &Matrix2<f64>, nu: f64, plane: Plane) -> f64 {
        let (sx, sy, t) = (s[(0, 0)], s[(1, 1)], s[(0, 1)]);
        let sz = out_of_plane_stress(sx, sy, nu, plane);
        (0.5 * ((sx - sy).powi(2) + (sy - sz).powi(2) + (sz - sx).powi(2)) + 3.0 * t * t).sqrt()
    }

    pub fn von_mises(s: &Matrix2<f64>) -> f64 {
        let (sx, sy, txy) = (s[(0, 0)], s[(1, 1)], s[(0, 1)]);
        (sx * sx - sx * sy + sy * sy + 3.0 * txy * txy).sqrt()
    }

    /// The criteria of the damage kernel before the refactor.
    pub fn extremes(s: &Matrix2<f64>, nu: f64, plane: Plane) -> (f64, f64) {
        let (s1, s2) = principal_values(s);
        let s33 = out_of_plane_stress(s1, s2, nu, plane);
        (s1.max(s33), s2.min(s33))
    }

    /// D·ε of the damage kernel before the refactor.
    pub fn stress_of_strain(d: &Matrix3<f64>, eps_d: &Matrix2<f64>) -> Matrix2<f64> {
        let sv = d * Vector3::new(eps_d[(0, 0)], eps_d[(1, 1)], 2.0 * eps_d[(0, 1)]);
        Matrix2::new(sv[0], sv[2], sv[2], sv[1])
    }

    pub fn elasticity_matrix(e: f64, nu: f64, plane: Plane) -> Matrix3<f64> {
        match plane {
            Plane::Stress => {
                let c = e / (1.0 - nu * nu);
                Matrix3::new(
                    c,
                    c * nu,
                    0.0,
                    c * nu,
                    c,
                    0.0,
                    0.0,
                    0.0,
                    c * (1.0 - nu) / 2.0,
                )
            }
            Plane::Strain => {
                let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
                Matrix3::new(
                    c * (1.0 - nu),
                    c * nu,
                    0.0,
                    c * nu,
                    c * (1.0 - nu),
                    0.0,
                    0.0,
                    0.0,
                    c * (1.0 - 2.0 * nu) / 2.0,
                )
            }
        }
    }

    #[derive(Default)]
    pub struct StressSum(pub Matrix2<f64>);
    impl StressSum {
        pub fn add(&mut self, n: &Vector2<f64>, l0: f64, fs: f64) {
            self.0 += n * n.transpose() * (l0 * fs);
        }
        pub fn finish(self, volume: f64) -> Matrix2<f64> {
            self.0 / (2.0 * volume)
        }
    }

    pub fn stiffness_basis(
        bonds: &[(Vector2<f64>, f64)],
        volume: f64,
    ) -> (Matrix3<f64>, Matrix3<f64>) {
        let mut a = Matrix3::zeros();
        let mut mv = Vector3::zeros();
        let mut nv = Vector3::zeros();
        for (n, l0) in bonds {
            let v = strain_projector(n);
            let w = l0 / (2.0 * volume);
            a += v * v.transpose() * w;
            mv += v * w;
            nv += v;
        }
        (a, mv * nv.transpose())
    }

    /// (a, b, residual).
    pub fn fit(
        bonds: &[(Vector2<f64>, f64)],
        volume: f64,
        d: &Matrix3<f64>,
    ) -> Option<(f64, f64, f64)> {
        let (a_m, b_m) = stiffness_basis(bonds, volume);
        let dot = |x: &Matrix3<f64>, y: &Matrix3<f64>| x.component_mul(y).sum();
        let g = nalgebra::Matrix2::new(
            dot(&a_m, &a_m),
            dot(&a_m, &b_m),
            dot(&b_m, &a_m),
            dot(&b_m, &b_m),
        );
        let r = Vector2::new(dot(&a_m, d), dot(&b_m, d));
        if a_m.determinant().abs() <= 1e-12 * a_m.norm().powi(3) {
            return None;
        }
        let sol = g.try_inverse()? * r;
        let (a, b) = (sol.x, sol.y);
        if !(a > 0.0 && a.is_finite() && b.is_finite()) {
            return None;
        }
        let residual = (a_m * a + b_m * b - d).norm() / d.norm();
        Some((a, b, residual))
    }
}

/// Uniform in [0, 1).
fn uni(r: &mut ChaCha20Rng) -> f64 {
    (r.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Uniform in [lo, hi).
fn range(r: &mut ChaCha20Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * uni(r)
}

/// A scale 10^U(−e, e).
fn scale(r: &mut ChaCha20Rng, e: f64) -> f64 {
    10f64.powf(range(r, -e, e))
}

fn unit2(r: &mut ChaCha20Rng) -> Vector2<f64> {
    let a = range(r, 0.0, std::f64::consts::TAU);
    Vector2::new(a.cos(), a.sin())
}

fn unit3(r: &mut ChaCha20Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            range(r, -1.0, 1.0),
            range(r, -1.0, 1.0),
            range(r, -1.0, 1.0),
        );
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

fn rotation(r: &mut ChaCha20Rng) -> Matrix3<f64> {
    let q = Quaternion::new(
        range(r, -1.0, 1.0),
        range(r, -1.0, 1.0),
        range(r, -1.0, 1.0),
        range(r, -1.0, 1.0),
    );
    *UnitQuaternion::from_quaternion(q)
        .to_rotation_matrix()
        .matrix()
}

fn sym2(r: &mut ChaCha20Rng, s: f64) -> Matrix2<f64> {
    let (a, b, c) = (range(r, -s, s), range(r, -s, s), range(r, -s, s));
    Matrix2::new(a, b, b, c)
}

fn plane(r: &mut ChaCha20Rng) -> Plane {
    if r.next_u64().is_multiple_of(2) {
        Plane::Stress
    } else {
        Plane::Strain
    }
}

// -- 2D: the generic path is bit-identical to the old code --------------------------

#[test]
fn two_d_strain_fit_and_tensor_are_bit_identical() {
    let mut r = ChaCha20Rng::seed_from_u64(1);
    for case in 0..2000 {
        let mut dirs = [None; 6];
        let rot = range(&mut r, 0.0, 1.0);
        for (k, d) in dirs.iter_mut().enumerate() {
            // hexagonal slots (some missing), or random directions
            if r.next_u64() % 5 != 0 {
                *d = Some(if case % 2 == 0 {
                    let a = rot + k as f64 * std::f64::consts::PI / 3.0;
                    Vector2::new(a.cos(), a.sin())
                } else {
                    unit2(&mut r)
                });
            }
        }
        let p = <D2 as Dimension<2>>::strain_fit(&dirs);
        assert_eq!(p, reference::strain_fit(&dirs));
        let sc = scale(&mut r, 6.0);
        let s: [f64; 6] = std::array::from_fn(|_| range(&mut r, -sc, sc));
        let e = reference::strain_tensor(&p, &s);
        assert_eq!(<D2 as Dimension<2>>::strain_tensor(&p, &s), e);
    }
}

#[test]
fn two_d_principal_and_equivalent_values_are_bit_identical() {
    let mut r = ChaCha20Rng::seed_from_u64(2);
    for case in 0..20000 {
        let sc = scale(&mut r, 9.0);
        let mut t = sym2(&mut r, sc);
        if case % 7 == 0 {
            t[(0, 1)] = 0.0;
            t[(1, 0)] = 0.0;
        }
        if case % 11 == 0 {
            t[(1, 1)] = t[(0, 0)];
        }
        let nu = range(&mut r, 0.0, 0.49);
        let pl = plane(&mut r);
        let (p1, p2) = reference::principal_values(&t);
        assert_eq!(<D2 as Dimension<2>>::principal_values(&t), [p1, p2]);
        let ps = reference::principal_strains(&t, nu, pl);
        assert_eq!(<D2 as Dimension<2>>::principal_strains(&t, nu, pl), ps);
        assert_eq!(
            <D2 as Dimension<2>>::principal_stress_extremes(&t, nu, pl),
            reference::extremes(&t, nu, pl)
        );
        let q = reference::equivalent_stress(&t, nu, pl);
        assert_eq!(<D2 as Dimension<2>>::equivalent_stress(&t, nu, pl), q);
        let (sx, sy) = (t[(0, 0)], t[(1, 1)]);
        assert_eq!(
            out_of_plane_stress(sx, sy, nu, pl),
            reference::out_of_plane_stress(sx, sy, nu, pl)
        );
        let vm = reference::von_mises(&t);
        assert_eq!(<D2 as Dimension<2>>::von_mises(&t), vm);
        assert_eq!(
            <D2 as Dimension<2>>::max_principal(&t),
            t.symmetric_eigenvalues().max()
        );
    }
}

#[test]
fn two_d_elasticity_and_stress_are_bit_identical() {
    let mut r = ChaCha20Rng::seed_from_u64(3);
    for _ in 0..5000 {
        let e = range(&mut r, 1e9, 60e9);
        let nu = range(&mut r, 0.0, 0.49);
        let pl = plane(&mut r);
        let d = reference::elasticity_matrix(e, nu, pl);
        assert_eq!(<D2 as Dimension<2>>::elasticity(e, nu, pl), d);
        assert_eq!(micro_modulus::elasticity_matrix(e, nu, pl), d);
        let d = d * range(&mut r, 0.5, 2.0);
        let sc = scale(&mut r, 4.0);
        let eps = sym2(&mut r, sc);
        assert_eq!(
            <D2 as Dimension<2>>::stress_of_strain(&d, &eps),
            reference::stress_of_strain(&d, &eps)
        );
        // (3.18) bond by bond
        let vol = range(&mut r, 1e-6, 1e-4);
        let mut old = reference::StressSum::default();
        let mut new = StressSum::default();
        for _ in 0..6 {
            let (n, l0, fs) = (
                unit2(&mut r),
                range(&mut r, 1e-3, 1e-2),
                range(&mut r, -1e5, 1e5),
            );
            old.add(&n, l0, fs);
            new.add(&n, l0, fs);
        }
        assert_eq!(new.finish(vol), old.finish(vol));
        let n = unit2(&mut r);
        assert_eq!(
            micro_modulus::strain_projector(&n),
            reference::strain_projector(&n)
        );
        assert_eq!(
            <D2 as Dimension<2>>::projector(&n),
            reference::strain_projector(&n)
        );
    }
}

#[test]
fn two_d_stiffness_basis_and_fit_are_bit_identical() {
    let mut r = ChaCha20Rng::seed_from_u64(4);
    let mut fitted = 0;
    for case in 0..5000 {
        let l0 = range(&mut r, 1e-3, 2e-2);
        let vol = 0.5 * 3f64.sqrt() * l0 * l0 * 0.1 * range(&mut r, 0.7, 1.3);
        let rot = range(&mut r, 0.0, 1.0);
        let kept: Vec<usize> = (0..6).filter(|_| r.next_u64() % 4 != 0).collect();
        let bonds: Vec<(Vector2<f64>, f64)> = kept
            .into_iter()
            .map(|k| {
                let n = if case % 2 == 0 {
                    let a = rot + k as f64 * std::f64::consts::PI / 3.0;
                    Vector2::new(a.cos(), a.sin())
                } else {
                    unit2(&mut r)
                };
                (n, l0 * range(&mut r, 0.8, 1.2))
            })
            .collect();
        let want = reference::stiffness_basis(&bonds, vol);
        assert_eq!(<D2 as Dimension<2>>::stiffness_basis(&bonds, vol), want);
        assert_eq!(micro_modulus::stiffness_basis(&bonds, vol), want);
        let d = reference::elasticity_matrix(30e9, range(&mut r, 0.0, 0.45), plane(&mut r));
        let want = reference::fit(&bonds, vol, &d);
        for got in [
            <D2 as Dimension<2>>::fit(&bonds, vol, &d),
            micro_modulus::fit(&bonds, vol, &d),
        ] {
            assert_eq!(got.map(|f| (f.moduli.a, f.moduli.b, f.residual)), want);
        }
        fitted += want.is_some() as usize;
    }
    assert!(fitted > 1000, "{fitted}");
}

// -- 3D principal values -------------------------------------------------------------

/// Asserts and returns the error relative to ‖t‖.
fn check_principal_3(t: &Matrix3<f64>, what: &str) -> f64 {
    let p = principal_values_3(t);
    let mut ev: Vec<f64> = t.symmetric_eigenvalues().iter().copied().collect();
    ev.sort_by(|a, b| b.partial_cmp(a).unwrap());
    let tol = 1e-12 * t.norm();
    assert!(p[0] >= p[1] && p[1] >= p[2], "{what}: not sorted {p:?}");
    for k in 0..3 {
        assert!(
            (p[k] - ev[k]).abs() <= tol,
            "{what}: {p:?} vs {ev:?} (err {:e} of ‖t‖ = {:e})",
            (p[k] - ev[k]).abs() / t.norm(),
            t.norm()
        );
    }
    assert_eq!(<D3 as Dimension<3>>::principal_values(t), p);
    assert_eq!(
        principal_max_3(t).to_bits(),
        p[0].to_bits(),
        "{what}: largest"
    );
    assert_eq!(
        <D3 as Dimension<3>>::principal_strain_max(t, 0.2, Plane::Stress).to_bits(),
        p[0].to_bits()
    );
    (0..3).map(|k| (p[k] - ev[k]).abs()).fold(0.0, f64::max) / t.norm().max(f64::MIN_POSITIVE)
}

#[test]
fn principal_values_3_match_nalgebra() {
    let mut r = ChaCha20Rng::seed_from_u64(5);
    let mut worst: f64 = 0.0;
    check_principal_3(&Matrix3::zeros(), "zero");
    check_principal_3(&Matrix3::identity(), "identity");
    check_principal_3(&(Matrix3::identity() * -3e7), "hydrostatic");
    check_principal_3(
        &Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)),
        "diagonal",
    );
    check_principal_3(
        &Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0),
        "rank-1",
    );
    for case in 0..20000 {
        let sc = scale(&mut r, 10.0);
        let t = match case % 6 {
            // generic symmetric
            0 => {
                let m = Matrix3::from_fn(|_, _| range(&mut r, -sc, sc));
                (m + m.transpose()) * 0.5
            }
            // exactly or nearly repeated eigenvalues in a random frame
            1..=3 => {
                let q = rotation(&mut r);
                let l1 = range(&mut r, -sc, sc);
                let gap = match case % 6 {
                    1 => 0.0,
                    2 => sc * scale(&mut r, 7.0) * 1e-7,
                    _ => sc * 10f64.powf(range(&mut r, -16.0, -3.0)),
                };
                let l3 = if case % 12 < 6 {
                    range(&mut r, -sc, sc)
                } else {
                    l1
                };
                let l = Vector3::new(l1, l1 + gap, l3);
                q * Matrix3::from_diagonal(&l) * q.transpose()
            }
            // large mean stress, small deviator
            4 => {
                let m = Matrix3::from_fn(|_, _| range(&mut r, -sc, sc) * 1e-6);
                (m + m.transpose()) * 0.5 + Matrix3::identity() * range(&mut r, -sc, sc)
            }
            // sparse: some zero entries, some exact symmetry in the diagonal
            _ => {
                let mut m = Matrix3::from_fn(|_, _| {
                    if uni(&mut r) < 0.5 {
                        0.0
                    } else {
                        range(&mut r, -sc, sc)
                    }
                });
                m = (m + m.transpose()) * 0.5;
                if uni(&mut r) < 0.5 {
                    m[(1, 1)] = m[(0, 0)];
                }
                m
            }
        };
        // exactly symmetric input
        let t = Matrix3::from_fn(|i, j| if i >= j { t[(i, j)] } else { t[(j, i)] });
        worst = worst.max(check_principal_3(&t, &format!("case {case}")));
    }
    eprintln!("principal_values_3: worst error {worst:e} of ‖t‖");
}

/// The 3D stress bounds enclose the extremes (so a bound that fails the initiation test
/// settles it) and meet them in uniaxial stress; the 3D effective strain from the
/// invariants is (4.17) of the principal strains.
#[test]
fn stress_bounds_enclose_the_extremes_and_effective_strain_is_invariant() {
    let mut r = ChaCha20Rng::seed_from_u64(11);
    for case in 0..20000 {
        let sc = scale(&mut r, 10.0);
        let q = rotation(&mut r);
        let l = Vector3::new(
            range(&mut r, -sc, sc),
            range(&mut r, -sc, sc),
            range(&mut r, -sc, sc),
        );
        // uniaxial (two zero principal values) in every fourth case
        let l = if case % 4 == 0 {
            Vector3::new(l.x, 0.0, 0.0)
        } else {
            l
        };
        let t = q * Matrix3::from_diagonal(&l) * q.transpose();
        let t = Matrix3::from_fn(|i, j| if i >= j { t[(i, j)] } else { t[(j, i)] });
        let (hi, lo) = <D3 as Dimension<3>>::principal_stress_extremes(&t, 0.2, Plane::Stress);
        let (bh, bl) = <D3 as Dimension<3>>::principal_stress_bounds(&t, 0.2, Plane::Stress);
        assert!(
            bh >= hi && bl <= lo,
            "case {case}: ({bh}, {bl}) against ({hi}, {lo})"
        );
        let tol = 1e-12 * t.norm();
        if case % 4 == 0 {
            // uniaxial σ: the bound on the extreme of σ's sign is σ itself, widened by
            // the round-off allowance (4/3)·1e-12·|σ|
            let got = if l.x > 0.0 { bh } else { bl };
            assert!(
                (got - l.x).abs() <= 3.0 * tol,
                "case {case}: {got} against {}",
                l.x
            );
        }
        let (e1, e2, e3) = <D3 as Dimension<3>>::principal_strains(&t, 0.2, Plane::Stress);
        let want = crate::model::damage::effective_strain(e1, e2, e3);
        let got = <D3 as Dimension<3>>::effective_strain(&t, 0.2, Plane::Stress);
        assert!(
            (got - want).abs() <= tol,
            "case {case}: {got} against {want}"
        );
    }
}

// -- strain fit is exact on affine fields -----------------------------------------------

/// FCC slots with nearest spacing `l0`: 12 nearest directions, then 6 second neighbours
/// (the second neighbours' flag is true).
fn fcc_slots(rot: &Matrix3<f64>, l0: f64) -> [(Vector3<f64>, f64, bool); 18] {
    let mut out = [(Vector3::zeros(), 0.0, false); 18];
    let mut k = 0;
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        for s1 in [1.0, -1.0] {
            for s2 in [1.0, -1.0] {
                let mut v = Vector3::zeros();
                v[i] = s1;
                v[j] = s2;
                out[k] = (rot * v.normalize(), l0, false);
                k += 1;
            }
        }
    }
    for i in 0..3 {
        for s in [1.0, -1.0] {
            let mut v = Vector3::zeros();
            v[i] = s;
            out[k] = (rot * v, 2f64.sqrt() * l0, true);
            k += 1;
        }
    }
    out
}

fn affine_fit_error<const K: usize>(dirs: &[Option<Vector3<f64>>; K], r: &mut ChaCha20Rng) -> f64 {
    let sc = scale(r, 5.0);
    let g = Matrix3::from_fn(|_, _| range(r, -sc, sc));
    let c = Vector3::from_fn(|_, _| range(r, -sc, sc));
    let u = |x: &Vector3<f64>| c + g * x;
    let xi = Vector3::from_fn(|_, _| range(r, -1.0, 1.0)) * 0.01;
    let l0 = 0.01;
    let mut s = [0.0; K];
    for k in 0..K {
        if let Some(n) = dirs[k] {
            let xj = xi + n * l0;
            s[k] = n.dot(&(u(&xj) - u(&xi))) / l0;
        }
    }
    let p = <D3 as Dimension<3>>::strain_fit(dirs);
    let e = <D3 as Dimension<3>>::strain_tensor(&p, &s);
    let want = (g + g.transpose()) * 0.5;
    (e - want).norm() / g.norm()
}

#[test]
fn three_d_strain_fit_is_exact_on_affine_fields() {
    let mut r = ChaCha20Rng::seed_from_u64(6);
    let mut worst: f64 = 0.0;
    for case in 0..600 {
        let rot = if case % 2 == 0 {
            Matrix3::identity()
        } else {
            rotation(&mut r)
        };
        let slots = fcc_slots(&rot, 1.0);
        // the lattice frame decides which slots a surface particle misses
        let frame = fcc_slots(&Matrix3::identity(), 1.0);
        let keep = |k: usize, which: usize| {
            let n = frame[k].0;
            match which {
                0 => true,                     // bulk
                1 => n.z <= 0.0,               // (001) surface
                _ => n.z <= 0.0 && n.x <= 0.0, // edge
            }
        };
        for which in 0..3 {
            let near: [Option<Vector3<f64>>; 12] =
                std::array::from_fn(|k| keep(k, which).then_some(slots[k].0));
            let all: [Option<Vector3<f64>>; 18] =
                std::array::from_fn(|k| keep(k, which).then_some(slots[k].0));
            if which < 2 {
                worst = worst.max(affine_fit_error(&near, &mut r));
            }
            worst = worst.max(affine_fit_error(&all, &mut r));
        }
        // random direction sets, some slots empty
        let random: [Option<Vector3<f64>>; 18] =
            std::array::from_fn(|k| (k < 9 || uni(&mut r) < 0.7).then(|| unit3(&mut r)));
        worst = worst.max(affine_fit_error(&random, &mut r));
    }
    eprintln!("3D affine strain fit: worst error {worst:e} of ‖G‖");
    assert!(worst <= 1e-12, "worst relative error {worst:e}");
}

#[test]
fn two_d_strain_fit_is_exact_on_affine_fields() {
    let mut r = ChaCha20Rng::seed_from_u64(7);
    for case in 0..4000 {
        let sc = scale(&mut r, 5.0);
        let g = Matrix2::from_fn(|_, _| range(&mut r, -sc, sc));
        let rot = range(&mut r, 0.0, 1.0);
        let missing = (r.next_u64() % 7) as usize; // 6: none missing
        let dirs: [Option<Vector2<f64>>; 6] = if case % 2 == 0 {
            // hexagonal slots, rotated, at most one missing (bulk or a straight edge)
            std::array::from_fn(|k| {
                let a = rot + k as f64 * std::f64::consts::PI / 3.0;
                (k != missing).then(|| Vector2::new(a.cos(), a.sin()))
            })
        } else {
            std::array::from_fn(|k| (k < 4 || uni(&mut r) < 0.5).then(|| unit2(&mut r)))
        };
        let s: [f64; 6] = std::array::from_fn(|k| dirs[k].map_or(0.0, |n| n.dot(&(g * n))));
        let p = <D2 as Dimension<2>>::strain_fit(&dirs);
        let e = <D2 as Dimension<2>>::strain_tensor(&p, &s);
        let err = (e - (g + g.transpose()) * 0.5).norm() / g.norm();
        if case % 2 == 0 {
            assert!(err <= 1e-12, "hexagonal: {err:e}");
        } else {
            // random directions can be nearly dependent; the normal equations square
            // the conditioning, measured by the largest projector entry ~ 1/σ_min(N)
            let cond = p.iter().flatten().map(|x| x.abs()).fold(1.0, f64::max);
            assert!(err <= 1e-14 * cond * cond, "{err:e}, cond {cond}");
        }
    }
}

// -- stress of a uniform strain is D·ε ---------------------------------------------------

fn uniform_strain_stress_3(
    bonds: &[FccBond],
    vol: f64,
    m: (f64, f64, f64),
    eps: &Matrix3<f64>,
) -> Matrix3<f64> {
    let (a, b, c) = m;
    let ev = <D3 as Dimension<3>>::strain_to_voigt(eps);
    let s: Vec<f64> = bonds
        .iter()
        .map(|(n, _, _)| Voigt6::projector(n).dot(&ev))
        .collect();
    let theta: f64 = s.iter().sum();
    let mut acc = StressSum::<3>::default();
    for ((n, l0, second), s) in bonds.iter().zip(&s) {
        let modulus = if *second { a + c } else { a };
        acc.add(n, *l0, modulus * s + b * theta);
    }
    acc.finish(vol)
}

#[test]
fn fcc_constants_reproduce_isotropic_elasticity() {
    let mut r = ChaCha20Rng::seed_from_u64(8);
    let (e, l0) = (30e9, 0.01);
    let vol = fcc_volume(l0);
    for nu in [0.0, 0.1, 0.2, 0.25, 1.0 / 3.0, 0.4, 0.45] {
        let m = fcc(e, nu, l0);
        assert!((2.0 * 2f64.sqrt() * (m.a + m.c) - m.a).abs() <= 1e-14 * m.a);
        let d = <D3 as Dimension<3>>::elasticity(e, nu, Plane::Stress);
        for case in 0..50 {
            let rot = if case == 0 {
                Matrix3::identity()
            } else {
                rotation(&mut r)
            };
            let bonds = fcc_slots(&rot, l0);
            let (a_m, b_m, c_m) = micro_modulus::fcc_basis(&bonds, vol);
            let model = a_m * m.a + b_m * m.b + c_m * m.c;
            assert!((model - d).norm() <= 1e-13 * d.norm(), "nu={nu}");
            // the least-squares fit recovers (4.8)
            let f = fit_fcc(&bonds, vol, &d).unwrap();
            assert!(f.residual < 1e-13, "nu={nu} residual {:e}", f.residual);
            for (x, y) in [(f.moduli.a, m.a), (f.moduli.b, m.b), (f.moduli.c, m.c)] {
                assert!((x - y).abs() <= 1e-11 * m.a, "nu={nu}: {x} vs {y}");
            }
            // (3.18) under a uniform strain: σ = D·ε, with (4.8) and with the fit
            for _ in 0..4 {
                let g = Matrix3::from_fn(|_, _| range(&mut r, -1e-4, 1e-4));
                let eps = (g + g.transpose()) * 0.5;
                let want = <D3 as Dimension<3>>::stress_of_strain(&d, &eps);
                for mm in [(m.a, m.b, m.c), (f.moduli.a, f.moduli.b, f.moduli.c)] {
                    let sigma = uniform_strain_stress_3(&bonds, vol, mm, &eps);
                    assert!(
                        (sigma - want).norm() <= 1e-12 * want.norm(),
                        "nu={nu}: {:e}",
                        (sigma - want).norm() / want.norm()
                    );
                }
            }
        }
    }
}

#[test]
fn fcc_surface_particle_fit_is_stiffer_and_nearest_only_needs_no_c() {
    let (e, nu, l0) = (30e9, 0.2, 0.01);
    let vol = fcc_volume(l0);
    let d = <D3 as Dimension<3>>::elasticity(e, nu, Plane::Strain);
    let bulk = fcc(e, nu, l0);
    let surface: Vec<FccBond> = fcc_slots(&Matrix3::identity(), l0)
        .into_iter()
        .filter(|(n, _, _)| n.z <= 0.0)
        .collect();
    let f = fit_fcc(&surface, vol, &d).unwrap();
    assert!(f.moduli.a > bulk.a && f.moduli.a + f.moduli.c > 0.0);
    assert!(f.residual > 0.0 && f.residual < 1.0);
    // without second neighbours the c-basis vanishes: the (a, b) fit is the one to use
    let near: Vec<FccBond> = fcc_slots(&Matrix3::identity(), l0)[..12].to_vec();
    assert!(fit_fcc(&near, vol, &d).is_none());
    let near_ab: Vec<(Vector3<f64>, f64)> = near.iter().map(|&(n, l, _)| (n, l)).collect();
    let f = <D3 as Dimension<3>>::fit(&near_ab, vol, &d).unwrap();
    assert!(f.moduli.a > 0.0 && f.residual > 0.0);
    // three collinear-ish directions cannot carry it
    let line = vec![(Vector3::x(), l0), (-Vector3::x(), l0)];
    assert!(<D3 as Dimension<3>>::fit(&line, vol, &d).is_none());
}

#[test]
fn two_d_uniform_strain_stress_is_d_epsilon() {
    let mut r = ChaCha20Rng::seed_from_u64(9);
    let (e, l0, t) = (30e9, 0.01, 0.1);
    let vol = 0.5 * 3f64.sqrt() * l0 * l0 * t;
    for pl in [Plane::Stress, Plane::Strain] {
        for nu in [0.0, 0.2, 1.0 / 3.0, 0.45] {
            let m = hexagonal(e, nu, l0, t, pl);
            let d = <D2 as Dimension<2>>::elasticity(e, nu, pl);
            for _ in 0..20 {
                let rot = range(&mut r, 0.0, 1.0);
                let g = Matrix2::from_fn(|_, _| range(&mut r, -1e-4, 1e-4));
                let eps = (g + g.transpose()) * 0.5;
                let ev = Voigt3::strain_to_voigt(&eps);
                let dirs: Vec<Vector2<f64>> = (0..6)
                    .map(|k| {
                        let a = rot + k as f64 * std::f64::consts::PI / 3.0;
                        Vector2::new(a.cos(), a.sin())
                    })
                    .collect();
                let s: Vec<f64> = dirs.iter().map(|n| Voigt3::projector(n).dot(&ev)).collect();
                let theta: f64 = s.iter().sum();
                let mut acc = StressSum::<2>::default();
                for (n, s) in dirs.iter().zip(&s) {
                    acc.add(n, l0, m.a * s + m.b * theta);
                }
                // (3.18) holds per unit thickness: σ·t is what the lattice carries
                let sigma = acc.finish(vol);
                let want = D2::stress_of_strain(&d, &eps);
                assert!(
                    (sigma - want).norm() <= 1e-12 * want.norm(),
                    "{pl:?} nu={nu}"
                );
            }
        }
    }
}

// -- 3D tensors -------------------------------------------------------------------------

#[test]
fn three_d_voigt_round_trips_and_projector_reads_strain() {
    let mut r = ChaCha20Rng::seed_from_u64(10);
    for _ in 0..1000 {
        let g = Matrix3::from_fn(|_, _| range(&mut r, -1.0, 1.0));
        let t = (g + g.transpose()) * 0.5;
        assert!((Voigt6::voigt_to_strain(&Voigt6::strain_to_voigt(&t)) - t).norm() < 1e-15);
        assert_eq!(Voigt6::voigt_to_stress(&Voigt6::stress_to_voigt(&t)), t);
        let n = unit3(&mut r);
        let s = n.dot(&(t * n));
        assert!((Voigt6::projector(&n).dot(&Voigt6::strain_to_voigt(&t)) - s).abs() < 1e-14);
        // σ = D·ε equals λ·tr(ε)·I + 2μ·ε
        let (e, nu) = (30e9, range(&mut r, 0.0, 0.45));
        let d = <D3 as Dimension<3>>::elasticity(e, nu, Plane::Strain);
        let (lam, mu) = (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        );
        let want = Matrix3::identity() * (lam * t.trace()) + t * (2.0 * mu);
        let got = <D3 as Dimension<3>>::stress_of_strain(&d, &t);
        assert!((got - want).norm() <= 1e-14 * want.norm());
        // von Mises equals √(3/2)·‖dev σ‖; extremes are σ1, σ3
        let dev = t - Matrix3::identity() * (t.trace() / 3.0);
        let vm = (1.5 * dev.norm_squared()).sqrt();
        assert!((<D3 as Dimension<3>>::von_mises(&t) - vm).abs() <= 1e-14 * t.norm());
        assert_eq!(
            <D3 as Dimension<3>>::equivalent_stress(&t, nu, Plane::Stress),
            <D3 as Dimension<3>>::von_mises(&t)
        );
        let p = principal_values_3(&t);
        assert_eq!(principal_max_3(&t).to_bits(), p[0].to_bits());
        assert_eq!(
            <D3 as Dimension<3>>::principal_stress_extremes(&t, nu, Plane::Strain),
            (p[0], p[2])
        );
        assert_eq!(
            <D3 as Dimension<3>>::principal_strains(&t, nu, Plane::Stress),
            (p[0], p[1], p[2])
        );
        assert!((<D3 as Dimension<3>>::max_principal(&t) - p[0]).abs() <= 1e-14);
    }
    assert_eq!(<D2 as Dimension<2>>::VOIGT, 3);
    assert_eq!(<D3 as Dimension<3>>::VOIGT, 6);
}
