//! The body's shape (`[body]`) and the regions cut out of it (`[[cutouts]]`), as the scene
//! writes them, and the geometry they make: the body's 2D shape, its solid and its size.
//! Lengths in metres.

use super::{inline_table, Scene};
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

/// The specimen's shape (`[body] shape = "..."`). Lengths in metres.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum BodySpec {
    Rectangle {
        width: f64,
        height: f64,
        #[serde(default)]
        origin: [f64; 2],
    },
    Polygon {
        vertices: Vec<[f64; 2]>,
    },
    Disc {
        diameter: f64,
        #[serde(default)]
        centre: [f64; 2],
    },
    /// van Vliet dog-bone of size D (docs/validation.md §D).
    Dogbone {
        size: f64,
    },
    NotchedBeam {
        length: f64,
        depth: f64,
        notch_depth: f64,
        notch_width: f64,
    },
    /// A box (3D): `size` = [x, y, z] from its lower corner `origin`.
    Box {
        size: [f64; 3],
        #[serde(default)]
        origin: [f64; 3],
    },
    /// A circular cylinder (3D) of `diameter` and `length` along `axis` (default z) from the
    /// centre of its base `base`.
    Cylinder {
        diameter: f64,
        length: f64,
        #[serde(default = "z_axis")]
        axis: [f64; 3],
        #[serde(default)]
        base: [f64; 3],
    },
    /// A 2D `section` (any 2D shape, with the scene's cutouts) extruded through
    /// z ∈ [0, thickness] (3D): the dog-bone and the notched beam as prisms.
    Prism {
        section: std::boxed::Box<BodySpec>,
        thickness: f64,
    },
}

fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl BodySpec {
    /// The shape's name as a scene writes it (`body.shape`).
    pub fn name(&self) -> &'static str {
        match self {
            BodySpec::Rectangle { .. } => "rectangle",
            BodySpec::Polygon { .. } => "polygon",
            BodySpec::Disc { .. } => "disc",
            BodySpec::Dogbone { .. } => "dogbone",
            BodySpec::NotchedBeam { .. } => "notched_beam",
            BodySpec::Box { .. } => "box",
            BodySpec::Cylinder { .. } => "cylinder",
            BodySpec::Prism { .. } => "prism",
        }
    }

    /// Whether the shape is a solid (box, cylinder, prism) rather than a 2D section.
    pub fn is_solid(&self) -> bool {
        matches!(
            self,
            BodySpec::Box { .. } | BodySpec::Cylinder { .. } | BodySpec::Prism { .. }
        )
    }
}

/// A region cut out of the body (`[[cutouts]] shape = "..."`). Lengths in metres. The body
/// is the outer shape less the open interiors of its cutouts: a particle on a cutout's edge
/// belongs to the body. A cutout may lie inside the body (a hole, an internal slit) or cross
/// its outline (a notch); cutouts must not overlap (a crack line may cross others).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum CutoutSpec {
    /// A circular hole.
    Disc { centre: [f64; 2], diameter: f64 },
    /// A simple polygon, vertices in either orientation.
    Polygon { vertices: Vec<[f64; 2]> },
    /// The rectangle of `width` about the segment start–end, at any angle; `width = 0` is a
    /// crack line: it removes no area, only the bonds that cross it.
    Slit {
        start: [f64; 2],
        end: [f64; 2],
        width: f64,
    },
    /// A rectangle `width` × `height` with its lower-left corner at `origin`, turned by
    /// `rotation_deg` about the origin.
    Rectangle {
        origin: [f64; 2],
        width: f64,
        height: f64,
        #[serde(default)]
        rotation_deg: f64,
    },
}

impl CutoutSpec {
    /// The cutout's geometry.
    pub fn cutout(&self) -> crate::geometry::Cutout {
        use crate::geometry::Cutout;
        use nalgebra::Vector2;
        let v = |a: &[f64; 2]| Vector2::new(a[0], a[1]);
        match self {
            CutoutSpec::Disc { centre, diameter } => Cutout::Disc {
                centre: v(centre),
                radius: 0.5 * diameter,
            },
            CutoutSpec::Polygon { vertices } => {
                Cutout::polygon(&vertices.iter().map(v).collect::<Vec<_>>())
            }
            CutoutSpec::Slit { start, end, width } => Cutout::slit(v(start), v(end), *width),
            CutoutSpec::Rectangle {
                origin,
                width,
                height,
                rotation_deg,
            } => Cutout::rectangle(v(origin), *width, *height, *rotation_deg),
        }
    }

    /// The cutout as the scene writes it, an inline TOML table
    /// (`{ shape = "disc", centre = [0.1, 0.1], diameter = 0.01 }`), for messages.
    pub fn scene_text(&self) -> String {
        inline_table(self, "shape")
    }
}

impl Scene {
    /// The contact area of a strip selection (m²): its width times the length it runs along,
    /// the thickness of a 2D body or the z extent of a prism or a cylinder along z; `None`
    /// for other selections.
    pub fn strip_area(&self, select: &super::Selection) -> Option<f64> {
        let super::Selection::Strip { width, .. } = select else {
            return None;
        };
        let length = match self.solid() {
            None => self.material.thickness(),
            Some(solid) => {
                let (lo, hi) = solid.bounding_box();
                hi.z - lo.z
            }
        };
        Some(width * length)
    }

    /// The body's smallest overall dimension (m).
    pub fn body_size(&self) -> f64 {
        shape_size(&self.body, &self.shape())
    }

