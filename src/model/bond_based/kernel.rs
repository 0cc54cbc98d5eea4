//! The bond-based force kernel: every point sums its own bonds' forces (each bond is held by
//! both its points, so no two threads write one point), c·λ·ω·s·(1 − d(s_max))·v_c·ΔV_i·ΔV_j
//! along the deformed bond (B.1), updating the bond's largest stretch; the contact
//! repulsion of points pressed together. Per bond the step streams 20 bytes (neighbour,
//! ξ, stiffness, s_max) and gathers the neighbour's position, which its grid neighbours
//! have mostly brought into the cache.

use super::body::BondBody;
use nalgebra::SVector;
use rayon::prelude::*;

/// Points per parallel task: large enough that a task's bonds are a long stream.
const CHUNK: usize = 512;

/// Bonds a point computes at once: the neighbours' positions of a block are gathered, then
/// its lengths and forces computed in vectorised loops.
const BLOCK: usize = 64;

/// Whether the CPU runs AVX2 and FMA (asked once).
#[cfg(target_arch = "x86_64")]
fn avx2() -> bool {
    static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAS.get_or_init(|| is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"))
}

impl<const D: usize> BondBody<D> {
    /// The internal force on each point (N) at positions `x`, into `f`; the bonds' largest
    /// stretches are updated and bonds past their critical stretch (or the compressive one)
    /// break for good.
    pub fn forces(&mut self, x: &[SVector<f64, D>], f: &mut [SVector<f64, D>]) {
        let mut s_max = std::mem::take(&mut self.s_max);
        self.split_forces(x, 0, f, &mut s_max);
        self.s_max = s_max;
    }

    /// The forces on points i0.. (as many as `fs` holds), whose bonds' largest stretches are
    /// `smax`: halved at a chunk boundary (with the bonds of each half) and the halves run in
    /// parallel, down to chunks of [`CHUNK`] points; nothing is allocated.
    fn split_forces(
        &self,
        x: &[SVector<f64, D>],
        i0: usize,
        fs: &mut [SVector<f64, D>],
        smax: &mut [f32],
    ) {
        if fs.len() <= CHUNK {
            return self.chunk_forces(x, i0, fs, smax);
        }
        let half = fs.len().div_ceil(2 * CHUNK) * CHUNK;
        let bonds = (self.start[i0 + half] - self.start[i0]) as usize;
        let (fa, fb) = fs.split_at_mut(half);
        let (sa, sb) = smax.split_at_mut(bonds);
        rayon::join(
            || self.split_forces(x, i0, fa, sa),
            || self.split_forces(x, i0 + half, fb, sb),
        );
    }

    /// The forces on points i0.. (as many as `fs` holds), whose bonds' largest stretches
    /// are `smax`.
    fn chunk_forces(
        &self,
        x: &[SVector<f64, D>],
        i0: usize,
        fs: &mut [SVector<f64, D>],
        smax: &mut [f32],
    ) {
        #[cfg(target_arch = "x86_64")]
        if avx2() {
            // SAFETY: the CPU has AVX2 and FMA (checked at run time by `avx2`).
            unsafe { self.chunk_forces_avx2(x, i0, fs, smax) };
            return;
        }
        self.chunk_forces_plain(x, i0, fs, smax);
    }

    /// [`Self::chunk_forces`] compiled for AVX2 and FMA: the same code, which the compiler
    /// turns into 4-wide square roots and divisions.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn chunk_forces_avx2(
        &self,
        x: &[SVector<f64, D>],
        i0: usize,
        fs: &mut [SVector<f64, D>],
        smax: &mut [f32],
    ) {
        self.chunk_forces_plain(x, i0, fs, smax);
    }

    #[inline(always)]
    fn chunk_forces_plain(
        &self,
        x: &[SVector<f64, D>],
        i0: usize,
        fs: &mut [SVector<f64, D>],
        smax: &mut [f32],
    ) {
        let b0 = self.start[i0] as usize;
        for (k, fi) in fs.iter_mut().enumerate() {
            let i = i0 + k;
            let (lo, hi) = (self.start[i] as usize, self.start[i + 1] as usize);
            let mut sum = SVector::<f64, D>::zeros();
            let mut at = lo;
            while at < hi {
                let end = hi.min(at + BLOCK);
                sum += self.block_force(x, i, at, end, &mut smax[at - b0..end - b0]);
                at = end;
            }
            *fi = sum;
        }
    }

    /// The force on point i of its bonds lo..hi (at most [`BLOCK`]), whose largest stretches
    /// are `sm`: the neighbours' positions are gathered, then lengths, stretches and force
    /// factors computed in straight loops the compiler vectorises; a bond that may soften,
    /// break, be crushed or touch takes [`Self::bond_beyond_elastic`].
    #[inline(always)]
    fn block_force(
        &self,
        x: &[SVector<f64, D>],
        i: usize,
        lo: usize,
        hi: usize,
        sm: &mut [f32],
    ) -> SVector<f64, D> {
        let m = hi - lo;
        let here = x[i];
        let mut y = [[0.0f64; BLOCK]; D];
        for (t, &j) in self.neighbour[lo..hi].iter().enumerate() {
            let p = x[j as usize];
            for c in 0..D {
                y[c][t] = p[c] - here[c];
            }
        }
        let k = &self.stiffness[lo..hi];
        let mut len = [0.0f64; BLOCK];
        let mut s = [0.0f64; BLOCK];
        let mut coef = [0.0f64; BLOCK];
        let inv_xi = &self.inv_xi[lo..hi];
        for t in 0..m {
            let mut r2 = 0.0;
            for yc in &y {
                r2 += yc[t] * yc[t];
            }
            len[t] = r2.sqrt();
            s[t] = len[t] * inv_xi[t] - 1.0;
            // k·s/|y| = k·(1/ξ − 1/|y|): one division
            coef[t] = k[t] as f64 * (inv_xi[t] - 1.0 / len[t]);
        }
        // the common case: elastic and whole, a new largest stretch kept, not touching (the
        // contact distance min(reach, 0.9·ξ) is a stretch of at most −0.1)
        let limit = self.elastic_limit as f32;
        let crush = -self.settings.compressive.unwrap_or(f64::INFINITY);
        let touch = match &self.contact {
            Some(_) => -0.1,
            None => f64::NEG_INFINITY,
        };
        let crush = crush.max(touch);
        let mut rare = 0u32;
        for t in 0..m {
            let st = s[t] as f32;
            let common = sm[t] < limit && st < limit && s[t] > crush;
            sm[t] = if common { sm[t].max(st) } else { sm[t] };
            coef[t] = if common { coef[t] } else { 0.0 };
            rare += u32::from(!common);
        }
        // the sums in four lanes, so that they vectorise (a sum in one order would not)
        let mut sum = SVector::<f64, D>::zeros();
        for c in 0..D {
            let mut lanes = [0.0f64; 4];
            for (cs, ys) in coef[..m].chunks(4).zip(y[c][..m].chunks(4)) {
                for (l, (a, b)) in cs.iter().zip(ys).enumerate() {
                    lanes[l] += a * b;
                }
            }
            sum[c] = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
        }
        if rare > 0 {
            for t in 0..m {
                let st = s[t] as f32;
                let common = sm[t] < limit && st < limit && s[t] > crush;
                if !common {
                    let yt = SVector::<f64, D>::from_fn(|c, _| y[c][t]);
                    sum += self.bond_beyond_elastic(lo + t, yt, len[t], s[t], k[t], &mut sm[t]);
                }
            }
        }
        sum
    }

    /// The force of bond n when it may soften, break, be crushed or touch (the rare case of
    /// [`Self::chunk_forces`]): y the deformed bond, of length `len`, stretch s.
    #[cold]
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn bond_beyond_elastic(
        &self,
        n: usize,
        y: SVector<f64, D>,
        len: f64,
        s: f64,
        stiffness: f32,
        sm: &mut f32,
    ) -> SVector<f64, D> {
        let mut f = SVector::<f64, D>::zeros();
        if let Some(c) = &self.contact {
            let reach = c.reach.min(0.9 / self.inv_xi[n]);
            if len < reach {
                f -= y * (c.stiffness * (reach - len) / len);
            }
        }
        if sm.is_infinite() {
            return f;
        }
        if s as f32 > *sm {
            *sm = s as f32;
        }
        if let Some(crush) = self.settings.compressive {
            if s < -crush {
                *sm = f32::INFINITY;
                return f;
            }
        }
        let mut factor = 1.0;
        if s > 0.0 {
            let d = self.law_of(n).map(|l| l.damage(*sm as f64)).unwrap_or(0.0);
            if d >= 1.0 {
                *sm = f32::INFINITY;
                return f;
            }
            factor = 1.0 - d;
        }
        f + y * (stiffness as f64 * s * factor / len)
    }

    /// The elastic energy held by the bonds (J): ¼·k·(1 − d)·s²·ξ over every bond of every
    /// point (each bond is held by both its points).
    pub fn elastic_energy(&self, x: &[SVector<f64, D>]) -> f64 {
        // each point's energy in parallel, summed in point order: the same bits on any
        // number of threads
        let per_point: Vec<f64> = (0..self.len())
            .into_par_iter()
            .map(|i| {
                let mut e = 0.0;
                for b in self.start[i] as usize..self.start[i + 1] as usize {
                    if self.s_max[b].is_infinite() {
                        continue;
                    }
                    let j = self.neighbour[b] as usize;
                    let xi = 1.0 / self.inv_xi[b];
                    let s = ((x[j] - x[i]).norm() - xi) / xi;
                    let d = if s > 0.0 { self.bond_damage(b) } else { 0.0 };
                    e += 0.25 * self.stiffness[b] as f64 * (1.0 - d) * s * s * xi;
                }
                e
            })
            .collect();
        per_point.iter().sum()
    }

    /// The linearised forces of the body at rest for displacements `u` (every bond intact):
    /// −K·u, K the stiffness of the small-displacement model.
    pub fn linear_forces(&self, u: &[SVector<f64, D>], out: &mut [SVector<f64, D>]) {
        out.par_iter_mut().enumerate().for_each(|(i, o)| {
            let mut sum = SVector::<f64, D>::zeros();
            for b in self.start[i] as usize..self.start[i + 1] as usize {
                let j = self.neighbour[b] as usize;
                let e = (self.x0[j] - self.x0[i]) * self.inv_xi[b];
                let s = e.dot(&(u[j] - u[i])) * self.inv_xi[b];
                sum += e * (self.stiffness[b] as f64 * s);
            }
            *o = sum;
        });
    }

    /// Σ_b k_b/ξ_b of each point (N/m): the Gershgorin bound of its stiffness, from which the
    /// stable step of the explicit integration is Δt ≤ √(2·m_i/Σ k/ξ) (Silling & Askari 2005).
    pub fn stiffness_sums(&self) -> Vec<f64> {
        (0..self.len())
            .map(|i| {
                (self.start[i] as usize..self.start[i + 1] as usize)
                    .map(|b| self.stiffness[b] as f64 * self.inv_xi[b])
                    .sum()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::body::{BodySettings, BondBody};
    use super::super::bonds::Bonds;
    use super::super::family::CubicGrid;
    use super::super::micromodulus::{micromodulus, Body, Influence};
    use super::super::softening::{Fit, Softening};
    use nalgebra::Vector3;
    use std::f64::consts::PI;

    const DX: f64 = 0.005;

    fn grid_points(n: usize) -> Vec<Vector3<f64>> {
        CubicGrid {
            n: [n, n, n],
            dx: DX,
        }
        .points()
    }

    fn law() -> Softening {
        let delta = PI * DX;
        Softening::non_linear(
            &Fit {
                e: 37e9,
                ft: 3.9e6,
                gf: 143.2,
                delta,
                c: micromodulus(37e9, delta, Body::Solid, Influence::Constant),
                thickness: None,
            },
            25.0,
            0.25,
        )
    }

    fn settings(law: Option<Softening>) -> BodySettings {
        let delta = PI * DX;
        BodySettings {
            delta,
            dx: DX,
            c: micromodulus(37e9, delta, Body::Solid, Influence::Constant),
            influence: Influence::Constant,
            surface_correction: true,
            critical_stretch_correction: false,
            law,
            compressive: None,
            contact: false,
        }
    }

    fn body(n: usize, s: BodySettings) -> BondBody<3> {
        let grid = CubicGrid {
            n: [n, n, n],
            dx: DX,
        };
        let v0: f64 = grid.stencil(s.delta).iter().map(|(_, w)| w).sum::<f64>() * DX.powi(3);
        let x0 = grid_points(n);
        let cell = DX.powi(3);
        BondBody::new(x0.clone(), vec![cell; x0.len()], s, Some(v0), &|_, _| true)
    }

    use super::super::test_support::jiggle;

    /// The kernel's forces are the scalar reference's (`bonds.rs`, force densities) times
    /// each point's volume, to the single precision of the stored stiffness (1e-6), elastic
    /// and while bonds soften; the largest stretches agree.
    #[test]
    fn the_kernel_matches_the_scalar_reference() {
        let n = 8;
        let law = law();
        let mut fast = body(n, settings(Some(law)));
        let grid = CubicGrid {
            n: [n, n, n],
            dx: DX,
        };
        let mut slow = Bonds::new(&grid, PI * DX, fast.settings.c, law, true);
        let x0 = grid_points(n);
        let cell = DX.powi(3);
        // elastic, then past s0 = 1.05e-4 on many bonds (a jiggle of 2 µm over 5 mm bonds)
        for (a, seed) in [(1e-7, 1u64), (2e-6, 2)] {
            let x = jiggle(&x0, a, seed);
            let mut f = vec![Vector3::zeros(); x0.len()];
            let mut g = vec![Vector3::zeros(); x0.len()];
            fast.forces(&x, &mut f);
            slow.forces(&x, &x0, &mut g);
            let scale = g.iter().map(|v| v.norm()).fold(0.0, f64::max) * cell;
            for (p, (a, b)) in f.iter().zip(&g).enumerate() {
                assert!(
                    (a - b * cell).norm() <= 1e-6 * scale,
                    "point {p}: {a} against {}",
                    b * cell
                );
            }
            let softened = fast
                .s_max
                .iter()
                .filter(|&&s| s as f64 > law.elastic_limit())
                .count();
            if a > 1e-6 {
                assert!(softened > 100, "{softened} bonds softened");
            }
            for (s, r) in fast.s_max.iter().zip(&slow.s_max) {
                assert!((*s as f64 - r).abs() <= 1e-6 * r.abs().max(1e-9));
            }
        }
    }

    /// At rest nothing pulls; the forces balance under any displacement; the linearised
    /// forces are the kernel's for a small displacement (to 1e-4 of the largest).
    #[test]
    fn forces_vanish_at_rest_balance_and_linearise() {
        let mut b = body(7, settings(None));
        let x0 = b.x0.clone();
        let mut f = vec![Vector3::zeros(); x0.len()];
        b.forces(&x0, &mut f);
        let x = jiggle(&x0, 1e-8, 7);
        let mut g = vec![Vector3::zeros(); x0.len()];
        b.forces(&x, &mut g);
        let largest = g.iter().map(|v| v.norm()).fold(0.0, f64::max);
        assert!(f.iter().all(|v| v.norm() <= 1e-12 * largest));
        let total: Vector3<f64> = g.iter().sum();
        assert!(total.norm() <= 1e-9 * largest, "{total}");
        let u: Vec<_> = x.iter().zip(&x0).map(|(a, b)| a - b).collect();
        let mut lin = vec![Vector3::zeros(); x0.len()];
        b.linear_forces(&u, &mut lin);
        for (a, l) in g.iter().zip(&lin) {
            assert!((a - l).norm() <= 1e-4 * largest);
        }
    }

    /// A body stretched past the critical stretch breaks every bond for good; squeezed past
    /// the compressive critical stretch it breaks too; with contact, points pressed closer
    /// than 0.9·ξ push apart although their bonds are broken.
    #[test]
    fn bonds_break_in_tension_and_compression_and_contact_repels() {
        let law = law();
        let mut b = body(5, settings(Some(law)));
        let x0 = b.x0.clone();
        let mut f = vec![Vector3::zeros(); x0.len()];
        let pulled: Vec<_> = x0
            .iter()
            .map(|p| p * (1.0 + 2.0 * law.critical_stretch()))
            .collect();
        b.forces(&pulled, &mut f);
        assert_eq!(b.broken_bonds(), b.bonds());
        b.forces(&x0, &mut f);
        assert!(f.iter().all(|v| v.norm() == 0.0));
        assert!(b.damage().iter().all(|&d| d == 1.0));

        let mut s = settings(Some(law));
        s.compressive = Some(2e-3);
        let mut c = body(5, s);
        let squeezed: Vec<_> = x0.iter().map(|p| p * (1.0 - 3e-3)).collect();
        c.forces(&squeezed, &mut f);
        assert_eq!(c.broken_bonds(), c.bonds());
        let mut s = settings(Some(law));
        s.compressive = Some(2e-3);
        s.contact = true;
        let mut d = body(5, s);
        let crushed: Vec<_> = x0.iter().map(|p| p * 0.5).collect();
        d.forces(&crushed, &mut f);
        assert_eq!(d.broken_bonds(), d.bonds());
        // the corner point is pushed outwards, away from the body's centre
        let centre = x0.iter().sum::<Vector3<f64>>() / x0.len() as f64;
        assert!(f[0].dot(&(x0[0] - centre)) > 0.0, "{}", f[0]);
    }
}
