//! `[[cutouts]]`: each cutout's values, then their geometry against the body and each other.

use super::{finite, invalid, positive, simple_polygon, SceneError};
use crate::geometry::{cutout_area_in, Cutout, Shape2};
use crate::scene::{BodySpec, CutoutSpec, Scene};
use nalgebra::Vector2;

/// Where a cutout's numbers may lie: within a thousand times the body's size of it (beyond,
/// its numbers would only lose the body's digits).
struct Reach {
    /// The body's bounding box.
    lo: Vector2<f64>,
    hi: Vector2<f64>,
    /// The body's size.
    size: f64,
    /// 1000 × the body's size.
    reach: f64,
}

impl Reach {
    fn of(outer: &Shape2) -> Reach {
        let size = outer.size();
        let (lo, hi) = outer.bounding_box();
        Reach {
            lo,
            hi,
            size,
            reach: 1e3 * size,
        }
    }

    /// A point: finite, near the body.
    fn point(&self, key: &str, p: &[f64; 2]) -> Result<(), SceneError> {
        let (lo, hi, reach) = (self.lo, self.hi, self.reach);
        for (c, (l, h)) in [(lo.x, hi.x), (lo.y, hi.y)].into_iter().enumerate() {
            let k = format!("{key}[{c}]");
            finite(&k, p[c])?;
            if p[c] < l - reach || p[c] > h + reach {
                return Err(invalid(
                    k,
                    p[c],
                    format!("within 1000 × the body's size ({reach:.4e} m) of the body, [{:.4e}, {:.4e}] m", l - reach, h + reach),
                ));
            }
        }
        Ok(())
    }

    /// A length: positive, at most the reach.
    fn length(&self, key: String, v: f64) -> Result<(), SceneError> {
        positive(&key, v)?;
        if v > self.reach {
            return Err(invalid(
                key,
                v,
                format!("at most 1000 × the body's size ({:.4e} m)", self.reach),
            ));
        }
        Ok(())
    }
}

impl Scene {
    /// The values of `[[cutouts]]`, then their geometry: each must meet the body, one that
    /// crosses the outline must have an exact area (every cutout but a disc across a disc's
    /// or a dog-bone's arc), none may overlap another (crack lines aside), and together they
    /// must leave some of the body.
    pub(super) fn validate_cutouts(&self) -> Result<(), SceneError> {
        if self.cutouts.is_empty() {
            return Ok(());
        }
        if matches!(self.body, BodySpec::Box { .. } | BodySpec::Cylinder { .. }) {
            return Err(invalid(
                "cutouts",
                format!("{} cutouts on body.shape = \"{}\"", self.cutouts.len(), self.body.name()),
                "cutouts on a 2D body or on a prism's section (shape = \"prism\"), through its whole thickness",
            ));
        }
        let outer = self.outer_shape();
        let reach = Reach::of(&outer);
        for (i, c) in self.cutouts.iter().enumerate() {
            cutout_values(&format!("cutouts[{i}]"), c, &reach)?;
        }
        let cutouts: Vec<Cutout> = self.cutouts.iter().map(CutoutSpec::cutout).collect();
        self.cutouts_meet_the_body(&outer, &cutouts, &reach)?;
        self.cutouts_apart(&cutouts)?;
        let outer_area = outer.area();
        let area = self.shape().area();
        if area <= 1e-9 * outer_area {
            return Err(invalid(
                "cutouts",
                format!("{} cutouts", cutouts.len()),
                format!(
                    "cutouts that leave some of the body; cutouts[0] to cutouts[{}] together remove all of it ({outer_area:.4e} m²)",
                    cutouts.len() - 1
                ),
            ));
        }
        Ok(())
    }

