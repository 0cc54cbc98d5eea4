//! The members of the scene's platens with friction (`groups.<name>.friction`, docs/model.md
//! §10), for the solver's friction step (`solver::friction`).

use super::model::Model;
use crate::solver::friction::{contacts_of, Contact};

/// Every friction platen's contacts. A platen's direction into the body is the sign of the
/// body's centroid less the platen's along the platen's normal.
pub fn contacts<const K: usize, const D: usize>(model: &Model<K, D>) -> Vec<Contact> {
    let x0 = &model.particles.x0;
    let mean = |members: &mut dyn Iterator<Item = usize>, c: usize| {
        let (mut sum, mut n) = (0.0, 0.0);
        for i in members {
            sum += x0[i][c];
            n += 1.0;
        }
        sum / n
    };
    let mut out = Vec::new();
    for (spec, g) in model.scene.groups.iter().zip(&model.groups) {
        let (Some(mu), Some(normal)) = (spec.friction, spec.platen_normal()) else {
            continue;
        };
        let body = mean(&mut (0..x0.len()), normal);
        let platen = mean(&mut g.members.iter().map(|&i| i as usize), normal);
        let inward = if body >= platen { 1.0 } else { -1.0 };
        out.extend(contacts_of(
            &g.members,
            normal,
            inward,
            mu,
            &model.constrained,
        ));
    }
    out
}
