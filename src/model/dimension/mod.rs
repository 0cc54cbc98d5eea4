//! Dimension as a type: the constitutive tensors of the model in 2D and 3D from one source.
//!
//! [`Dim<D>`] is a marker for the spatial dimension; [`Dimension<D>`] (implemented for
//! `Dim<2>` and `Dim<3>`) is what the rest of the model and the solver ask of a dimension:
//!
//! - the Voigt strain projector v(n) of a unit bond direction, S = n·ε·n = v·ε (§3, (3.20)),
//!   and the Voigt ↔ tensor conversions;
//! - the least-squares strain fit of a particle from its bond stretches (§7 and §13;
//!   see `model::strain`): the projector P_i = N_i⁺ and ε = P_i·S;
//! - principal values (closed form), principal strains with the out-of-plane component,
//!   the extreme principal stresses the concrete criteria use (§8), and the von Mises
//!   equivalent stress of the yield criterion (§9, (3.39)–(3.43) with the erratum);
//! - the isotropic elasticity matrix D, σ = D·ε, and the stiffness basis and least-squares
//!   micro-modulus fit D ≈ a·A + b·B of (3.20).
//!
//! The stress accumulation (3.18) σ_i = (1/(2ΔV_i))·Σ_j L0,ij·F_s,ij·(n_ij ⊗ n_ij) is the
//! generic [`crate::model::stress::StressSum<D>`].
//!
//! **Layout.** Voigt vectors have V = 3 components in 2D, [xx, yy, xy], and V = 6 in 3D,
//! [xx, yy, zz, yz, xz, xy]. Strains carry engineering shear (γ = 2ε), stresses the tensor
//! shear. The projector is v = [nx², ny², nx·ny] in 2D and
//! [nx², ny², nz², ny·nz, nx·nz, nx·ny] in 3D. Only this layout ([`Layout<D, V>`]: [`Voigt3`] in 2D, [`Voigt6`] in 3D), the
//! elasticity matrix and the principal-value formulas differ between the dimensions; the
//! strain fit, σ = D·ε, the stiffness basis and the least-squares fit are written once over
//! `Layout<D, V>` (the free functions below) and both dimensions instantiate them.
//!
//! **Plane stress / plane strain.** A 2D model is a slice of a 3D body: the methods that
//! need the out-of-plane component take the Poisson ratio ν and the [`Plane`] at run time,
//! exactly as the 2D functions did (plane stress: σ_zz = 0, ε_zz = −ν/(1−ν)·(ε1+ε2);
//! plane strain: ε_zz = 0, σ_zz = ν·(σ1+σ2)). In 3D there is no out-of-plane component and
//! these arguments are ignored, so the solver calls the same methods in both dimensions
//! (pass the scene's plane, or any value, in 3D).
//!
//! **Bit-identical 2D.** `Dim<2>` performs exactly the floating-point operations of the 2D
//! functions it replaced (the strain fit, strain tensor, principal values and strains,
//! equivalent and von Mises stress of `strain`, `plasticity` and `stress`, removed since;
//! `micro_modulus::elasticity_matrix`, `stiffness_basis` and `fit` remain as 2D wrappers);
//! `tests` compares every one with a verbatim copy of the old code on random inputs with `==`.
//!
//! **3D principal values** are in closed form (trigonometric method on the deviator with
//! the discriminant as a sum of squares, [`principal_values_3`]), accurate to round-off of
//! the tensor's norm also at repeated and nearly repeated eigenvalues.

use crate::scene::Plane;
use nalgebra::allocator::Allocator;
use nalgebra::{
    ArrayStorage, Const, DefaultAllocator, DimDiff, DimMin, DimSub, Matrix2, Matrix3, Matrix6,
    SMatrix, SVector, Vector3, Vector6, U1,
};
use std::fmt::Debug;

/// A position or bond direction in D dimensions.
pub type Vector<const D: usize> = SVector<f64, D>;
/// A symmetric second-order tensor (stress, strain) in D dimensions.
pub type Tensor<const D: usize> = SMatrix<f64, D, D>;

/// Marker type of the spatial dimension D (2 or 3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Dim<const D: usize>;

/// The 2D Voigt layout [xx, yy, xy].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Voigt3;

/// The 3D Voigt layout [xx, yy, zz, yz, xz, xy].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Voigt6;

/// The Voigt layout of a dimension D with V components: the only per-dimension ingredient of
/// the generic strain fit, σ = D·ε and the stiffness fit. Implemented by [`Voigt3`] (2D) and
/// [`Voigt6`] (3D); [`Dimension`] re-exposes it per dimension.
pub trait Layout<const D: usize, const V: usize> {
    /// v(n) of a unit bond direction n: its stretch under strain ε is S = v·ε (Voigt strain,
    /// engineering shear); its stress contribution (3.18) is ∝ v (Voigt stress).
    fn projector(n: &Vector<D>) -> SVector<f64, V>;
    /// Strain tensor → Voigt with engineering shear γ = 2ε_ij.
    fn strain_to_voigt(e: &Tensor<D>) -> SVector<f64, V>;
    /// Voigt strain (engineering shear) → strain tensor.
    fn voigt_to_strain(v: &SVector<f64, V>) -> Tensor<D>;
    /// Stress tensor → Voigt (tensor shear).
    fn stress_to_voigt(s: &Tensor<D>) -> SVector<f64, V>;
    /// Voigt stress → stress tensor.
    fn voigt_to_stress(v: &SVector<f64, V>) -> Tensor<D>;
}

