//! `[[gauges]]`: openings measured during a run (docs/scenes.md, "Gauges"): the crack-mouth
//! opening of a notched beam, or an LVDT between two points of a specimen.

use super::Axis;
use serde::{Deserialize, Serialize};

/// The most gauges a scene may have: each record of a run carries their readings inline, so
/// that a record stays a plain copyable value.
pub const MAX_GAUGES: usize = 8;

/// One gauge: the displacement of its second end less that of its first, along a
/// direction. Each end is a group (the mean displacement of its particles) or a point (the
/// particle nearest it).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GaugeSpec {
    /// Names the gauge's column in force_displacement.csv and its plot.
    pub name: String,
    /// The two ends as points `[[x, y], [x, y]]` (3D: three coordinates each).
    #[serde(default)]
    pub points: Option<Vec<Vec<f64>>>,
    /// The two ends as groups `["first", "second"]`.
    #[serde(default)]
    pub groups: Option<Vec<String>>,
    /// The direction of the opening: an axis ...
    #[serde(default)]
    pub component: Option<Axis>,
    /// ... or a vector (normalised).
    #[serde(default)]
    pub direction: Option<Vec<f64>>,
}

impl GaugeSpec {
    /// The unit direction of the opening in `dim` dimensions (validated).
    pub fn unit_direction(&self, dim: usize) -> Vec<f64> {
        match (&self.component, &self.direction) {
            (Some(a), _) => (0..dim).map(|k| f64::from(k == a.index())).collect(),
            (None, Some(d)) => {
                let n = d.iter().map(|v| v * v).sum::<f64>().sqrt();
                d.iter().map(|v| v / n).collect()
            }
            (None, None) => vec![0.0; dim],
        }
    }
}
