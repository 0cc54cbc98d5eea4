//! The cracks that cross a 3D specimen normal to its load axis, as a prism in direct tension
//! breaks: where each crack lies along the axis and how much of the section it cuts.
//!
//! The cracked particles (w_t at or above a threshold) are sorted along the load axis and cut
//! into bands wherever two neighbours in that order lie more than [`BAND_GAP_SPACINGS`]
//! particle spacings apart: one crack, however rough, is a run of cracked particles without
//! such a gap. A band's coverage is the share of the section's columns (squares of
//! [`COLUMN_SPACINGS`] spacings in the two other axes that hold a particle of the body) in
//! which the band has a cracked particle. A band crosses the section when it covers at least
//! [`ACROSS_COVERAGE`] of it: more than half of the section cannot carry load past it, and a
//! second crack that started at a face and stopped (as in the two-crack prisms of Nikravesh
//! Kazeroni (2017), §5.2) covers less.

/// Largest gap (in particle spacings) between consecutive cracked particles along the load
/// axis within one band: two spacings bridge the roughness of a crack across random
/// particles (a band a spacing or two thick) and split cracks a few spacings apart.
pub const BAND_GAP_SPACINGS: f64 = 2.0;

/// The side of a column of the section, in particle spacings: each column then holds
/// particles on every lattice plane, so a crack that cuts it damages one of them.
pub const COLUMN_SPACINGS: f64 = 2.0;

/// The share of the section's columns a band must cover to cross the section.
pub const ACROSS_COVERAGE: f64 = 0.5;

/// One band of cracked particles across the load axis.
#[derive(Clone, Debug, PartialEq)]
pub struct CrackBand {
    /// Mean position of its particles along the load axis (m).
    pub position_m: f64,
    /// That position as a share of the body's extent along the axis: 0 at the lower end,
    /// 1 at the upper.
    pub share: f64,
    /// Share of the section's columns in which it has a cracked particle.
    pub coverage: f64,
    /// Its cracked particles.
    pub particles: usize,
}

impl CrackBand {
    /// Does it cross the section ([`ACROSS_COVERAGE`])?
    pub fn crosses(&self) -> bool {
        self.coverage >= ACROSS_COVERAGE
    }
}

/// The bands of the particles at `x0` whose tensile damage `wt` is at least `threshold`,
/// along `axis` (0, 1 or 2), in order along it; `spacing` is the particle spacing L0.
pub fn crack_bands(
    x0: &[[f64; 3]],
    wt: &[f64],
    threshold: f64,
    axis: usize,
    spacing: f64,
) -> Vec<CrackBand> {
    let (a, b) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let (lo, hi) = extent(x0, axis);
    let (lo_a, _) = extent(x0, a);
    let (lo_b, _) = extent(x0, b);
    let side = COLUMN_SPACINGS * spacing;
    let column = |p: &[f64; 3]| {
        (
            ((p[a] - lo_a) / side).floor() as i64,
            ((p[b] - lo_b) / side).floor() as i64,
        )
    };
    let mut section: Vec<(i64, i64)> = x0.iter().map(column).collect();
    section.sort_unstable();
    section.dedup();
    let mut cracked: Vec<usize> = (0..x0.len()).filter(|&i| wt[i] >= threshold).collect();
    cracked.sort_by(|&i, &j| x0[i][axis].total_cmp(&x0[j][axis]));
    let gap = BAND_GAP_SPACINGS * spacing;
    let mut bands = vec![];
    let mut start = 0;
    for k in 1..=cracked.len() {
        let split = k == cracked.len() || x0[cracked[k]][axis] - x0[cracked[k - 1]][axis] > gap;
        if !split {
            continue;
        }
        let members = &cracked[start..k];
        let mut cut: Vec<(i64, i64)> = members.iter().map(|&i| column(&x0[i])).collect();
        cut.sort_unstable();
        cut.dedup();
        let position = members.iter().map(|&i| x0[i][axis]).sum::<f64>() / members.len() as f64;
        bands.push(CrackBand {
            position_m: position,
            share: (position - lo) / (hi - lo),
            coverage: cut.len() as f64 / section.len() as f64,
            particles: members.len(),
        });
        start = k;
    }
    bands
}