/// Micro-elastic constants of one particle (N; per unit stretch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicroModuli {
    pub a: f64,
    pub b: f64,
}

/// Result of the least-squares fit of one particle.
#[derive(Clone, Copy, Debug)]
pub struct Fit {
    pub moduli: MicroModuli,
    /// ‖a·A + b·B − D‖_F / ‖D‖_F.
    pub residual: f64,
}

/// What the model asks of a spatial dimension D. Implemented for [`Dim<2>`] and [`Dim<3>`];
/// code generic over `const D: usize` bounds `Dim<D>: Dimension<D>`.
///
/// Methods taking `nu` and `plane` need them only for the 2D out-of-plane component; 3D
/// ignores both.
pub trait Dimension<const D: usize>: Copy + Default + Debug + Send + Sync + 'static {
    /// Number of Voigt components: 3 in 2D, 6 in 3D.
    const VOIGT: usize;
    /// A Voigt vector (`Vector3` in 2D, `Vector6` in 3D).
    type Voigt: Copy + Debug + PartialEq + Send + Sync + 'static;
    /// A V×V matrix in Voigt notation: elasticity D, stiffness bases A, B, C.
    type Stiffness: Copy
        + Debug
        + PartialEq
        + Send
        + Sync
        + 'static
        + std::ops::Mul<f64, Output = Self::Stiffness>;
    /// Rows of a particle's least-squares strain projector for K slots, V×K
    /// (`[[f64; K]; V]`).
    type StrainFit<const K: usize>: Copy + Debug + PartialEq + Send + Sync + 'static;

    /// v(n), see [`Layout::projector`].
    fn projector(n: &Vector<D>) -> Self::Voigt;
    /// See [`Layout::strain_to_voigt`].
    fn strain_to_voigt(e: &Tensor<D>) -> Self::Voigt;
    /// See [`Layout::voigt_to_strain`].
    fn voigt_to_strain(v: &Self::Voigt) -> Tensor<D>;
    /// See [`Layout::stress_to_voigt`].
    fn stress_to_voigt(s: &Tensor<D>) -> Self::Voigt;
    /// See [`Layout::voigt_to_stress`].
    fn voigt_to_stress(v: &Self::Voigt) -> Tensor<D>;

    /// The least-squares strain projector of a particle whose slot k holds a bond of unit
    /// direction `dirs[k]` (`None` where empty): minimum-norm pseudo-inverse of N (rows v_k).
    fn strain_fit<const K: usize>(dirs: &[Option<Vector<D>>; K]) -> Self::StrainFit<K>;
    /// The strain tensor ε = P·S of stretches `s` through projector `p`.
    fn strain_tensor<const K: usize>(p: &Self::StrainFit<K>, s: &[f64; K]) -> Tensor<D>;

    /// Principal values of a symmetric tensor in closed form, sorted descending.
    fn principal_values(t: &Tensor<D>) -> [f64; D];
    /// Principal strains (ε1, ε2, ε3). 2D: ε1 ≥ ε2 in the plane and the out-of-plane ε3
    /// (0 in plane strain, −ν/(1−ν)·(ε1+ε2) in plane stress), not sorted against ε1, ε2.
    /// 3D: the three principal values, descending.
    fn principal_strains(e: &Tensor<D>, nu: f64, plane: Plane) -> (f64, f64, f64);
    /// The largest in-plane (2D) or largest (3D) principal strain ε1 of
    /// [`Dimension::principal_strains`], bit for bit, where the others are not needed (the
    /// tension kernel's damage law, §8): in 3D at a third of the cosines ([`principal_max_3`]).
    #[inline(always)]
    fn principal_strain_max(e: &Tensor<D>, nu: f64, plane: Plane) -> f64 {
        Self::principal_strains(e, nu, plane).0
    }
    /// (σ_max, σ_min): the largest and smallest principal stress including, in 2D, the
    /// out-of-plane σ_zz ([`out_of_plane_stress`]) — the pair the concrete
    /// criteria take (§8, `damage::initiates`).
    fn principal_stress_extremes(s: &Tensor<D>, nu: f64, plane: Plane) -> (f64, f64);
    /// An upper bound on σ_max and a lower bound on σ_min of
    /// [`Dimension::principal_stress_extremes`], cheaper than the extremes, for tests that
    /// are monotone in them (initiation, `damage::initiates`): where the bounds fail the test,
    /// the extremes fail it too. 2D: the extremes themselves.
    #[inline(always)]
    fn principal_stress_bounds(s: &Tensor<D>, nu: f64, plane: Plane) -> (f64, f64) {
        Self::principal_stress_extremes(s, nu, plane)
    }
    /// Effective strain (4.17) of a strain tensor, √(½·Σ(ε_i − ε_j)²) over its principal
    /// strains ([`Dimension::principal_strains`]). 2D: from the principal strains.
    #[inline(always)]
    fn effective_strain(e: &Tensor<D>, nu: f64, plane: Plane) -> f64 {
        let (e1, e2, e3) = Self::principal_strains(e, nu, plane);
        crate::model::damage::effective_strain(e1, e2, e3)
    }
    /// Von Mises equivalent stress √(3/2)·‖σ_dev‖ ((3.39), (3.40)); in 2D with σ_zz from the
    /// plane (plane stress 0, plane strain ν·(σxx+σyy)).
    fn equivalent_stress(s: &Tensor<D>, nu: f64, plane: Plane) -> f64;
    /// Von Mises stress of the tensor as given (2D: σ_zz = 0, the plane stress form).
    fn von_mises(s: &Tensor<D>) -> f64;
    /// Largest principal value (nalgebra's symmetric eigen solver, as the output maps use).
    fn max_principal(s: &Tensor<D>) -> f64;

    /// Isotropic elasticity matrix D (Voigt, engineering shear strain); 2D by plane.
    fn elasticity(e: f64, nu: f64, plane: Plane) -> Self::Stiffness;
    /// σ = D·ε as tensors (`d` any Voigt stiffness, e.g. a scaled [`Dimension::elasticity`]).
    fn stress_of_strain(d: &Self::Stiffness, eps: &Tensor<D>) -> Tensor<D>;

    /// The bases A = Σ_j w_j v_j v_jᵀ and B = (Σ_j w_j v_j)(Σ_k v_k)ᵀ, w_j = L0,j/(2ΔV), of a
    /// particle with bonds (unit direction, reference length) and volume ΔV: its stiffness
    /// under F_s,ij = a·S_ij + b·Σ_m S_im is a·A + b·B (3.20). (For FCC second neighbours,
    /// the c-basis C is A of the second-neighbour bonds alone; see `micro_modulus::fcc_basis`.)
    fn stiffness_basis(
        bonds: &[(Vector<D>, f64)],
        volume: f64,
    ) -> (Self::Stiffness, Self::Stiffness);
    /// Least-squares a, b with D ≈ a·A + b·B (3.20); `None` when A is rank deficient or
    /// a ≤ 0 or not finite.
    fn fit(bonds: &[(Vector<D>, f64)], volume: f64, d: &Self::Stiffness) -> Option<Fit>;
}

