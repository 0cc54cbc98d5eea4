//! Legacy binary VTK (an unstructured grid of vertex cells, one per particle) for ParaView,
//! with displacement, stress tensor, von Mises and maximum principal stress, the particle's
//! volume (`volume_m3`) and index (`id`), and group membership as point data, and each
//! random field's values (e.g. `ft_MPa`). Checked with meshio's reader.

use super::fields;
use crate::run::Outcome;
use crate::scene::Field;
use anyhow::Context;
use std::io::Write;
use std::path::Path;

fn be(w: &mut impl Write, v: f64) -> std::io::Result<()> {
    w.write_all(&(v as f32).to_be_bytes())
}

pub fn write_particles(o: &Outcome, path: &Path) -> anyhow::Result<()> {
    let f =
        std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut w = std::io::BufWriter::new(f);
    let n = o.x0.len();
    writeln!(w, "# vtk DataFile Version 3.0")?;
    writeln!(w, "sppm {} particles", o.summary.scene)?;
    writeln!(w, "BINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS {n} float")?;
    for x in &o.x0 {
        for c in x {
            be(&mut w, *c)?;
        }
    }
    writeln!(w, "\nCELLS {n} {}", 2 * n)?;
    for i in 0..n {
        w.write_all(&1i32.to_be_bytes())?;
        w.write_all(&(i as i32).to_be_bytes())?;
    }
    // cell type 1: VTK_VERTEX
    writeln!(w, "\nCELL_TYPES {n}")?;
    for _ in 0..n {
        w.write_all(&1i32.to_be_bytes())?;
    }
    writeln!(w, "\nPOINT_DATA {n}\nVECTORS displacement_m float")?;
    for u in &o.displacement {
        for c in u {
            be(&mut w, *c)?;
        }
    }
    writeln!(w, "\nTENSORS stress_Pa float")?;
    for s in &o.stress {
        // Voigt [xx, yy, zz, yz, xz, xy] to the row-major 3×3 tensor
        for v in crate::run::arrays::tensor9(s) {
            be(&mut w, v)?;
        }
    }
    // in Pa, as the stress tensor (the maps' values are in MPa)
    for (name, field) in [
        ("von_mises_Pa", Field::StressVonMises),
        ("max_principal_Pa", Field::MaxPrincipalStress),
    ] {
        writeln!(w, "\nSCALARS {name} float 1\nLOOKUP_TABLE default")?;
        for v in fields::values(o, field) {
            be(&mut w, v * 1e6)?;
        }
    }
    if let Some(d) = &o.damage {
        type Get = fn(&crate::solver::inelastic::ParticleDamage) -> f64;
        let scalars: [(&str, Get); 3] = [
            ("tensile_damage", |p| p.wt),
            ("compressive_damage", |p| p.wc),
            ("yielded", |p| if p.yielded { 1.0 } else { 0.0 }),
        ];
        for (name, get) in scalars {
            writeln!(w, "\nSCALARS {name} float 1\nLOOKUP_TABLE default")?;
            for p in d {
                be(&mut w, get(p))?;
            }
        }
    }
    if let Some(r) = &o.moduli_residual {
        writeln!(
            w,
            "\nSCALARS micro_modulus_residual float 1\nLOOKUP_TABLE default"
        )?;
        for v in r {
            be(&mut w, *v)?;
        }
    }
    // random fields (docs/model.md §12), in the units of their names
    for f in &o.fields {
        let (name, unit) = f.label();
        writeln!(w, "\nSCALARS {name} float 1\nLOOKUP_TABLE default")?;
        for v in &f.values {
            be(&mut w, v * unit)?;
        }
    }
    writeln!(w, "\nSCALARS volume_m3 float 1\nLOOKUP_TABLE default")?;
    for v in &o.volume {
        be(&mut w, *v)?;
    }
    writeln!(w, "\nSCALARS id int 1\nLOOKUP_TABLE default")?;
    for i in 0..n {
        w.write_all(&(i as i32).to_be_bytes())?;
    }
    for g in &o.groups {
        let mut member = vec![0.0; n];
        for &i in &g.members {
            member[i as usize] = 1.0;
        }
        let name: String = g
            .name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        writeln!(w, "\nSCALARS group_{name} float 1\nLOOKUP_TABLE default")?;
        for v in member {
            be(&mut w, v)?;
        }
    }
    writeln!(w)?;
    w.flush()?;
    Ok(())
}