/// The smallest and largest coordinate along `axis`.
fn extent(x0: &[[f64; 3]], axis: usize) -> (f64, f64) {
    x0.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p[axis]), h.max(p[axis]))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic grid of spacing 1 over [0, n)² × [0, h) and its positions.
    fn grid(n: usize, h: usize) -> Vec<[f64; 3]> {
        let mut x = vec![];
        for k in 0..h {
            for j in 0..n {
                for i in 0..n {
                    x.push([i as f64, j as f64, k as f64]);
                }
            }
        }
        x
    }

    #[test]
    fn one_plane_of_cracked_particles_is_one_band_across_at_its_height() {
        let x = grid(10, 30);
        let wt: Vec<f64> = x
            .iter()
            .map(|p| if p[2] == 12.0 { 1.0 } else { 0.0 })
            .collect();
        let bands = crack_bands(&x, &wt, 0.9, 2, 1.0);
        assert_eq!(bands.len(), 1);
        let b = &bands[0];
        assert_eq!(b.particles, 100);
        assert_eq!(b.position_m, 12.0);
        assert!((b.share - 12.0 / 29.0).abs() < 1e-12);
        assert_eq!(b.coverage, 1.0);
        assert!(b.crosses());
    }

    #[test]
    fn a_rough_crack_is_one_band_and_two_cracks_apart_are_two() {
        let x = grid(10, 30);
        // a crack stepping between z = 10 and z = 11 across x, and a second at z = 20
        let wt: Vec<f64> = x
            .iter()
            .map(|p| {
                let rough = p[2] == if p[0] < 5.0 { 10.0 } else { 11.0 };
                if rough || p[2] == 20.0 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        let bands = crack_bands(&x, &wt, 0.9, 2, 1.0);
        assert_eq!(bands.len(), 2, "{bands:?}");
        assert!((bands[0].position_m - 10.5).abs() < 1e-12);
        assert!(bands.iter().all(CrackBand::crosses));
    }

    #[test]
    fn a_crack_over_a_quarter_of_the_section_does_not_cross_it() {
        let x = grid(12, 30);
        // cracked at z = 5 only where x < 6 and y < 6: a quarter of the section
        let wt: Vec<f64> = x
            .iter()
            .map(|p| {
                if p[2] == 5.0 && p[0] < 6.0 && p[1] < 6.0 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        let bands = crack_bands(&x, &wt, 0.9, 2, 1.0);
        assert_eq!(bands.len(), 1);
        assert_eq!(bands[0].coverage, 0.25);
        assert!(!bands[0].crosses());
        // below the threshold nothing is cracked
        let weak: Vec<f64> = wt.iter().map(|w| 0.5 * w).collect();
        assert!(crack_bands(&x, &weak, 0.9, 2, 1.0).is_empty());
    }

    #[test]
    fn the_axis_chooses_the_section() {
        let x = grid(10, 30);
        // a plane of cracks normal to x at x = 3
        let wt: Vec<f64> = x
            .iter()
            .map(|p| if p[0] == 3.0 { 1.0 } else { 0.0 })
            .collect();
        let along_x = crack_bands(&x, &wt, 0.9, 0, 1.0);
        assert_eq!(along_x.len(), 1);
        assert_eq!(along_x[0].coverage, 1.0);
        // seen along z the same particles spread over every height: one band covering only
        // the columns at x = 2..3 (one column of five in x)
        let along_z = crack_bands(&x, &wt, 0.9, 2, 1.0);
        assert_eq!(along_z.len(), 1);
        assert!((along_z[0].coverage - 0.2).abs() < 1e-12);
    }
}