// ---------------------------------------------------------------------------------------
// Generic code, written once over the Voigt layout.
// ---------------------------------------------------------------------------------------

/// The least-squares strain projector P = (NᵀN)⁺·Nᵀ (V×K) of a particle whose slot k holds
/// a bond of unit direction `dirs[k]`; N's rows are v(n_k) (zero for empty slots).
pub fn strain_fit<const D: usize, const V: usize, const K: usize, L: Layout<D, V>>(
    dirs: &[Option<Vector<D>>; K],
) -> [[f64; K]; V]
where
    Const<V>: DimMin<Const<V>, Output = Const<V>> + DimSub<U1>,
    DefaultAllocator: Allocator<DimDiff<Const<V>, U1>>,
{
    let mut n = SMatrix::<f64, K, V>::from_array_storage(ArrayStorage([[0.0; K]; V]));
    for (k, d) in dirs.iter().enumerate() {
        if let Some(d) = d {
            let v = L::projector(d);
            for c in 0..V {
                n[(k, c)] = v[c];
            }
        }
    }
    let ntn: SMatrix<f64, V, V> = n.transpose() * n;
    let pinv = pseudo_inverse(ntn);
    let p = pinv * n.transpose();
    let mut out = [[0.0; K]; V];
    for (c, row) in out.iter_mut().enumerate() {
        for (k, x) in row.iter_mut().enumerate() {
            *x = p[(c, k)];
        }
    }
    out
}

/// Pseudo-inverse of NᵀN with singular values below 1e-10·‖NᵀN‖ dropped (zero if the SVD
/// fails).
fn pseudo_inverse<const V: usize>(ntn: SMatrix<f64, V, V>) -> SMatrix<f64, V, V>
where
    Const<V>: DimMin<Const<V>, Output = Const<V>> + DimSub<U1>,
    DefaultAllocator: Allocator<DimDiff<Const<V>, U1>>,
{
    match ntn.pseudo_inverse(1e-10 * ntn.norm().max(f64::MIN_POSITIVE)) {
        Ok(p) => p,
        Err(_) => SMatrix::from_array_storage(ArrayStorage([[0.0; V]; V])),
    }
}

