//! Damage laws behind a trait (docs/model.md §6): what a material's damage and plasticity decide,
//! apart from the kernel that moves the particles (`solver::inelastic`).
//!
//! The kernel owns the kinematics: for each particle it computes, bond by bond, the total
//! stretch S_T, the elastic stretch S_e = S_T − S_P (3.38), the damage factor d the law
//! gives the bond, the dilatation term, the bond forces (through `model::force_state`) and
//! the time integration; it keeps each particle's committed and trial law state and the
//! plastic stretch states S_Ps, and commits them once per step. The law decides the rest.
//!
//! # Adding a damage law
//!
//! A new law (say the bond-based bilinear softening of Hobbs (2021), or the failure criteria of
//! Ness (2019)) implements [`DamageLaw`] and nothing else; neither the kernel nor the pipeline
//! changes:
//!
//! 1. `type State`: what one particle remembers (e.g. the largest stretch reached), `Copy`
//!    and `Default` (the undamaged state).
//! 2. [`DamageLaw::kernel`]: whether the kernel must carry plastic stretch and read the
//!    compressive branch ([`Kernel::Full`]) or not ([`Kernel::Tension`]).
//! 3. [`DamageLaw::bond_factor`]: the factor d ∈ [0, 1] (and √d) a bond between two particles
//!    carries, from their committed states and the sign of its elastic stretch. It must be
//!    symmetric bit for bit in (i, j), so that the two ends of a bond see the same force.
//! 4. [`DamageLaw::update`]: the particle's trial state (and plastic stretch increments, for a
//!    [`Kernel::Full`] law) from its bonds' stretches ([`ParticleBonds`]: total, elastic,
//!    damaged, the strain fit, its micro-modulus and length scale).
//! 5. [`DamageLaw::view`]: the state as the outputs show it ([`ParticleDamage`]).
//! 6. Optionally [`DamageLaw::SERIES_DAMAGE`] and [`DamageLaw::series_damage`], if its bond
//!    factor is the two springs in series (3.37) of two damage variables per particle: pass 1
//!    then runs four particles at once (SIMD).
//!
//! Then `run` builds `solver::inelastic::DamageKernel::<K, YourLaw>::new(law, &body)` where it
//! builds the two-spring law today.

use super::dimension::{Dim, Dimension};

/// Which kernel a law needs (the solver's `KernelSet` without the elastic one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// Tensile damage only: no plastic stretch, no compressive branch.
    Tension,
    /// Plastic stretch and the compressive branch.
    Full,
}

/// A particle's damage and plasticity as the outputs show them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ParticleDamage {
    /// Tensile damage w_t.
    pub wt: f64,
    /// Compressive damage w_c.
    pub wc: f64,
    /// ε_I when tensile damage started.
    pub eps_init: f64,
    pub initiated: bool,
    /// Has yielded at least once.
    pub yielded: bool,
}

/// Tensile damage w_t at and above which the outputs count a particle as cracked.
pub const CRACKED_WT: f64 = 0.99;

/// Compressive damage w_c at and above which the outputs count a particle that is not
/// cracked as crushed. Compressive damage also follows tensile damage (4.16): w_c reaches
/// 0.5 at w_t = 0.62 (w_t,cr = 1/3) in any partly open crack, but 0.99 only at w_t ≥ 0.9916,
/// so w_c ≥ 0.99 without w_t ≥ 0.99 is the crushing beyond the ultimate strain (4.17).
pub const CRUSHED_WC: f64 = 0.99;

impl ParticleDamage {
    /// Whether the particle has failed (w_t or w_c ≥ 0.99).
    pub fn failed(&self) -> bool {
        self.wt >= 0.99 || self.wc >= 0.99
    }

    /// Cracked: w_t ≥ [`CRACKED_WT`] (summary.json's `cracked_particles`, the crack map).
    pub fn cracked(&self) -> bool {
        self.wt >= CRACKED_WT
    }

    /// Crushed: w_c ≥ [`CRUSHED_WC`] and not cracked (summary.json's `crushed_particles`,
    /// the crack map's ×).
    pub fn crushed(&self) -> bool {
        self.wc >= CRUSHED_WC && !self.cracked()
    }
}

