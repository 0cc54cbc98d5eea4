//! Shared helpers of the verification tests.
#![allow(dead_code)]

use nalgebra::{Matrix3, Vector2, Vector3};
use sppm::run::Model;
/// The hexagonal lattice's model (most tests).
pub type Prepared = Model<6>;
use sppm::solver::linear::LinearOperator;
use sppm::solver::modal::static_response;
use sppm::Scene;

/// A rectangular plate in uniaxial tension: bottom rows held in y, one particle at the
/// bottom centre held in x, top rows pulled `strain × height` in y.
pub fn plate_toml(
    width: f64,
    height: f64,
    spacing: f64,
    rotation: f64,
    plane: &str,
    correction: bool,
    nu: f64,
) -> String {
    format!(
        r#"
name = "plate"
[body]
shape = "rectangle"
width = {width}
height = {height}
[discretisation]
spacing = {spacing}
rotation_deg = {rotation}
surface_correction = {correction}
[material]
E = 30.0e9
nu = {nu}
rho = 2400.0
thickness = 0.05
plane = "{plane}"
[[groups]]
name = "bottom"
select = {{ by = "edge", edge = "bottom", rows = 2 }}
fix = ["y"]
[[groups]]
name = "anchor"
select = {{ by = "box", min = [{ax0}, -{h}], max = [{ax1}, {h}] }}
fix = ["x"]
[[groups]]
name = "top"
select = {{ by = "edge", edge = "top", rows = 2 }}
load = {{ component = "y", displacement = {disp} }}
[loading]
end_periods = 4.0
[damping]
internal = 0.2
external = 1.0
"#,
        ax0 = 0.5 * width - 0.6 * spacing,
        ax1 = 0.5 * width + 0.6 * spacing,
        h = 0.6 * spacing,
        disp = 1e-4 * height,
    )
}

pub fn scene(toml: &str) -> Scene {
    Scene::from_toml_str(toml, &[]).expect("test scene is valid")
}

/// Prescribed displacement field at full load.
pub fn full_load<const K: usize>(p: &Model<K>) -> Vec<Vector2<f64>> {
    let mut u = vec![Vector2::zeros(); p.particles.len()];
    for pr in &p.prescribed {
        u[pr.particle as usize][pr.component as usize] = pr.amplitude;
    }
    u
}

/// Static small-strain response to the full prescribed displacements.
pub fn static_solution<const K: usize>(p: &Model<K>) -> Vec<Vector2<f64>> {
    static_response(&p.mech, &p.particles.x0, &p.constrained, &full_load(p)).expect("static solve")
}

/// Reaction along y of a group for displacements u (linearised forces).
pub fn reaction_y<const K: usize>(p: &Model<K>, u: &[Vector2<f64>], group: &str) -> f64 {
    let mut op = LinearOperator::new(&p.mech, &p.particles.x0);
    let mut f = vec![Vector2::zeros(); u.len()];
    op.internal_forces(u, &mut f);
    let g = p.groups.iter().find(|g| g.name == group).unwrap();
    -g.members.iter().map(|&i| f[i as usize].y).sum::<f64>()
}

/// Least-squares affine fit u ≈ A·x + c over the particles selected by `keep`; returns A.
pub fn fit_gradient(
    x0: &[Vector2<f64>],
    u: &[Vector2<f64>],
    keep: impl Fn(&Vector2<f64>) -> bool,
) -> nalgebra::Matrix2<f64> {
    let mut ata = Matrix3::zeros();
    let mut atb = [Vector3::zeros(), Vector3::zeros()];
    for (x, ui) in x0.iter().zip(u) {
        if !keep(x) {
            continue;
        }
        let row = Vector3::new(x.x, x.y, 1.0);
        ata += row * row.transpose();
        atb[0] += row * ui.x;
        atb[1] += row * ui.y;
    }
    let inv = ata.try_inverse().unwrap();
    let gx = inv * atb[0];
    let gy = inv * atb[1];
    nalgebra::Matrix2::new(gx[0], gx[1], gy[0], gy[1])
}

/// E and ν of a plate measured as an engineer would: σ = F/(W·t), strains fitted over the
/// middle half of the plate (away from edges and grips).
pub fn measure_e_nu<const K: usize>(
    p: &Model<K>,
    width: f64,
    height: f64,
    thickness: f64,
) -> (f64, f64) {
    let u = static_solution(p);
    let f = reaction_y(p, &u, "top");
    let cx = 0.5 * width;
    let cy = 0.5 * height;
    let g = fit_gradient(&p.particles.x0, &u, |x| {
        (x.x - cx).abs() <= 0.25 * width && (x.y - cy).abs() <= 0.25 * height
    });
    let (exx, eyy) = (g[(0, 0)], g[(1, 1)]);
    let sigma = f / (width * thickness);
    (sigma / eyy, -exx / eyy)
}