/// The strain tensor of stretches `s` through projector `p`: ε_voigt = P·S.
#[inline(always)]
pub fn strain_tensor<const D: usize, const V: usize, const K: usize, L: Layout<D, V>>(
    p: &[[f64; K]; V],
    s: &[f64; K],
) -> Tensor<D> {
    let mut e = [0.0; V];
    for c in 0..V {
        let mut acc = 0.0;
        for k in 0..K {
            acc += p[c][k] * s[k];
        }
        e[c] = acc;
    }
    L::voigt_to_strain(&SVector::<f64, V>::from(e))
}

/// σ = D·ε as tensors.
#[inline(always)]
pub fn stress_of_strain<const D: usize, const V: usize, L: Layout<D, V>>(
    d: &SMatrix<f64, V, V>,
    eps: &Tensor<D>,
) -> Tensor<D> {
    let sv = d * L::strain_to_voigt(eps);
    L::voigt_to_stress(&sv)
}

/// The bases A and B of bonds (unit direction, reference length) of a particle of volume ΔV
/// (see [`Dimension::stiffness_basis`]).
pub fn stiffness_basis<const D: usize, const V: usize, L: Layout<D, V>>(
    bonds: &[(Vector<D>, f64)],
    volume: f64,
) -> (SMatrix<f64, V, V>, SMatrix<f64, V, V>) {
    stiffness_basis_weighted::<D, V, L>(bonds, volume, None)
}

/// [`stiffness_basis`] of a particle whose dilatation weighs bond m by L0,m/ℓ
/// (`ell = Some(ℓ)`; random particles, docs/sppm.md): B = (M·1)(wᵀN), symmetric. `None`:
/// the unweighted θ = Σ S of the lattices.
pub fn stiffness_basis_weighted<const D: usize, const V: usize, L: Layout<D, V>>(
    bonds: &[(Vector<D>, f64)],
    volume: f64,
    ell: Option<f64>,
) -> (SMatrix<f64, V, V>, SMatrix<f64, V, V>) {
    let mut a = SMatrix::<f64, V, V>::zeros();
    let mut mv = SVector::<f64, V>::zeros();
    let mut nv = SVector::<f64, V>::zeros();
    for (n, l0) in bonds {
        let v = L::projector(n);
        let w = l0 / (2.0 * volume);
        a += v * v.transpose() * w;
        mv += v * w;
        match ell {
            Some(ell) => nv += v * (l0 / ell),
            None => nv += v,
        }
    }
    (a, mv * nv.transpose())
}

/// The least-squares (a, b) of a 2D particle with weighted dilatation (random particles):
/// D ≈ a·A + b·B with B from [`stiffness_basis_weighted`].
pub fn fit_weighted_2d(
    bonds: &[(Vector<2>, f64)],
    volume: f64,
    ell: f64,
    d: &Matrix3<f64>,
) -> Option<Fit> {
    let (a_m, b_m) = stiffness_basis_weighted::<2, 3, Voigt3>(bonds, volume, Some(ell));
    let ([a, b], residual) = least_squares(&[a_m, b_m], d, |_| true)?;
    Some(Fit {
        moduli: MicroModuli { a, b },
        residual,
    })
}

/// Least-squares coefficients x with d ≈ Σ_p x_p·basis[p] (Frobenius norm) and the relative
/// residual ‖Σ_p x_p·basis[p] − d‖/‖d‖. `None` when basis[0] (the a-basis A, which must
/// resist every strain) is rank deficient (|det A| ≤ 1e-12·‖A‖^V), the Gram matrix is
/// singular, x_0 ≤ 0, any x_p is not finite, or `accept(x)` refuses.
pub fn least_squares<const V: usize, const P: usize>(
    basis: &[SMatrix<f64, V, V>; P],
    d: &SMatrix<f64, V, V>,
    accept: impl Fn(&[f64; P]) -> bool,
) -> Option<([f64; P], f64)>
where
    Const<V>: DimMin<Const<V>, Output = Const<V>>,
{
    let dot = |x: &SMatrix<f64, V, V>, y: &SMatrix<f64, V, V>| x.component_mul(y).sum();
    let g = SMatrix::<f64, P, P>::from_fn(|i, j| dot(&basis[i], &basis[j]));
    let r = SVector::<f64, P>::from_fn(|i, _| dot(&basis[i], d));
    let a_m = &basis[0];
    if a_m.determinant().abs() <= 1e-12 * a_m.norm().powi(V as i32) {
        return None;
    }
    let sol = g.try_inverse()? * r;
    let x: [f64; P] = sol.into();
    if !(x[0] > 0.0 && x.iter().all(|v| v.is_finite()) && accept(&x)) {
        return None;
    }
    let mut model = basis[0] * x[0];
    for p in 1..P {
        model += basis[p] * x[p];
    }
    let residual = (model - d).norm() / d.norm();
    Some((x, residual))
}

// ---------------------------------------------------------------------------------------
// 2D
// ---------------------------------------------------------------------------------------