    /// Each cutout meets the body and leaves some of it; one that crosses the outline has an
    /// exact area.
    fn cutouts_meet_the_body(
        &self,
        outer: &Shape2,
        cutouts: &[Cutout],
        reach: &Reach,
    ) -> Result<(), SceneError> {
        let outer_area = outer.area();
        let (lo, hi) = (reach.lo, reach.hi);
        for (i, (c, spec)) in cutouts.iter().zip(&self.cutouts).enumerate() {
            let outside = || {
                invalid(
                    format!("cutouts[{i}]"),
                    spec.scene_text(),
                    format!(
                        "a cutout that meets the body; this one lies outside the body (the body spans x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m)",
                        lo.x, hi.x, lo.y, hi.y
                    ),
                )
            };
            let whole = || {
                invalid(
                    format!("cutouts[{i}]"),
                    spec.scene_text(),
                    "a cutout that leaves some of the body; this one removes the whole body",
                )
            };
            if !c.removes_area() {
                let alone = Shape2::WithCutouts {
                    outer: Box::new(outer.clone()),
                    cutouts: vec![c.clone()],
                };
                if alone.cutout_outlines().is_empty() {
                    return Err(outside());
                }
                continue;
            }
            let own = c.area();
            match cutout_area_in(outer, c, None) {
                Some(a) if a <= 1e-9 * own => return Err(outside()),
                Some(a) if a >= (1.0 - 1e-9) * outer_area => return Err(whole()),
                Some(_) => {}
                None => {
                    // a disc across an arc: classify it on the chords, to name the problem
                    let a = crate::geometry::cutout_area_in_or_chords(outer, c, None);
                    if a <= 1e-6 * own {
                        return Err(outside());
                    }
                    if a >= (1.0 - 1e-6) * outer_area {
                        return Err(whole());
                    }
                    return Err(invalid(
                        format!("cutouts[{i}]"),
                        spec.scene_text(),
                        "a disc cutout inside the body or clear of it: a disc that crosses the arc of a disc or dog-bone body has no exact area here (its particles' volumes would be wrong); move it inside the body, or cut the notch as a polygon",
                    ));
                }
            }
        }
        Ok(())
    }

    /// No two cutouts overlap (a crack line may cross others).
    fn cutouts_apart(&self, cutouts: &[Cutout]) -> Result<(), SceneError> {
        for j in 0..cutouts.len() {
            for i in 0..j {
                let overlap = cutouts[i].overlap_area(&cutouts[j]);
                if overlap > 1e-9 * cutouts[i].area().min(cutouts[j].area()) {
                    return Err(invalid(
                        format!("cutouts[{j}]"),
                        self.cutouts[j].scene_text(),
                        format!(
                            "cutouts must not overlap: this one overlaps cutouts[{i}] = {} by {overlap:.4e} m² (a slit of width 0, a crack line, may cross others)",
                            self.cutouts[i].scene_text()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The values of one cutout, its keys under `key` (`cutouts[i]`).
fn cutout_values(key: &str, c: &CutoutSpec, reach: &Reach) -> Result<(), SceneError> {
    match c {
        CutoutSpec::Disc { centre, diameter } => {
            reach.point(&format!("{key}.centre"), centre)?;
            reach.length(format!("{key}.diameter"), *diameter)?;
        }
        CutoutSpec::Polygon { vertices } => simple_polygon(
            key,
            vertices,
            |k, v| reach.point(&format!("{key}.vertices[{k}]"), v),
            "a simple polygon: each vertex once, edges that neither cross, touch nor overlap",
        )?,
        CutoutSpec::Slit { start, end, width } => {
            reach.point(&format!("{key}.start"), start)?;
            reach.point(&format!("{key}.end"), end)?;
            let length = (Vector2::new(end[0] - start[0], end[1] - start[1])).norm();
            if length <= 1e-9 * reach.size {
                return Err(invalid(
                    format!("{key}.end"),
                    format!("{end:?}"),
                    format!("a slit of non-zero length: end must differ from start = {start:?}"),
                ));
            }
            if !(width.is_finite() && *width >= 0.0 && *width <= reach.reach) {
                return Err(invalid(
                    format!("{key}.width"),
                    width,
                    format!("a width from 0 to 1000 × the body's size ({:.4e} m); 0 is a crack line, which removes no area, only the bonds that cross it", reach.reach),
                ));
            }
        }
        CutoutSpec::Rectangle {
            origin,
            width,
            height,
            rotation_deg,
        } => {
            reach.point(&format!("{key}.origin"), origin)?;
            reach.length(format!("{key}.width"), *width)?;
            reach.length(format!("{key}.height"), *height)?;
            finite(&format!("{key}.rotation_deg"), *rotation_deg)?;
        }
    }
    Ok(())
}
