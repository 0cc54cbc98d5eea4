//! `[[gauges]]`: a plain unique name, two ends given one way (points of the scene's
//! dimension, or groups of the scene), and one direction.

use super::{invalid, SceneError};
use crate::scene::gauge::MAX_GAUGES;
use crate::scene::Scene;

impl Scene {
    pub(super) fn validate_gauges(&self) -> Result<(), SceneError> {
        if self.gauges.len() > MAX_GAUGES {
            return Err(invalid(
                "gauges",
                format!("{} gauges", self.gauges.len()),
                format!("at most {MAX_GAUGES} gauges"),
            ));
        }
        let dim = self.dim();
        for (k, g) in self.gauges.iter().enumerate() {
            let key = |f: &str| format!("gauges[{k}].{f}");
            let plain = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
            if g.name.is_empty() || g.name.len() > 40 || !g.name.chars().all(plain) {
                return Err(invalid(
                    key("name"),
                    format!("{:?}", g.name),
                    "1 to 40 letters, digits, '_' or '-' (it names a CSV column and a file)",
                ));
            }
            if self.gauges[..k].iter().any(|o| o.name == g.name) {
                return Err(invalid(
                    key("name"),
                    format!("{:?}", g.name),
                    "a name no other gauge has",
                ));
            }
            match (&g.points, &g.groups) {
                (Some(p), None) => {
                    let ok = p.len() == 2
                        && p.iter()
                            .all(|q| q.len() == dim && q.iter().all(|v| v.is_finite()));
                    if !ok {
                        return Err(invalid(
                            key("points"),
                            format!("{p:?}"),
                            format!("two points of {dim} finite coordinates (m), [[x, y{}], [x, y{}]]: the first end and the second", if dim == 3 { ", z" } else { "" }, if dim == 3 { ", z" } else { "" }),
                        ));
                    }
                }
                (None, Some(names)) => {
                    if names.len() != 2 {
                        return Err(invalid(
                            key("groups"),
                            format!("{names:?}"),
                            "two group names, [\"first\", \"second\"]",
                        ));
                    }
                    for n in names {
                        if !self.groups.iter().any(|gr| &gr.name == n) {
                            return Err(self.unknown_group(&key("groups"), n));
                        }
                    }
                }
                _ => return Err(invalid(
                    format!("gauges[{k}]"),
                    format!("{:?}", g.name),
                    "exactly one of points = [[x, y], [x, y]] or groups = [\"first\", \"second\"]",
                )),
            }
            match (&g.component, &g.direction) {
                (Some(a), None) => {
                    if a.index() >= dim {
                        return Err(invalid(
                            key("component"),
                            "\"z\"",
                            "\"x\" or \"y\" in a 2D scene",
                        ));
                    }
                }
                (None, Some(d)) => {
                    let n2: f64 = d.iter().map(|v| v * v).sum();
                    if d.len() != dim || !(n2.is_finite() && n2 > 0.0) {
                        return Err(invalid(
                            key("direction"),
                            format!("{d:?}"),
                            format!("a non-zero vector of {dim} finite components"),
                        ));
                    }
                }
                _ => return Err(invalid(
                    format!("gauges[{k}]"),
                    format!("{:?}", g.name),
                    "exactly one of component = \"x\" (an axis) or direction = [dx, dy] (a vector)",
                )),
            }
        }
        Ok(())
    }
}