impl Layout<2, 3> for Voigt3 {
    #[inline(always)]
    fn projector(n: &Vector<2>) -> Vector3<f64> {
        Vector3::new(n.x * n.x, n.y * n.y, n.x * n.y)
    }
    #[inline(always)]
    fn strain_to_voigt(e: &Matrix2<f64>) -> Vector3<f64> {
        Vector3::new(e[(0, 0)], e[(1, 1)], 2.0 * e[(0, 1)])
    }
    #[inline(always)]
    fn voigt_to_strain(e: &Vector3<f64>) -> Matrix2<f64> {
        Matrix2::new(e[0], 0.5 * e[2], 0.5 * e[2], e[1])
    }
    #[inline(always)]
    fn stress_to_voigt(s: &Matrix2<f64>) -> Vector3<f64> {
        Vector3::new(s[(0, 0)], s[(1, 1)], s[(0, 1)])
    }
    #[inline(always)]
    fn voigt_to_stress(v: &Vector3<f64>) -> Matrix2<f64> {
        Matrix2::new(v[0], v[2], v[2], v[1])
    }
}

/// Principal values p1 ≥ p2 of a symmetric 2×2 tensor, (a+c)/2 ± √(((a−c)/2)² + b²).
#[inline(always)]
fn principal_values_2(t: &Matrix2<f64>) -> (f64, f64) {
    let (a, b, c) = (t[(0, 0)], t[(0, 1)], t[(1, 1)]);
    let m = 0.5 * (a + c);
    let r = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    (m + r, m - r)
}

/// Out-of-plane stress σ_zz of a 2D particle: 0 in plane stress, ν·(σxx + σyy) in plane
/// strain (the sum of the in-plane normal stresses, equally of the principal ones).
#[inline(always)]
pub fn out_of_plane_stress(sxx: f64, syy: f64, nu: f64, plane: Plane) -> f64 {
    match plane {
        Plane::Stress => 0.0,
        Plane::Strain => nu * (sxx + syy),
    }
}

impl Dimension<2> for Dim<2> {
    const VOIGT: usize = 3;
    type Voigt = Vector3<f64>;
    type Stiffness = Matrix3<f64>;
    type StrainFit<const K: usize> = [[f64; K]; 3];

    #[inline(always)]
    fn projector(n: &Vector<2>) -> Vector3<f64> {
        Voigt3::projector(n)
    }
    #[inline(always)]
    fn strain_to_voigt(e: &Matrix2<f64>) -> Vector3<f64> {
        Voigt3::strain_to_voigt(e)
    }
    #[inline(always)]
    fn voigt_to_strain(v: &Vector3<f64>) -> Matrix2<f64> {
        Voigt3::voigt_to_strain(v)
    }
    #[inline(always)]
    fn stress_to_voigt(s: &Matrix2<f64>) -> Vector3<f64> {
        Voigt3::stress_to_voigt(s)
    }
    #[inline(always)]
    fn voigt_to_stress(v: &Vector3<f64>) -> Matrix2<f64> {
        Voigt3::voigt_to_stress(v)
    }

    fn strain_fit<const K: usize>(dirs: &[Option<Vector<2>>; K]) -> [[f64; K]; 3] {
        strain_fit::<2, 3, K, Voigt3>(dirs)
    }
    #[inline(always)]
    fn strain_tensor<const K: usize>(p: &[[f64; K]; 3], s: &[f64; K]) -> Matrix2<f64> {
        strain_tensor::<2, 3, K, Voigt3>(p, s)
    }

    #[inline(always)]
    fn principal_values(t: &Matrix2<f64>) -> [f64; 2] {
        let (p1, p2) = principal_values_2(t);
        [p1, p2]
    }
    #[inline(always)]
    fn principal_strains(e: &Matrix2<f64>, nu: f64, plane: Plane) -> (f64, f64, f64) {
        let (e1, e2) = principal_values_2(e);
        let e3 = match plane {
            Plane::Strain => 0.0,
            Plane::Stress => -nu / (1.0 - nu) * (e1 + e2),
        };
        (e1, e2, e3)
    }
    #[inline(always)]
    fn principal_stress_extremes(s: &Matrix2<f64>, nu: f64, plane: Plane) -> (f64, f64) {
        let (s1, s2) = principal_values_2(s);
        let s33 = out_of_plane_stress(s1, s2, nu, plane);
        (s1.max(s33), s2.min(s33))
    }
    #[inline(always)]
    fn equivalent_stress(s: &Matrix2<f64>, nu: f64, plane: Plane) -> f64 {
        let (sx, sy, t) = (s[(0, 0)], s[(1, 1)], s[(0, 1)]);
        let sz = out_of_plane_stress(sx, sy, nu, plane);
        (0.5 * ((sx - sy).powi(2) + (sy - sz).powi(2) + (sz - sx).powi(2)) + 3.0 * t * t).sqrt()
    }
    #[inline]
    fn von_mises(s: &Matrix2<f64>) -> f64 {
        let (sx, sy, txy) = (s[(0, 0)], s[(1, 1)], s[(0, 1)]);
        (sx * sx - sx * sy + sy * sy + 3.0 * txy * txy).sqrt()
    }
    fn max_principal(s: &Matrix2<f64>) -> f64 {
        s.symmetric_eigenvalues().max()
    }

