//! The sizes of a Monte Carlo study: `--sizes`, the size variant of a scene
//! ([`SPACING_RULE`]), the seed of a realisation of a size, and the nominal strength σN of
//! a run.

use super::nominal::Nominal;
use crate::random_field::splitmix64;
use crate::scene::BodySpec;
use crate::study::size_effect_report::size_um;
use crate::Scene;
use anyhow::bail;

/// The van Vliet dog-bone sizes A–F (docs/validation.md §D): D in m.
pub const DOGBONE_SIZES: [(char, f64); 6] = [
    ('A', 0.05),
    ('B', 0.1),
    ('C', 0.2),
    ('D', 0.4),
    ('E', 0.8),
    ('F', 1.6),
];

/// The scaling rule of the size variant, the one text the documentation, `--help` and
/// size_effect.json state it in.
macro_rules! displacement_rule {
    () => {
        "every loaded group's displacement × √(D/D0)"
    };
}
macro_rules! spacing_rule {
    () => {
        concat!(
            "body.size = D; discretisation.spacing = s0·min(1, D/D0); ",
            displacement_rule!(),
            "; with the relaxation solver, solver.max_iterations × max(1, D/D0) (D0, s0: the \
             scene's size and spacing)"
        )
    };
}

/// The rule that makes a size variant, as recorded in size_effect.json.
pub const SPACING_RULE: &str = spacing_rule!();

/// How the loaded groups' displacement scales with the size: a part of [`SPACING_RULE`].
pub const DISPLACEMENT_RULE: &str = displacement_rule!();

/// The paragraph of `sppm study montecarlo --help` that states [`SPACING_RULE`].
pub const SIZE_VARIANT_HELP: &str = concat!(
    "Size variant of size D from a scene of size D0 and spacing s0 (--sizes, dog-bones only): ",
    spacing_rule!(),
    "."
);

/// Read `--sizes`: dog-bone letters A–F or sizes D in m (> 0), comma-separated; returned
/// sorted and without repeats.
pub fn parse_sizes(text: &str) -> anyhow::Result<Vec<f64>> {
    let items = crate::study::options::comma_items(text);
    if items.is_empty() {
        bail!("--sizes `{text}`: give dog-bone letters A–F or sizes D in m, comma-separated");
    }
    let mut sizes = Vec::new();
    for s in items {
        let letter = DOGBONE_SIZES
            .iter()
            .find(|(c, _)| s.len() == 1 && s.eq_ignore_ascii_case(&c.to_string()));
        let d = match letter {
            Some((_, d)) => *d,
            None => match s.parse::<f64>() {
                Ok(d) if d.is_finite() && d > 0.0 => d,
                _ => bail!(
                    "--sizes `{text}`: `{s}` is neither a dog-bone letter A–F nor a size D in m > 0"
                ),
            },
        };
        sizes.push(d);
    }
    sizes.sort_by(f64::total_cmp);
    sizes.dedup_by(|a, b| size_um(*a) == size_um(*b));
    Ok(sizes)
}

/// The seed of realisation `r` (0-based) of size `d` (m) in a study of seed `study_seed`: a
/// SplitMix64 hash of (S, D in µm, r), kept below 2^63 so that it is a TOML integer.
pub fn realisation_seed(study_seed: u64, d: f64, r: usize) -> u64 {
    splitmix64(splitmix64(splitmix64(study_seed) ^ size_um(d)) ^ r as u64) >> 1
}

/// The nominal strength σN (Pa) of a run of `scene` with peak force `peak_force_n`, defined
/// per body ([`Nominal`]); an error naming the body when σN is not defined for it.
pub fn nominal_strength(scene: &Scene, peak_force_n: f64) -> anyhow::Result<f64> {
    Ok(Nominal::of(scene)?.strength(peak_force_n))
}

/// The size D of a dog-bone body: the 2D dog-bone or a prism of its section.
pub(super) fn dogbone_size(body: &BodySpec) -> Option<f64> {
    match body {
        BodySpec::Dogbone { size } => Some(*size),
        BodySpec::Prism { section, .. } => dogbone_size(section),
        _ => None,
    }
}

/// The size D (m) of `scene` in the size effect ([`Nominal::size`]).
pub(super) fn nominal_size(scene: &Scene) -> anyhow::Result<f64> {
    Ok(Nominal::of(scene)?.size())
}

/// The label of a size: D in mm, e.g. `D50mm`.
pub(super) fn size_label(d: f64) -> String {
    format!("D{}mm", size_um(d) as f64 / 1000.0)
}

/// A float as a TOML value.
fn toml_float(v: f64) -> String {
    format!("{v:?}")
}

