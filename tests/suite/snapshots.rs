//! The time series of a run (`output.snapshots`, docs/outputs.md): snapshots.pvd lists the
//! frames, each snapshots/frame_NNNN.vtu holds every particle with its arrays, the crack
//! grows from frame to frame and ends as summary.json counts it, crack_growth.html holds the
//! same frames, a rerun removes frames it does not write, and meshio (when installed) reads
//! every frame.

use crate::common::{plate_toml, run, says, tension_block};
use sppm::run::RunOptions;
use sppm::Scene;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A fresh folder for a test's outputs.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sppm-snapshots-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

/// Standard base64 with padding, decoded (the test's own reader, not sppm's writer).
fn unbase64(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => (c - b'A') as u32,
            b'a'..=b'z' => (c - b'a') as u32 + 26,
            b'0'..=b'9' => (c - b'0') as u32 + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        }
    };
    let mut out = Vec::new();
    for quad in text.as_bytes().chunks(4) {
        assert_eq!(quad.len(), 4, "base64 comes in groups of 4");
        let pad = quad.iter().filter(|&&c| c == b'=').count();
        let n = quad
            .iter()
            .map(|&c| if c == b'=' { 0 } else { value(c) })
            .fold(0u32, |acc, v| (acc << 6) | v);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// The value of attribute `name` in an XML start tag.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!("{name}=\"");
    let (at, _) = tag
        .match_indices(&key)
        .find(|&(i, _)| i == 0 || tag.as_bytes()[i - 1] == b' ')?;
    let at = at + key.len();
    Some(&tag[at..at + tag[at..].find('"')?])
}

/// One DataArray of a .vtu file: its type, components and decoded bytes.
struct DataArray {
    kind: String,
    components: usize,
    bytes: Vec<u8>,
}

impl DataArray {
    fn f64s(&self) -> Vec<f64> {
        assert_eq!(self.kind, "Float64");
        self.bytes
            .chunks(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect()
    }
}

/// The point count and the named DataArrays of a .vtu file (binary, UInt64 headers, each
/// header base64-encoded apart from its data, as VTK writes them).
fn read_vtu(path: &Path) -> (usize, HashMap<String, DataArray>) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.starts_with("<?xml"), "{}", path.display());
    assert!(text.contains(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    ));
    let piece = &text[text.find("<Piece ").unwrap()..];
    let n: usize = attribute(piece, "NumberOfPoints").unwrap().parse().unwrap();
    let cells: usize = attribute(piece, "NumberOfCells").unwrap().parse().unwrap();
    assert_eq!(cells, n, "one vertex cell per particle");
    let mut arrays = HashMap::new();
    for chunk in text.split("<DataArray ").skip(1) {
        let (tag, rest) = chunk.split_once('>').unwrap();
        let body = &rest[..rest.find("</DataArray>").unwrap()];
        assert_eq!(attribute(tag, "format"), Some("binary"));
        // the header: 8 bytes, 12 base64 characters with their padding
        let count = u64::from_le_bytes(unbase64(&body[..12]).try_into().unwrap()) as usize;
        let bytes = unbase64(&body[12..]);
        assert_eq!(bytes.len(), count, "{tag}: the header counts the data");
        let name = attribute(tag, "Name").unwrap().to_string();
        let components = attribute(tag, "NumberOfComponents").map_or(1, |c| c.parse().unwrap());
        let kind = attribute(tag, "type").unwrap().to_string();
        arrays.insert(
            name,
            DataArray {
                kind,
                components,
                bytes,
            },
        );
    }
    (n, arrays)
}

/// The (timestep, file) pairs of a .pvd collection.
fn read_pvd(path: &Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("<VTKFile type=\"Collection\""));
    text.split("<DataSet ")
        .skip(1)
        .map(|tag| {
            (
                attribute(tag, "timestep").unwrap().parse().unwrap(),
                attribute(tag, "file").unwrap().to_string(),
            )
        })
        .collect()
}

/// The frames' JSON block of crack_growth.html.
fn animation_frames(path: &Path) -> Vec<serde_json::Value> {
    let html = std::fs::read_to_string(path).unwrap();
    let open = "<script type=\"application/json\" id=\"sppm-frames\">";
    let at = html.find(open).unwrap() + open.len();
    let json = &html[at..at + html[at..].find("</script>").unwrap()];
    let data: serde_json::Value = serde_json::from_str(json).unwrap();
    data["frames"].as_array().unwrap().clone()
}