    fn elasticity(e: f64, nu: f64, plane: Plane) -> Matrix3<f64> {
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
    #[inline(always)]
    fn stress_of_strain(d: &Matrix3<f64>, eps: &Matrix2<f64>) -> Matrix2<f64> {
        stress_of_strain::<2, 3, Voigt3>(d, eps)
    }

    fn stiffness_basis(bonds: &[(Vector<2>, f64)], volume: f64) -> (Matrix3<f64>, Matrix3<f64>) {
        stiffness_basis::<2, 3, Voigt3>(bonds, volume)
    }
    fn fit(bonds: &[(Vector<2>, f64)], volume: f64, d: &Matrix3<f64>) -> Option<Fit> {
        fit_ab::<2, 3, Voigt3>(bonds, volume, d)
    }
}

/// The (a, b) fit of either dimension.
fn fit_ab<const D: usize, const V: usize, L: Layout<D, V>>(
    bonds: &[(Vector<D>, f64)],
    volume: f64,
    d: &SMatrix<f64, V, V>,
) -> Option<Fit>
where
    Const<V>: DimMin<Const<V>, Output = Const<V>>,
{
    let (a_m, b_m) = stiffness_basis::<D, V, L>(bonds, volume);
    let ([a, b], residual) = least_squares(&[a_m, b_m], d, |_| true)?;
    Some(Fit {
        moduli: MicroModuli { a, b },
        residual,
    })
}

// ---------------------------------------------------------------------------------------
// 3D
// ---------------------------------------------------------------------------------------

impl Layout<3, 6> for Voigt6 {
    #[inline(always)]
    fn projector(n: &Vector<3>) -> Vector6<f64> {
        crate::geometry::solid::dyad_voigt(n)
    }
    #[inline(always)]
    fn strain_to_voigt(e: &Matrix3<f64>) -> Vector6<f64> {
        Vector6::new(
            e[(0, 0)],
            e[(1, 1)],
            e[(2, 2)],
            2.0 * e[(1, 2)],
            2.0 * e[(0, 2)],
            2.0 * e[(0, 1)],
        )
    }
    #[inline(always)]
    fn voigt_to_strain(e: &Vector6<f64>) -> Matrix3<f64> {
        let (yz, xz, xy) = (0.5 * e[3], 0.5 * e[4], 0.5 * e[5]);
        Matrix3::new(e[0], xy, xz, xy, e[1], yz, xz, yz, e[2])
    }
    #[inline(always)]
    fn stress_to_voigt(s: &Matrix3<f64>) -> Vector6<f64> {
        Vector6::new(
            s[(0, 0)],
            s[(1, 1)],
            s[(2, 2)],
            s[(1, 2)],
            s[(0, 2)],
            s[(0, 1)],
        )
    }
    #[inline(always)]
    fn voigt_to_stress(v: &Vector6<f64>) -> Matrix3<f64> {
        Matrix3::new(v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2])
    }
}

/// Principal values of a symmetric 3×3 tensor in closed form, sorted descending. Only the
/// lower triangle is read (as nalgebra's symmetric eigen solver).
///
/// Trigonometric method on the deviator s = t − (tr t/3)·I, scaled to order one: the
/// eigenvalues of s are 2√(J2/3)·cos(θ − 2πk/3), with 3θ = atan2(√Δ, 3√3·J3),
/// J2 = ½ tr s², J3 = det s and Δ = 4J2³ − 27J3² = Π_{i<j}(λ_i − λ_j)² the discriminant.
/// Δ is not formed by that difference (which cancels catastrophically at nearly repeated
/// eigenvalues, where acos-based formulas lose half the digits) but as the Gram determinant
/// of (I, s, s²): Δ = 3·(‖s‖²‖t‖² − ⟨s, t⟩²) with t = s² − (tr s²/3)·I, and the bracket by
/// Lagrange's identity as a sum of squares of 2×2 minors, each computed with an absolute
/// error of round-off times ‖s‖³. So the angle, and the eigenvalues, are accurate to a few
/// ulps of ‖t‖ whatever the eigenvalue gaps (`tests::principal_values_3_match_nalgebra`).
pub fn principal_values_3(t: &Matrix3<f64>) -> [f64; 3] {
    let (m, scale, r, theta) = match deviator_angle(t) {
        Deviator::Zero { m } => return [m, m, m],
        Deviator::Angle { m, scale, r, theta } => (m, scale, r, theta),
    };
    let third = 2.0 * std::f64::consts::FRAC_PI_3;
    let mut p = [
        r * theta.cos(),
        r * (theta - third).cos(),
        r * (theta + third).cos(),
    ];
    // Sorted by construction for θ ∈ [0, π/3]; round-off may swap near-equal values.
    if p[1] > p[0] {
        p.swap(0, 1);
    }
    if p[2] > p[1] {
        p.swap(1, 2);
        if p[1] > p[0] {
            p.swap(0, 1);
        }
    }
    [m + p[0] * scale, m + p[1] * scale, m + p[2] * scale]
}