/// The overrides that make the size variant of size `d` from `base` ([`SPACING_RULE`]).
pub fn size_overrides(base: &Scene, d: f64) -> Vec<String> {
    let Some(d0) = dogbone_size(&base.body) else {
        return vec![];
    };
    let key = match base.body {
        BodySpec::Prism { .. } => "body.section.size",
        _ => "body.size",
    };
    let ratio = d / d0;
    let mut o = vec![
        format!("{key}={}", toml_float(d)),
        format!(
            "discretisation.spacing={}",
            toml_float(base.discretisation.spacing * ratio.min(1.0))
        ),
    ];
    for (i, g) in base.groups.iter().enumerate() {
        if let Some(load) = &g.load {
            o.push(format!(
                "groups.{i}.load.displacement={}",
                toml_float(load.delta() * ratio.sqrt())
            ));
        }
    }
    if base.solver.method.is_incremental() {
        let m = (base.solver.max_iterations() as f64 * ratio.max(1.0)).round() as usize;
        o.push(format!("solver.max_iterations={m}"));
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn sizes_take_letters_and_metres() {
        assert_eq!(
            parse_sizes("F,a,0.2,B").unwrap(),
            vec![0.05, 0.1, 0.2, 1.6],
            "sorted, repeats (B = 0.1) kept once"
        );
        let e = parse_sizes("A,G").unwrap_err().to_string();
        assert!(e.contains("--sizes") && e.contains("`G`"), "{e}");
        assert!(parse_sizes("0.1,-0.2").is_err());
        assert!(parse_sizes(" , ").is_err());
    }

    #[test]
    fn seeds_depend_on_study_seed_size_and_realisation_only() {
        let s = realisation_seed(7, 0.1, 3);
        assert_eq!(s, realisation_seed(7, 0.1 + 1e-9, 3), "same µm, same seed");
        assert!(s < 1 << 63, "a TOML integer");
        let mut all = std::collections::HashSet::new();
        for seed in [7, 8] {
            for d in [0.05, 0.1, 0.2] {
                for r in 0..50 {
                    assert!(all.insert(realisation_seed(seed, d, r)));
                }
            }
        }
    }

    #[test]
    fn size_variant_follows_the_spacing_rule() {
        let base = Scene::from_file(Path::new("lattices/dogbone_D.toml"), &[]).unwrap();
        let o = size_overrides(&base, 0.1);
        assert_eq!(o[0], "body.size=0.1");
        assert_eq!(o[1], "discretisation.spacing=0.002", "8 mm × 0.1/0.4");
        assert_eq!(
            o[2], "groups.2.load.displacement=0.00025",
            "0.5 mm × √(1/4)"
        );
        let o = size_overrides(&base, 1.6);
        assert_eq!(
            o[1], "discretisation.spacing=0.008",
            "the scene's spacing above D0"
        );
        assert_eq!(o[2], "groups.2.load.displacement=0.001", "0.5 mm × √4");
        assert_eq!(o.len(), 3, "explicit: max_iterations is not set");
        let s = Scene::from_file(Path::new("lattices/dogbone_D.toml"), &o).unwrap();
        assert!(matches!(s.body, BodySpec::Dogbone { size } if size == 1.6));
        let sigma = nominal_strength(&s, 1.0e5).unwrap();
        assert!((sigma - 1.0e5 / (0.6 * 1.6 * 0.1)).abs() < 1e-6);
        let relax = Scene::from_file(Path::new("lattices/dogbone_montecarlo.toml"), &[]).unwrap();
        let o = size_overrides(&relax, 1.6);
        assert_eq!(o[3], "solver.max_iterations=2000", "500 × 1.6/0.4");
        let o = size_overrides(&relax, 0.05);
        assert_eq!(o[3], "solver.max_iterations=500", "not below the scene's");
    }

    /// 3D: a prism of the dog-bone section scales its section's size (thickness kept) and
    /// its σN is the mean stress over the neck; a box pulled along z reads σN over its section.
    #[test]
    fn size_variant_and_strength_in_3d() {
        let base = Scene::from_file(Path::new("lattices/dogbone_B_3d.toml"), &[]).unwrap();
        let o = size_overrides(&base, 0.2);
        assert_eq!(o[0], "body.section.size=0.2");
        assert_eq!(
            o[1], "discretisation.spacing=0.00625",
            "the scene's above D0"
        );
        let s = Scene::from_file(Path::new("lattices/dogbone_B_3d.toml"), &o).unwrap();
        assert_eq!(dogbone_size(&s.body), Some(0.2));
        let sigma = nominal_strength(&s, 1.0e5).unwrap();
        assert!((sigma / (1.0e5 / (0.6 * 0.2 * 0.1)) - 1.0).abs() < 1e-12);
        let prism = Scene::from_file(Path::new("lattices/tension_prism_3d.toml"), &[]).unwrap();
        let sigma = nominal_strength(&prism, 1.0e5).unwrap();
        assert!((sigma / (1.0e5 / (0.15 * 0.15)) - 1.0).abs() < 1e-12);
    }
}
