//! The scene's gauges (`[[gauges]]`) as weights on the model's particles: a group end reads
//! the mean displacement of the group's members, a point end the particle nearest the point.

use super::Model;
use crate::discretise::groups;
use crate::solver::gauge::Gauge;
use nalgebra::SVector;

/// Each gauge of the model's scene, in its order.
pub fn gauges_of<const K: usize, const D: usize>(model: &Model<K, D>) -> Vec<Gauge<D>> {
    let x0 = &model.particles.x0;
    let members = |name: &str| -> Vec<u32> {
        model
            .groups
            .iter()
            .find(|g| g.name == name)
            .map(|g| g.members.clone())
            .unwrap_or_default()
    };
    let nearest = |q: &[f64]| groups::nearest(x0, &SVector::<f64, D>::from_fn(|k, _| q[k]));
    model
        .scene
        .gauges
        .iter()
        .map(|g| {
            let (first, second) = match (&g.points, &g.groups) {
                (Some(p), _) => (nearest(&p[0]), nearest(&p[1])),
                (None, Some(n)) => (members(&n[0]), members(&n[1])),
                (None, None) => (vec![], vec![]),
            };
            let d = g.unit_direction(D);
            let n = SVector::<f64, D>::from_fn(|k, _| d[k]);
            Gauge::between(&g.name, &first, &second, n)
        })
        .collect()
}
