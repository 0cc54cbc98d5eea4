//! The members of the scene's platens with friction (`groups.<name>.friction`) and of its
//! bearing strips (`groups.<name>.bearing`), docs/model.md §10, for the solver's steps
//! (`solver::friction`, `solver::bearing`).

use super::model::Model;
use crate::solver::bearing::Bearing;
use crate::solver::friction::{contacts_of, Contact};
use crate::solver::loading::Prescribed;
use nalgebra::SVector;

/// +1 or −1: the sign of the body's centroid less the group's along `normal`, the direction
/// from a platen into the body.
fn inward<const D: usize>(x0: &[SVector<f64, D>], members: &[u32], normal: usize) -> f64 {
    let body = x0.iter().map(|x| x[normal]).sum::<f64>() / x0.len() as f64;
    let platen =
        members.iter().map(|&i| x0[i as usize][normal]).sum::<f64>() / members.len() as f64;
    if body >= platen {
        1.0
    } else {
        -1.0
    }
}

/// Every friction platen's contacts, each platen's direction into the body from its
/// members' centroid ([`inward`]).
pub fn contacts<const K: usize, const D: usize>(model: &Model<K, D>) -> Vec<Contact> {
    let x0 = &model.particles.x0;
    let mut out = Vec::new();
    for (spec, g) in model.scene.groups.iter().zip(&model.groups) {
        let (Some(mu), Some(normal)) = (spec.friction, spec.platen_normal()) else {
            continue;
        };
        out.extend(contacts_of(
            &g.members,
            normal,
            inward(x0, &g.members, normal),
            mu,
            &model.constrained,
        ));
    }
    out
}

/// Every bearing strip's members (`groups.<name>.bearing`): the strip's stiffness per unit
/// area E/thickness over its area (the strip's width × the body's length along z, or the 2D
/// thickness), shared among the members by volume; the platen's Δmax is the group's load (0
/// for a fixed one).
pub fn bearings<const K: usize, const D: usize>(model: &Model<K, D>) -> Vec<Bearing> {
    let scene = &model.scene;
    let x0 = &model.particles.x0;
    let volume = &model.particles.volume;
    let mut out = Vec::new();
    for (spec, g) in scene.groups.iter().zip(&model.groups) {
        let (Some(b), Some(normal), Some(area)) = (
            spec.bearing,
            spec.platen_normal(),
            scene.strip_area(&spec.select),
        ) else {
            continue;
        };
        let amplitude = spec.load.as_ref().map_or(0.0, |l| l.delta());
        let inward = inward(x0, &g.members, normal);
        let total: f64 = g.members.iter().map(|&i| volume[i as usize]).sum();
        out.extend(g.members.iter().map(|&i| Bearing {
            particle: i,
            component: normal as u8,
            amplitude,
            stiffness: b.e / b.thickness * area * volume[i as usize] / total,
            inward,
        }));
    }
    out
}

/// The prescribed components less those a bearing strip takes over (its members' normal
/// components, which the strip presses instead).
pub fn without_bearings(prescribed: Vec<Prescribed>, bearings: &[Bearing]) -> Vec<Prescribed> {
    if bearings.is_empty() {
        return prescribed;
    }
    let taken: std::collections::HashSet<(u32, u8)> =
        bearings.iter().map(|b| (b.particle, b.component)).collect();
    prescribed
        .into_iter()
        .filter(|p| !taken.contains(&(p.particle, p.component)))
        .collect()
}