/// The tension block (150 mm, L0 = 10 mm, 279 particles) with 8 frames: the series lists 8
/// frames over the load, each with every particle and every array at its length, ids 0 … n−1,
/// volumes summing to the body's; the cracked count rises from 0 to summary.json's, and the
/// animation holds the same 8 frames with the same counts.
#[test]
fn series_of_a_cracking_block() {
    let frames = 8;
    let o = run(
        &tension_block(0.15, 0.01, &[&format!("output.snapshots={frames}")]),
        1,
    );
    let dir = folder("block");
    sppm::output::write_all(&o, &dir).unwrap();
    let listed = read_pvd(&dir.join("snapshots.pvd"));
    assert_eq!(listed.len(), frames);
    let n = o.x0.len();
    assert_eq!(n, 279);
    // the body's volume: 150 mm × 150 mm × 150 mm thick
    let body = 0.15 * 0.15 * 0.15;
    let mut cracked = Vec::new();
    let mut largest: f64 = 0.0;
    for (k, (t, file)) in listed.iter().enumerate() {
        assert_eq!(file, &format!("snapshots/frame_{k:04}.vtu"));
        // frame k at the first step past (k+1)/8 of t_end (steps of dt ≈ 1.5e-4 t_end)
        let due = (k + 1) as f64 / frames as f64;
        assert!(
            *t >= due && *t < due + 1e-3,
            "frame {k} at {t}, due at {due}"
        );
        let (points, a) = read_vtu(&dir.join(file));
        assert_eq!(points, n);
        for (name, components) in [
            ("displacement_m", 3),
            ("stress_Pa", 9),
            ("von_mises_Pa", 1),
            ("damage_wt", 1),
            ("damage_wc", 1),
            ("volume_m3", 1),
            ("Points", 3),
        ] {
            let array = &a[name];
            assert_eq!(array.components, components, "{name}");
            assert_eq!(array.f64s().len(), n * components, "{name}");
        }
        let id = &a["id"];
        assert_eq!(id.kind, "Int32");
        let ids: Vec<i32> = id
            .bytes
            .chunks(4)
            .map(|b| i32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(ids, (0..n as i32).collect::<Vec<_>>());
        // The clipped cells give the body its volume: summary.json's particle_volume is the
        // body's within 9.7e-11 (relative) on this block; the frames' volumes are those.
        let volume: f64 = a["volume_m3"].f64s().iter().sum();
        let s = &o.summary.surface_correction;
        assert!((volume / s.particle_volume - 1.0).abs() < 1e-13, "{volume}");
        assert!(
            (volume / body - 1.0).abs() < 1e-9,
            "{volume} against {body}"
        );
        // the stress tensor is symmetric, and von Mises is the plane-stress value of its
        // in-plane part, in Pa as the tensor
        let stress = a["stress_Pa"].f64s();
        let von_mises = a["von_mises_Pa"].f64s();
        for (s, vm) in stress.chunks(9).zip(&von_mises) {
            assert_eq!((s[1], s[2], s[5]), (s[3], s[6], s[7]));
            let expected = (s[0] * s[0] - s[0] * s[4] + s[4] * s[4] + 3.0 * s[1] * s[1]).sqrt();
            assert!(
                (vm - expected).abs() <= 1e-9 * expected.max(1.0),
                "{vm} {expected}"
            );
        }
        largest = von_mises.iter().cloned().fold(largest, f64::max);
        cracked.push(a["damage_wt"].f64s().iter().filter(|&&w| w >= 0.99).count());
        if k + 1 == frames {
            // the last frame is the state summary.json and particles.csv report
            assert_eq!(*t, 1.0);
            let u = a["displacement_m"].f64s();
            let end: Vec<f64> = o.displacement.iter().flatten().copied().collect();
            assert_eq!(u, end);
        }
    }
    // f't = 2.6 MPa: the stress near the peak is MPa-sized (Pa, not MPa, in the file)
    assert!(
        largest > 1e6 && largest < 1e8,
        "largest von Mises {largest} Pa"
    );
    assert_eq!(cracked[0], 0);
    assert!(cracked.windows(2).all(|w| w[0] <= w[1]), "{cracked:?}");
    assert_eq!(Some(cracked[frames - 1]), o.summary.cracked_particles);
    assert!(cracked[frames - 1] >= 20, "{cracked:?}");
    let html = animation_frames(&dir.join("crack_growth.html"));
    assert_eq!(html.len(), frames);
    for (k, f) in html.iter().enumerate() {
        let wt = f["wt"].as_str().unwrap();
        assert_eq!(wt.len(), n);
        assert_eq!(wt.matches('/').count(), cracked[k], "frame {k}");
        assert_eq!(f["cracked"].as_u64(), Some(cracked[k] as u64));
    }
    meshio_reads(&dir, &listed, n, &cracked);
    std::fs::remove_dir_all(&dir).ok();
}

/// meshio reads every frame with the point count, the arrays and the cracked counts the Rust
/// reader found; without meshio, a note says the check was left out.
fn meshio_reads(dir: &Path, listed: &[(f64, String)], n: usize, cracked: &[usize]) {
    let has = std::process::Command::new("python3")
        .args(["-c", "import meshio"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has {
        eprintln!("note: python3 with meshio not found; the .vtu files were checked by the Rust reader only");
        return;
    }
    let script = r#"
import sys, meshio
for f in sys.argv[1:]:
    m = meshio.read(f)
    d = m.point_data
    shapes = ",".join(f"{k}:{d[k].shape[1] if d[k].ndim > 1 else 1}" for k in sorted(d))
    ids = d["id"].ravel().tolist() == list(range(len(m.points)))
    print(len(m.points), len(m.cells[0].data), m.cells[0].type, int((d["damage_wt"] >= 0.99).sum()), ids, shapes)
"#;
    let files: Vec<String> = listed
        .iter()
        .map(|(_, f)| dir.join(f).to_string_lossy().into_owned())
        .collect();
    let out = std::process::Command::new("python3")
        .args(["-c", script])
        .args(&files)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), listed.len());
    for (k, line) in lines.iter().enumerate() {
        assert_eq!(
            *line,
            format!(
                "{n} {n} vertex {} True damage_wc:1,damage_wt:1,displacement_m:3,id:1,stress_Pa:9,volume_m3:1,von_mises_Pa:1",
                cracked[k]
            ),
            "frame {k}"
        );
    }
}

/// The shipped notched beam's series (`output.snapshots = 20`; the run stops after its
/// peak, so the frames reach only part of the load): every frame opens, the crack grows from
/// frame to frame to the count summary.json reports, and the animation holds the same frames.
#[test]
fn series_of_the_notched_beam_shows_the_crack_advancing() {
    let scene = Scene::from_file(Path::new("lattices/beam_3pb_notch02.toml"), &[]).unwrap();
    assert_eq!(scene.output.snapshots, Some(20));
    let o = sppm::run::run(&scene, &RunOptions::default()).unwrap();
    let dir = folder("beam");
    sppm::output::write_all(&o, &dir).unwrap();
    let listed = read_pvd(&dir.join("snapshots.pvd"));
    assert!(listed.len() >= 5 && listed.len() <= 20, "{}", listed.len());
    let n = o.x0.len();
    let cracked: Vec<usize> = listed
        .iter()
        .map(|(_, f)| {
            let (points, a) = read_vtu(&dir.join(f));
            assert_eq!(points, n);
            a["damage_wt"].f64s().iter().filter(|&&w| w >= 0.99).count()
        })
        .collect();
    assert_eq!(cracked[0], 0);
    assert!(cracked.windows(2).all(|w| w[0] <= w[1]), "{cracked:?}");
    assert_eq!(Some(*cracked.last().unwrap()), o.summary.cracked_particles);
    // the crack advances over several frames, not in one jump
    let growing = cracked.windows(2).filter(|w| w[1] > w[0]).count();
    assert!(growing >= 3, "{cracked:?}");
    let html = animation_frames(&dir.join("crack_growth.html"));
    assert_eq!(html.len(), listed.len());
    meshio_reads(&dir, &listed, n, &cracked);
    std::fs::remove_dir_all(&dir).ok();
}

/// A rerun into the folder with fewer frames removes the frames beyond them; one without
/// snapshots removes the series, the animation and the emptied folder.
#[test]
fn a_rerun_removes_stale_frames() {
    let o = run(&tension_block(0.15, 0.02, &["output.snapshots=5"]), 1);
    let dir = folder("stale");
    sppm::output::write_all(&o, &dir).unwrap();
    let frames = |dir: &Path| -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir.join("snapshots"))
            .map(|d| {
                d.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        names
    };
    assert_eq!(frames(&dir).len(), 5);
    let mut fewer = o.clone();
    fewer.snapshots = Arc::new(o.snapshots[3..].to_vec());
    sppm::output::write_all(&fewer, &dir).unwrap();
    assert_eq!(frames(&dir), ["frame_0000.vtu", "frame_0001.vtu"]);
    assert_eq!(read_pvd(&dir.join("snapshots.pvd")).len(), 2);
    assert_eq!(animation_frames(&dir.join("crack_growth.html")).len(), 2);
    let mut none = o.clone();
    none.snapshots = Arc::new(Vec::new());
    sppm::output::write_all(&none, &dir).unwrap();
    assert!(!dir.join("snapshots").exists());
    assert!(!dir.join("snapshots.pvd").exists());
    assert!(!dir.join("crack_growth.html").exists());
    assert!(dir.join("particles.vtk").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// Under relaxation the frames are at the increments k/increments: 8 increments, 4 frames at
/// 1/4, 1/2, 3/4 and 1. An elastic plate's displacement field is proportional to the load,
/// so each frame is the last one scaled by the ratio of their probe displacements, within
/// the geometric nonlinearity (ε = 1e-4) and the tolerance: measured 1.5e-6 to 8.0e-6 of the
/// field's norm, asserted below 1e-4. Without `[concrete]` the
/// frames have no damage arrays and no animation is written.
#[test]
fn relaxation_frames_are_at_their_increments() {
    let mut text = plate_toml(0.1, 0.2, 0.008, 0.0, "stress", false, 0.2);
    text.push_str("[output]\nmap = false\nsnapshots = 4\n");
    let scene = Scene::from_toml_str(
        &text,
        &[
            "solver.method=\"relaxation\"".into(),
            "solver.increments=8".into(),
            "solver.tolerance=1e-6".into(),
        ],
    )
    .unwrap();
    let o = run(&scene, 1);
    let f = &o.snapshots;
    let fractions: Vec<f64> = f.iter().map(|s| s.load_fraction).collect();
    assert_eq!(fractions, [0.25, 0.5, 0.75, 1.0]);
    let last = &f[3];
    let norm = |u: &[[f64; 3]]| u.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
    for s in &f[..3] {
        let r = s.probe_displacement_m / last.probe_displacement_m;
        let diff: Vec<[f64; 3]> = s
            .displacement
            .iter()
            .zip(&last.displacement)
            .map(|(a, b)| [a[0] - r * b[0], a[1] - r * b[1], a[2] - r * b[2]])
            .collect();
        let e = norm(&diff) / (r * norm(&last.displacement));
        assert!(e < 1e-4, "frame at {}: {e:e}", s.load_fraction);
        assert!(s.damage.is_none());
    }
    let dir = folder("plate");
    sppm::output::write_all(&o, &dir).unwrap();
    let (_, a) = read_vtu(&dir.join("snapshots/frame_0003.vtu"));
    assert!(!a.contains_key("damage_wt"));
    assert!(!dir.join("crack_growth.html").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// `output.snapshots` outside 1 … 1000 is refused naming the key, the value and the range.
#[test]
fn bad_snapshot_counts_are_named() {
    let text = plate_toml(0.1, 0.2, 0.008, 0.0, "stress", false, 0.2);
    for bad in ["0", "1001"] {
        let e = Scene::from_toml_str(&text, &[format!("output.snapshots={bad}")])
            .unwrap_err()
            .to_string();
        says(&e, &["output.snapshots", bad, "from 1 to 1000"]);
    }
    let e = Scene::from_toml_str(&text, &["output.snapshots=-2".into()])
        .unwrap_err()
        .to_string();
    says(&e, &["output.snapshots", "-2"]);
}

/// The memory estimate counts the frames: 88 bytes (11 f64) per particle and frame.
#[test]
fn memory_estimate_counts_the_frames() {
    let text = plate_toml(0.1, 0.2, 0.008, 0.0, "stress", false, 0.2);
    let with = |n: &str| {
        let s = Scene::from_toml_str(&text, &[format!("output.snapshots={n}")]).unwrap();
        sppm::run::estimated_memory(&s)
    };
    let plain = sppm::run::estimated_memory(&Scene::from_toml_str(&text, &[]).unwrap());
    let particles = sppm::run::estimated_particles(&Scene::from_toml_str(&text, &[]).unwrap());
    let frames = with("100") - plain;
    assert!(
        (frames / (100.0 * 88.0 * particles) - 1.0).abs() < 1e-12,
        "{frames}"
    );
    assert!((with("1") - plain - 88.0 * particles).abs() < 1e-6 * plain);
}
