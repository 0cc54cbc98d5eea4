//! The counts and signs a run reports agree wherever they appear (docs/outputs.md): the
//! cracked and crushed particles of summary.json are those the crack map's legend counts,
//! and the forces of summary.json carry the sign force_displacement.svg plots.

use sppm::run::{run, RunOptions};
use sppm::Scene;
use std::path::Path;

/// Run a shipped scene at a coarse spacing and write its outputs into a fresh folder.
fn run_shipped(file: &str, spacing: &str) -> (sppm::Outcome, std::path::PathBuf) {
    let set = [format!("discretisation.spacing={spacing}")];
    let scene = Scene::from_file(Path::new(file), &set).unwrap();
    let o = run(
        &scene,
        &RunOptions {
            progress: false,
            threads: Some(1),
        },
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!(
        "sppm-agree-{}-{}",
        scene.name(),
        std::process::id()
    ));
    sppm::output::write_all(&o, &dir).unwrap();
    (o, dir)
}

/// The number in the crack map's legend just after `label` and " (" or before it.
fn legend_count(svg: &str, after: &str) -> usize {
    let at = svg
        .find(after)
        .unwrap_or_else(|| panic!("{after:?} not in the legend"));
    let rest = &svg[at + after.len()..];
    let digits: String = rest
        .trim_start_matches(|c: char| !c.is_ascii_digit())
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().unwrap()
}

#[test]
fn summary_counts_are_the_crack_maps() {
    for file in [
        "lattices/uniaxial_tension.toml",
        "lattices/uniaxial_compression.toml",
    ] {
        let (o, dir) = run_shipped(file, "0.02");
        let s = &o.summary;
        let svg = std::fs::read_to_string(dir.join("crack_map.svg")).unwrap();
        let crushed = legend_count(&svg, "crushed, w_c ≥ 0.99");
        let cracked_at = svg.find("with w_t ≥ 0.99").unwrap();
        let before = &svg[..cracked_at];
        let cracked: usize = before
            .rsplit(|c: char| !c.is_ascii_digit())
            .find(|t| !t.is_empty())
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(Some(crushed), s.crushed_particles, "{file}");
        assert_eq!(Some(cracked), s.cracked_particles, "{file}");
        let damage = o.damage.as_ref().unwrap();
        // a specimen that failed has particles of its own kind of failure
        assert!(
            s.cracked_particles.unwrap() + s.crushed_particles.unwrap() > 0,
            "{file}"
        );
        assert!(damage.iter().all(|p| !(p.cracked() && p.crushed())));
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// In compression the probe group is pushed down: its reaction is negative, and both
/// summary.json and the plot turn the sign, and say so.
#[test]
fn compression_forces_are_reported_positive_and_say_so() {
    let (o, dir) = run_shipped("lattices/uniaxial_compression.toml", "0.02");
    let s = &o.summary;
    assert!(s.sign_turned);
    assert!(s.peak_force_n > 0.0, "{}", s.peak_force_n);
    // the block is broken through by the end of the stroke: what it still carries is zero
    // to round-off, never a force of the other sign
    assert!(
        s.final_force_n >= -1e-9 * s.peak_force_n,
        "{}",
        s.final_force_n
    );
    assert!(s.final_force_n <= s.peak_force_n);
    let svg = std::fs::read_to_string(dir.join("force_displacement.svg")).unwrap();
    assert!(svg.contains("(sign turned)"));
    let json = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(json.contains("\"sign_turned\": true"), "{json}");
    std::fs::remove_dir_all(&dir).ok();
    let (t, dir) = run_shipped("lattices/uniaxial_tension.toml", "0.02");
    assert!(!t.summary.sign_turned && t.summary.peak_force_n > 0.0);
    std::fs::remove_dir_all(&dir).ok();
}