    /// The geometric shape of the body: the outer shape ([`Self::outer_shape`]) and, when the
    /// scene has cutouts, less them (`Shape2::WithCutouts`). For a solid: a prism's section;
    /// the xy-extent of a box or a cylinder (3D code asks for [`Self::solid`]).
    pub fn shape(&self) -> crate::geometry::Shape2 {
        let outer = self.outer_shape();
        if self.cutouts.is_empty() {
            return outer;
        }
        crate::geometry::Shape2::WithCutouts {
            outer: Box::new(outer),
            cutouts: self.cutouts.iter().map(CutoutSpec::cutout).collect(),
        }
    }

    /// The shape of `[body]`, without the cutouts (see [`Self::shape`] for solids).
    pub fn outer_shape(&self) -> crate::geometry::Shape2 {
        section_shape(&self.body)
    }

    /// The 2D section a 3D body keeps all along z (a prism's, a cylinder's along z: the
    /// plane in which its strips are drawn); `None` for other bodies.
    pub fn section_along_z(&self) -> Option<crate::geometry::Shape2> {
        self.has_section_along_z().then(|| self.shape())
    }

    /// Whether the body is a prism or a cylinder along z ([`Self::section_along_z`]).
    pub(super) fn has_section_along_z(&self) -> bool {
        match &self.body {
            BodySpec::Prism { .. } => true,
            BodySpec::Cylinder { axis, .. } => z_axis_only(axis),
            _ => false,
        }
    }

    /// The solid of a 3D scene: a box, a cylinder (its axis normalised), or the prism of
    /// [`Self::shape`] (the section with the cutouts); `None` for a 2D body.
    pub fn solid(&self) -> Option<crate::geometry::Shape3> {
        use crate::geometry::Shape3;
        use nalgebra::Vector3;
        match &self.body {
            BodySpec::Box { size, origin } => Some(Shape3::Box {
                origin: Vector3::from(*origin),
                size: Vector3::from(*size),
            }),
            BodySpec::Cylinder {
                diameter,
                length,
                axis,
                base,
            } => Some(Shape3::Cylinder {
                base: Vector3::from(*base),
                axis: Vector3::from(*axis).normalize(),
                radius: 0.5 * diameter,
                length: *length,
            }),
            BodySpec::Prism { thickness, .. } => Some(Shape3::Extruded {
                section: self.shape(),
                thickness: *thickness,
            }),
            _ => None,
        }
    }
}

/// Whether a cylinder's axis runs along z.
fn z_axis_only(axis: &[f64; 3]) -> bool {
    let a = nalgebra::Vector3::from(*axis).normalize();
    a.x.abs() < 1e-12 && a.y.abs() < 1e-12
}

/// The smallest overall dimension (m) of a body shape (`shape`: its 2D shape).
fn shape_size(body: &BodySpec, shape: &crate::geometry::Shape2) -> f64 {
    match body {
        BodySpec::Rectangle { width, height, .. } => width.min(*height),
        BodySpec::Polygon { .. } => {
            let (lo, hi) = shape.bounding_box();
            (hi - lo).min()
        }
        BodySpec::Disc { diameter, .. } => *diameter,
        BodySpec::Dogbone { size } => 0.6 * size,
        BodySpec::NotchedBeam { length, depth, .. } => length.min(*depth),
        BodySpec::Box { size, .. } => size[0].min(size[1]).min(size[2]),
        BodySpec::Cylinder {
            diameter, length, ..
        } => diameter.min(*length),
        BodySpec::Prism { section, thickness } => shape_size(section, shape).min(*thickness),
    }
}

/// The 2D shape of a body shape: itself, a prism's section, the xy-extent of a box, the
/// disc of a cylinder along z (the xy-bounding rectangle of one along another axis).
fn section_shape(body: &BodySpec) -> crate::geometry::Shape2 {
    use crate::geometry::Shape2;
    match body {
        BodySpec::Rectangle {
            width,
            height,
            origin,
        } => Shape2::Rectangle {
            origin: Vector2::new(origin[0], origin[1]),
            width: *width,
            height: *height,
        },
        BodySpec::Polygon { vertices } => Shape2::Polygon {
            vertices: vertices.iter().map(|v| Vector2::new(v[0], v[1])).collect(),
        },
        BodySpec::Disc { diameter, centre } => Shape2::Disc {
            centre: Vector2::new(centre[0], centre[1]),
            radius: 0.5 * diameter,
        },
        BodySpec::Dogbone { size } => Shape2::DogBone { size: *size },
        BodySpec::NotchedBeam {
            length,
            depth,
            notch_depth,
            notch_width,
        } => Shape2::NotchedBeam {
            length: *length,
            depth: *depth,
            notch_depth: *notch_depth,
            notch_width: *notch_width,
        },
        BodySpec::Box { size, origin } => Shape2::Rectangle {
            origin: Vector2::new(origin[0], origin[1]),
            width: size[0],
            height: size[1],
        },
        BodySpec::Cylinder {
            diameter,
            length,
            axis,
            base,
        } => {
            let a = nalgebra::Vector3::from(*axis).normalize();
            let r = 0.5 * diameter;
            if z_axis_only(axis) {
                return Shape2::Disc {
                    centre: Vector2::new(base[0], base[1]),
                    radius: r,
                };
            }
            let solid = crate::geometry::Shape3::Cylinder {
                base: nalgebra::Vector3::from(*base),
                axis: a,
                radius: r,
                length: *length,
            };
            let (lo, hi) = solid.bounding_box();
            Shape2::Rectangle {
                origin: Vector2::new(lo.x, lo.y),
                width: hi.x - lo.x,
                height: hi.y - lo.y,
            }
        }
        BodySpec::Prism { section, .. } => section_shape(section),
    }
}
