//! 3D specimen bodies: a box, a cylinder about any axis, and any 2D shape
//! extruded through a thickness along z (so the dog-bone, the notched beam and every body
//! with cutouts come as prisms). They answer what the FCC lattice asks of a body: a bounding
//! box, a point test with a tolerance, whether a bond stays in the body, and the volume.

use super::Shape2;
use nalgebra::{Vector2, Vector3};

/// The dyad n⊗n of a direction in Voigt order [xx, yy, zz, yz, xz, xy]: a bond's strain
/// projector (its stretch under a small strain ε is p·ε with engineering shears), shared by
/// the strain fit (`model::dimension`) and the FCC fill's test of which particles' bonds
/// determine a strain (`discretise::fcc`).
pub fn dyad_voigt(n: &Vector3<f64>) -> nalgebra::Vector6<f64> {
    nalgebra::Vector6::new(
        n.x * n.x,
        n.y * n.y,
        n.z * n.z,
        n.y * n.z,
        n.x * n.z,
        n.x * n.y,
    )
}

/// A 3D specimen shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape3 {
    /// Axis-aligned box `[origin, origin + size]`.
    Box {
        origin: Vector3<f64>,
        size: Vector3<f64>,
    },
    /// Circular cylinder: base centre, unit axis, radius, length along the axis.
    Cylinder {
        base: Vector3<f64>,
        axis: Vector3<f64>,
        radius: f64,
        length: f64,
    },
    /// A 2D section (x, y) extruded through z ∈ [0, thickness].
    Extruded { section: Shape2, thickness: f64 },
}

/// A body that is a 2D section swept along an axis (a prism, a cylinder): `section` in the
/// local (u, v) plane through local w ∈ [0, length]; [`Sweep::local`] maps a position to
/// (u, v, w).
#[derive(Clone, Debug)]
pub struct Sweep {
    pub section: Shape2,
    pub length: f64,
    origin: Vector3<f64>,
    /// Rows: the local u, v and w axes (w the sweep's axis).
    axes: nalgebra::Matrix3<f64>,
}

impl Sweep {
    /// Local coordinates (u, v, w) of `x`.
    #[inline]
    pub fn local(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.axes * (x - self.origin)
    }

    /// The position of local coordinates (u, v, w): the inverse of [`Sweep::local`].
    #[inline]
    pub fn global(&self, q: &Vector3<f64>) -> Vector3<f64> {
        self.origin + self.axes.transpose() * q
    }
}

impl Shape3 {
    /// Lower and upper corners of the axis-aligned bounding box.
    pub fn bounding_box(&self) -> (Vector3<f64>, Vector3<f64>) {
        match self {
            Shape3::Box { origin, size } => (*origin, origin + size),
            Shape3::Cylinder {
                base,
                axis,
                radius,
                length,
            } => {
                let top = base + axis * *length;
                // a disc of radius r normal to a reaches r·√(1 − a_d²) along axis d
                let reach =
                    Vector3::from_fn(|d, _| radius * (1.0 - axis[d] * axis[d]).max(0.0).sqrt());
                (base.inf(&top) - reach, base.sup(&top) + reach)
            }
            Shape3::Extruded { section, thickness } => {
                let (lo, hi) = section.bounding_box();
                (
                    Vector3::new(lo.x, lo.y, 0.0),
                    Vector3::new(hi.x, hi.y, *thickness),
                )
            }
        }
    }