/// The largest principal value of a symmetric 3×3 tensor, bit for bit
/// `principal_values_3(t)[0]` (`tests::principal_values_3_match_nalgebra`) at a third of its
/// cosines: with θ ∈ [0, π/3], cos(θ + 2π/3) ≤ −½ < ½ ≤ cos θ, and cos θ − cos(θ − 2π/3) =
/// √3·sin(π/3 − θ), so cos θ is the largest of the three, computed as well as exactly, unless
/// θ is within 1e-6 of π/3 (two largest values nearly equal), where all three are computed and
/// sorted as `principal_values_3` sorts them.
pub fn principal_max_3(t: &Matrix3<f64>) -> f64 {
    match deviator_angle(t) {
        Deviator::Angle { m, scale, r, theta } if theta < std::f64::consts::FRAC_PI_3 - 1e-6 => {
            m + r * theta.cos() * scale
        }
        _ => principal_values_3(t)[0],
    }
}

/// The deviator of a symmetric 3×3 tensor in the form its principal values take
/// ([`principal_values_3`]): the mean m and either a zero deviator, or the scale, the radius
/// r = 2√(J2/3) and the angle θ = atan2(√Δ, 3√3·J3)/3 of the scaled deviator.
enum Deviator {
    Zero {
        m: f64,
    },
    Angle {
        m: f64,
        scale: f64,
        r: f64,
        theta: f64,
    },
}

/// [`Deviator`] of t (only the lower triangle is read).
#[inline]
fn deviator_angle(t: &Matrix3<f64>) -> Deviator {
    let m = (t[(0, 0)] + t[(1, 1)] + t[(2, 2)]) / 3.0;
    let (a, b, c) = (t[(0, 0)] - m, t[(1, 1)] - m, t[(2, 2)] - m);
    let (xy, yz, xz) = (t[(1, 0)], t[(2, 1)], t[(2, 0)]);
    // Scale (a sum keeps NaN); zero deviator: three equal values.
    let scale = a.abs() + b.abs() + c.abs() + xy.abs() + yz.abs() + xz.abs();
    if scale == 0.0 {
        return Deviator::Zero { m };
    }
    let k = 1.0 / scale;
    let (a, b, c, xy, yz, xz) = (a * k, b * k, c * k, xy * k, yz * k, xz * k);
    // s² (symmetric), its trace and the deviator t of s².
    let q00 = a * a + xy * xy + xz * xz;
    let q11 = xy * xy + b * b + yz * yz;
    let q22 = xz * xz + yz * yz + c * c;
    let q01 = a * xy + xy * b + xz * yz;
    let q12 = xy * xz + b * yz + yz * c;
    let q02 = a * xz + xy * yz + xz * c;
    let tr2 = q00 + q11 + q22; // = 2·J2
    let j2 = 0.5 * tr2;
    let t3 = tr2 / 3.0;
    let (t00, t11, t22) = (q00 - t3, q11 - t3, q22 - t3);
    // J3 = det s.
    let j3 = a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz);
    // ‖s‖²‖t‖² − ⟨s,t⟩² in orthonormal coordinates (diagonal, √2·off-diagonal).
    let sd = [a, b, c];
    let td = [t00, t11, t22];
    let so = [yz, xz, xy];
    let to = [q12, q02, q01];
    let mut gram = 0.0;
    for i in 0..3 {
        for j in (i + 1)..3 {
            let x = sd[i] * td[j] - sd[j] * td[i];
            gram += x * x;
            let y = so[i] * to[j] - so[j] * to[i];
            gram += 4.0 * y * y;
        }
        for j in 0..3 {
            let z = sd[i] * to[j] - so[j] * td[i];
            gram += 2.0 * z * z;
        }
    }
    let disc_sqrt = (3.0 * gram).sqrt();
    let theta = disc_sqrt.atan2(3.0 * 3f64.sqrt() * j3) / 3.0;
    let r = 2.0 * (j2 / 3.0).sqrt();
    Deviator::Angle { m, scale, r, theta }
}

impl Dimension<3> for Dim<3> {
    const VOIGT: usize = 6;
    type Voigt = Vector6<f64>;
    type Stiffness = Matrix6<f64>;
    type StrainFit<const K: usize> = [[f64; K]; 6];

    #[inline(always)]
    fn projector(n: &Vector<3>) -> Vector6<f64> {
        Voigt6::projector(n)
    }
    #[inline(always)]
    fn strain_to_voigt(e: &Matrix3<f64>) -> Vector6<f64> {
        Voigt6::strain_to_voigt(e)
    }
    #[inline(always)]
    fn voigt_to_strain(v: &Vector6<f64>) -> Matrix3<f64> {
        Voigt6::voigt_to_strain(v)
    }
    #[inline(always)]
    fn stress_to_voigt(s: &Matrix3<f64>) -> Vector6<f64> {
        Voigt6::stress_to_voigt(s)
    }
    #[inline(always)]
    fn voigt_to_stress(v: &Vector6<f64>) -> Matrix3<f64> {
        Voigt6::voigt_to_stress(v)
    }