/// The TOML text of [`tension_block`].
pub fn tension_block_toml(height: f64, spacing: f64) -> String {
    format!(
        r#"
name = "block"
[body]
shape = "rectangle"
width = 0.15
height = {height}
[discretisation]
spacing = {spacing}
[material]
nu = 0.2
rho = 2323.0
thickness = 0.15
[concrete]
preset = "splm_block"
ft = 2.6168e6
fy = 22.983e6
[[groups]]
name = "bottom"
select = {{ by = "edge", edge = "bottom", rows = 2 }}
fix = ["y"]
[[groups]]
name = "anchor"
select = {{ by = "nearest", point = [0.075, 0.0] }}
fix = ["x"]
[[groups]]
name = "top"
select = {{ by = "edge", edge = "top", rows = 2 }}
load = {{ component = "y" }}
[loading]
end_periods = 60.0
[damping]
internal = 0.2
external = 0.2
[output]
records = 400
"#
    )
}

/// A block 150 mm wide, `height` high, 150 mm thick, of the Table 1 concrete, pulled at the
/// top rows by 1.5·COD_c (the default), held at the bottom rows, one particle held in x.
pub fn tension_block(height: f64, spacing: f64, overrides: &[&str]) -> Scene {
    let text = tension_block_toml(height, spacing);
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scene::from_toml_str(&text, &o).unwrap()
}

/// The rows of a CSV file as maps from column to value.
pub fn csv_rows(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut rd = csv::Reader::from_path(path).unwrap();
    let h = rd.headers().unwrap().clone();
    rd.records()
        .map(|r| {
            let r = r.unwrap();
            h.iter()
                .zip(r.iter())
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// Run the sppm binary in the crate folder.
pub fn sppm(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sppm"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sppm runs")
}

/// A coarse dog-bone for study tests (D0 = 0.1 m at L0 = 8 mm, 223 particles, an f't random
/// field, relaxation to 80% after the peak): tests/suite/montecarlo.rs and
/// tests/suite/reliability_studies.rs.
pub const TINY_DOGBONE: &str = r#"
name = "tiny_dogbone"
[body]
shape = "dogbone"
size = 0.1
[discretisation]
spacing = 0.008
[material]
nu = 0.2
rho = 2183.0
thickness = 0.1
[concrete]
preset = "splm_dogbone"
[[random_field]]
property = "ft"
correlation = "exponential"
length = 0.016
marginal = "normal"
cov = 0.1
[[groups]]
name = "bottom"
select = { by = "edge", edge = "bottom", rows = 2 }
fix = ["y"]
[[groups]]
name = "anchor"
select = { by = "nearest", point = [0.0, 0.0] }
fix = ["x"]
[[groups]]
name = "top"
select = { by = "edge", edge = "top", rows = 2 }
load = { component = "y", displacement = 0.5e-3 }
[solver]
method = "relaxation"
# a few increments around the peak stop at max_iterations with 1–2% out of balance
# (seeds 1–3); the study's bookkeeping, not the solver, is under test here
max_residual = 0.05
[loading]
stop_after_peak = 0.8
"#;

/// Run `cmd` with stdout and stderr captured, for at most `limit`: its output, or `None` when
/// it was still running then (it is killed). The pipes are read while it runs, so a chatty
/// command never stalls on a full pipe.
pub fn run_limited(
    cmd: &mut std::process::Command,
    limit: std::time::Duration,
) -> Option<std::process::Output> {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the command starts");
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    };
    let (stdout, stderr) = (out.join().unwrap(), err.join().unwrap());
    status.map(|status| std::process::Output {
        status,
        stdout,
        stderr,
    })
}

/// Wait until `ready()` holds; fail with `what` if it does not within `limit`.
pub fn wait_until(limit: std::time::Duration, what: &str, ready: impl Fn() -> bool) {
    let start = std::time::Instant::now();
    while !ready() {
        assert!(start.elapsed() < limit, "{what}: not within {limit:?}");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// The split cylinder's reference peak (5.6) (Rocco et al., docs/validation.md §C):
/// P = (π/2)·f't·D·H / (1 − β²)^1.5 with β = b/D, for diameter `d`, length `h` and strip
/// width `b`.
pub fn split_cylinder_peak(ft: f64, d: f64, h: f64, b: f64) -> f64 {
    let beta = b / d;
    std::f64::consts::FRAC_PI_2 * ft * d * h / (1.0 - beta * beta).powf(1.5)
}

/// The message names every fragment (the error tests: one message naming the key, the
/// value and what is allowed).
pub fn says(msg: &str, fragments: &[&str]) {
    for f in fragments {
        assert!(msg.contains(f), "message {msg:?} does not name {f:?}");
    }
}

/// Run a scene on `threads` threads without a progress bar (it must succeed).
pub fn run(s: &sppm::Scene, threads: usize) -> sppm::Outcome {
    sppm::run(
        s,
        &sppm::run::RunOptions {
            progress: false,
            threads: Some(threads),
        },
    )
    .unwrap()
}