/// What the kernel hands a law about one particle's bonds at the current positions, slot by
/// slot (0 and `used = false` in empty slots).
pub struct ParticleBonds<'a, const D: usize, const K: usize>
where
    Dim<D>: Dimension<D>,
{
    /// The particle.
    pub i: usize,
    /// Its least-squares strain projector (`model::dimension`, `Dimension::strain_fit`).
    pub fit: &'a <Dim<D> as Dimension<D>>::StrainFit<K>,
    /// Total stretches S_T.
    pub total: &'a [f64; K],
    /// Elastic stretches S_e = S_T − S_P.
    pub elastic: &'a [f64; K],
    /// Damaged elastic stretches d·S_e.
    pub damaged: &'a [f64; K],
    pub used: &'a [bool; K],
    /// Whether the damaged elastic stretches equal the total ones (no damage, no plastic
    /// stretch): one strain serves both.
    pub undamaged: bool,
    /// Micro-modulus a_i.
    pub a: f64,
    /// The FCC second-neighbour modulus c_i and its first slot (docs/model.md §3 erratum): slots
    /// `first..K` have the bond modulus a_i + c_i; `None` without second neighbours.
    pub second: Option<(f64, usize)>,
    /// The undamaged dilatation term b_i·Σ S_e (for the force states of plastic flow).
    pub b_theta_elastic: f64,
    /// Every particle's length scale L0,i (m; read through [`ParticleBonds::length`]).
    pub lengths: &'a [f64],
    /// The strain the criteria (initiation, yield) read instead of the particle's own damaged
    /// elastic strain, where the kernel averages it over the particle's neighbourhood
    /// (random particles; `solver::inelastic`); `None`: the particle's own.
    pub criteria_strain: Option<&'a crate::model::dimension::Tensor<D>>,
}

impl<const D: usize, const K: usize> ParticleBonds<'_, D, K>
where
    Dim<D>: Dimension<D>,
{
    /// The particle's length scale L0,i (m), e.g. for the crack band (read only where a law
    /// needs it).
    #[inline(always)]
    pub fn length(&self) -> f64 {
        self.lengths[self.i]
    }

    /// The particle's own bond modulus in slot k: a_i, or a_i + c_i in a second-neighbour
    /// slot (docs/model.md §3 erratum), for its force states (3.8).
    #[inline(always)]
    pub fn modulus(&self, k: usize) -> f64 {
        crate::model::force_state::slot_modulus(self.a, self.second, k)
    }
}

/// A damage law of particles in D dimensions with K bond slots (see the module documentation
/// for how to add one).
pub trait DamageLaw<const D: usize, const K: usize>: Send + Sync + 'static
where
    Dim<D>: Dimension<D>,
{
    /// What one particle remembers; `Default` is undamaged.
    type State: Copy + Default + Send + Sync + PartialEq + std::fmt::Debug + 'static;

    /// The kernel this law needs.
    fn kernel(&self) -> Kernel;

    /// (d, √d) of a bond between particles in states `i` and `j` with elastic stretch
    /// `elastic_stretch`; `FULL` is the kernel running ([`Kernel::Full`]). The second must be
    /// `d.sqrt()` bit for bit: the kernel's pass 2 recomputes it so from d
    /// (`solver::inelastic::SlotCache`).
    fn bond_factor<const FULL: bool>(
        &self,
        i: &Self::State,
        j: &Self::State,
        elastic_stretch: f64,
    ) -> (f64, f64);

    /// Whether [`DamageLaw::bond_factor`] is the two springs in series (3.37) of the damage
    /// variables [`DamageLaw::series_damage`] gives: with w = w_t of both particles where
    /// S_e ≥ 0, w_c where S_e < 0 and `FULL` (0 otherwise), (1, 1) when both w are 0, and
    /// `model::damage::damage_factor` and its square root otherwise. A law that says so gets
    /// the kernel's SIMD pass 1, which evaluates that rule four bonds at once, bit for bit as
    /// `bond_factor` would (`solver::inelastic` tests it); the default, `false`, runs the scalar
    /// pass through `bond_factor`.
    const SERIES_DAMAGE: bool = false;

    /// (w_t, w_c) of a particle in `state`, read only where [`DamageLaw::SERIES_DAMAGE`].
    fn series_damage(&self, _state: &Self::State) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// Update `state` (the committed state on entry, the trial state on exit) and, with
    /// `FULL`, the plastic stretch states `sps` (committed on entry) of particle `bonds.i`.
    fn update<const FULL: bool>(
        &self,
        bonds: &ParticleBonds<'_, D, K>,
        state: &mut Self::State,
        sps: &mut [f64; K],
    );

    /// The state as the outputs show it.
    fn view(&self, state: &Self::State) -> ParticleDamage;
}