    fn strain_fit<const K: usize>(dirs: &[Option<Vector<3>>; K]) -> [[f64; K]; 6] {
        strain_fit::<3, 6, K, Voigt6>(dirs)
    }
    #[inline(always)]
    fn strain_tensor<const K: usize>(p: &[[f64; K]; 6], s: &[f64; K]) -> Matrix3<f64> {
        strain_tensor::<3, 6, K, Voigt6>(p, s)
    }

    #[inline]
    fn principal_values(t: &Matrix3<f64>) -> [f64; 3] {
        principal_values_3(t)
    }
    /// The three principal values; `nu` and `plane` are ignored.
    #[inline]
    fn principal_strains(e: &Matrix3<f64>, _nu: f64, _plane: Plane) -> (f64, f64, f64) {
        let [e1, e2, e3] = principal_values_3(e);
        (e1, e2, e3)
    }
    /// ε1 alone ([`principal_max_3`]); `nu` and `plane` are ignored.
    #[inline]
    fn principal_strain_max(e: &Matrix3<f64>, _nu: f64, _plane: Plane) -> f64 {
        principal_max_3(e)
    }
    /// (σ1, σ3); `nu` and `plane` are ignored.
    #[inline]
    fn principal_stress_extremes(s: &Matrix3<f64>, _nu: f64, _plane: Plane) -> (f64, f64) {
        let [s1, _, s3] = principal_values_3(s);
        (s1, s3)
    }
    /// σ_m ± (2/3)·σ_vM, widened by 1e-12 of (|σ_m| + σ_vM) against round-off: the deviator's
    /// eigenvalues lie within ±2·√(J2/3) = ±(2/3)·σ_vM (equality in uniaxial stress), so no
    /// eigenvalue solve; `nu` and `plane` are ignored.
    #[inline]
    fn principal_stress_bounds(s: &Matrix3<f64>, _nu: f64, _plane: Plane) -> (f64, f64) {
        let m = (s[(0, 0)] + s[(1, 1)] + s[(2, 2)]) / 3.0;
        let vm = <Self as Dimension<3>>::von_mises(s);
        let r = 2.0 / 3.0 * vm + 1e-12 * (m.abs() + vm);
        (m + r, m - r)
    }
    /// The von Mises form of the strain tensor (the same invariant, no eigenvalue solve);
    /// `nu` and `plane` are ignored.
    #[inline]
    fn effective_strain(e: &Matrix3<f64>, _nu: f64, _plane: Plane) -> f64 {
        <Self as Dimension<3>>::von_mises(e)
    }
    /// The full von Mises stress; `nu` and `plane` are ignored.
    #[inline]
    fn equivalent_stress(s: &Matrix3<f64>, _nu: f64, _plane: Plane) -> f64 {
        <Self as Dimension<3>>::von_mises(s)
    }
    #[inline]
    fn von_mises(s: &Matrix3<f64>) -> f64 {
        let (sx, sy, sz) = (s[(0, 0)], s[(1, 1)], s[(2, 2)]);
        let (yz, xz, xy) = (s[(1, 2)], s[(0, 2)], s[(0, 1)]);
        (0.5 * ((sx - sy).powi(2) + (sy - sz).powi(2) + (sz - sx).powi(2))
            + 3.0 * (xy * xy + yz * yz + xz * xz))
            .sqrt()
    }
    fn max_principal(s: &Matrix3<f64>) -> f64 {
        s.symmetric_eigenvalues().max()
    }

    /// Isotropic D = λ·(1⊗1) + 2μ·I (engineering shear: μ on the shear diagonal); `plane`
    /// is ignored.
    fn elasticity(e: f64, nu: f64, _plane: Plane) -> Matrix6<f64> {
        let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let (d11, d12, d44) = (c * (1.0 - nu), c * nu, c * (1.0 - 2.0 * nu) / 2.0);
        let mut d = Matrix6::zeros();
        for i in 0..3 {
            for j in 0..3 {
                d[(i, j)] = if i == j { d11 } else { d12 };
            }
            d[(i + 3, i + 3)] = d44;
        }
        d
    }
    #[inline(always)]
    fn stress_of_strain(d: &Matrix6<f64>, eps: &Matrix3<f64>) -> Matrix3<f64> {
        stress_of_strain::<3, 6, Voigt6>(d, eps)
    }

    fn stiffness_basis(bonds: &[(Vector<3>, f64)], volume: f64) -> (Matrix6<f64>, Matrix6<f64>) {
        stiffness_basis::<3, 6, Voigt6>(bonds, volume)
    }
    fn fit(bonds: &[(Vector<3>, f64)], volume: f64, d: &Matrix6<f64>) -> Option<Fit> {
        fit_ab::<3, 6, Voigt6>(bonds, volume, d)
    }
}

#[cfg(test)]
mod tests;