    /// The largest extent of the bounding box.
    pub fn size(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).max()
    }

    /// Volume (m³).
    pub fn volume(&self) -> f64 {
        match self {
            Shape3::Box { size, .. } => size.x * size.y * size.z,
            Shape3::Cylinder { radius, length, .. } => {
                std::f64::consts::PI * radius * radius * length
            }
            Shape3::Extruded { section, thickness } => section.area() * thickness,
        }
    }

    /// Whether `p` lies in the body or within `tol` of it.
    pub fn contains(&self, p: &Vector3<f64>, tol: f64) -> bool {
        match self {
            Shape3::Box { origin, size } => {
                (0..3).all(|d| p[d] >= origin[d] - tol && p[d] <= origin[d] + size[d] + tol)
            }
            Shape3::Cylinder {
                base,
                axis,
                radius,
                length,
            } => {
                let r = p - base;
                let h = r.dot(axis);
                h >= -tol && h <= length + tol && (r - axis * h).norm() <= radius + tol
            }
            Shape3::Extruded { section, thickness } => {
                p.z >= -tol
                    && p.z <= thickness + tol
                    && section.contains(&Vector2::new(p.x, p.y), tol)
            }
        }
    }

    /// Whether the bond from `a` to `b` (both in the body) stays in it: always for the convex
    /// box and cylinder; for a prism, the section's test of the bond's projection
    /// ([`Shape2::segment_in_body`], `parts` as there: the outline at the interior
    /// `parts`-th points, every cutout exactly).
    pub fn segment_in_body(
        &self,
        a: &Vector3<f64>,
        b: &Vector3<f64>,
        tol: f64,
        parts: usize,
    ) -> bool {
        match self {
            Shape3::Box { .. } | Shape3::Cylinder { .. } => true,
            Shape3::Extruded { section, .. } => {
                let (pa, pb) = (Vector2::new(a.x, a.y), Vector2::new(b.x, b.y));
                (pa - pb).norm() <= tol || section.segment_in_body(&pa, &pb, tol, parts)
            }
        }
    }

    /// The body as a section swept along an axis: a prism's section along z, a cylinder's
    /// disc along its axis (u, v completing the axis to a right-handed frame); `None` for
    /// the box.
    pub fn sweep(&self) -> Option<Sweep> {
        match self {
            Shape3::Box { .. } => None,
            Shape3::Extruded { section, thickness } => Some(Sweep {
                section: section.clone(),
                length: *thickness,
                origin: Vector3::zeros(),
                axes: nalgebra::Matrix3::identity(),
            }),
            Shape3::Cylinder {
                base,
                axis,
                radius,
                length,
            } => {
                let w = axis.normalize();
                let helper = if w.x.abs() < 0.9 {
                    Vector3::x()
                } else {
                    Vector3::y()
                };
                let u = helper.cross(&w).normalize();
                let v = w.cross(&u);
                Some(Sweep {
                    section: Shape2::Disc {
                        centre: Vector2::zeros(),
                        radius: *radius,
                    },
                    length: *length,
                    origin: *base,
                    axes: nalgebra::Matrix3::from_rows(&[
                        u.transpose(),
                        v.transpose(),
                        w.transpose(),
                    ]),
                })
            }
        }
    }

    /// The body as a section swept along an axis, the box included (its rectangle in x, y
    /// along z): what the surface of random particles is sampled on (`discretise::random3`).
    pub fn as_sweep(&self) -> Sweep {
        match self {
            Shape3::Box { origin, size } => Sweep {
                section: Shape2::Rectangle {
                    origin: Vector2::new(origin.x, origin.y),
                    width: size.x,
                    height: size.y,
                },
                length: size.z,
                origin: Vector3::new(0.0, 0.0, origin.z),
                axes: nalgebra::Matrix3::identity(),
            },
            _ => self.sweep().expect("a prism or a cylinder is a sweep"),
        }
    }

    /// The body as half-spaces n·x ≤ c (n outward unit normals) where it is a convex
    /// polyhedron (the box); `None` otherwise.
    pub fn planes(&self) -> Option<Vec<(Vector3<f64>, f64)>> {
        match self {
            Shape3::Box { origin, size } => Some(
                (0..3)
                    .flat_map(|d| {
                        let e = Vector3::from_fn(|k, _| if k == d { 1.0 } else { 0.0 });
                        [(e, origin[d] + size[d]), (-e, -origin[d])]
                    })
                    .collect(),
            ),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn volumes_and_point_tests() {
        let b = Shape3::Box {
            origin: Vector3::new(1.0, 2.0, 3.0),
            size: Vector3::new(2.0, 3.0, 4.0),
        };
        assert_relative_eq!(b.volume(), 24.0);
        assert!(b.contains(&Vector3::new(3.0, 5.0, 7.0), 1e-12));
        assert!(!b.contains(&Vector3::new(3.1, 5.0, 7.0), 1e-12));
        let axis = Vector3::new(1.0, 1.0, 0.0).normalize();
        let c = Shape3::Cylinder {
            base: Vector3::zeros(),
            axis,
            radius: 0.5,
            length: 2.0,
        };
        assert_relative_eq!(c.volume(), std::f64::consts::PI * 0.5);
        // two unit vectors normal to the axis and to each other
        let u = axis.cross(&Vector3::z()).normalize();
        let v = axis.cross(&u);
        let mid = axis * 1.0;
        assert!(c.contains(&(mid + u * 0.499), 0.0));
        assert!(!c.contains(&(mid + v * 0.501), 0.0));
        assert!(!c.contains(&(axis * 2.01), 0.0));
        // the bounding box holds the rim points
        let (lo, hi) = c.bounding_box();
        for k in 0..64 {
            let t = k as f64 / 64.0 * std::f64::consts::TAU;
            for h in [0.0, 2.0] {
                let p = axis * h + (u * t.cos() + v * t.sin()) * 0.5;
                assert!((0..3).all(|d| p[d] >= lo[d] - 1e-12 && p[d] <= hi[d] + 1e-12));
            }
        }
        let e = Shape3::Extruded {
            section: Shape2::Disc {
                centre: Vector2::zeros(),
                radius: 1.0,
            },
            thickness: 0.5,
        };
        assert_relative_eq!(e.volume(), 0.5 * std::f64::consts::PI, max_relative = 1e-12);
        assert!(e.contains(&Vector3::new(0.0, 0.99, 0.25), 0.0));
        assert!(!e.contains(&Vector3::new(0.0, 0.99, 0.51), 0.0));
    }
}
