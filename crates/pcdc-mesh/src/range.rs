//! Ranges: selections of nodes, elements or faces (manual chapter 4, item 11).
//!
//! A range selects by named group, by geometry (box, circle/sphere, plane) evaluated at
//! node positions or element/face centroids, or by a user closure; ranges combine with
//! `and`, `or` and `not`.

use std::fmt;
use std::sync::Arc;

/// A predicate on a point (`D` coordinates, metres).
pub type PointPredicate = Arc<dyn Fn(&[f64]) -> bool + Send + Sync>;

/// A selection of mesh entities.
#[derive(Clone)]
pub enum Range {
    /// Every entity.
    All,
    /// The entities of a named group (of the kind being selected).
    Group(String),
    /// Points with `min <= x <= max` component-wise (only the first `D` components are used).
    Box {
        /// Lower corner (m).
        min: [f64; 3],
        /// Upper corner (m).
        max: [f64; 3],
    },
    /// Points within `radius` of `center` (a circle in 2D, a sphere in 3D).
    Ball {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
    /// Points within `tol` of the line (2D) or plane (3D) through `point` with normal `normal`.
    Plane {
        /// A point on the plane (m).
        point: [f64; 3],
        /// Plane normal (need not be unit length, must be non-zero).
        normal: [f64; 3],
        /// Distance tolerance (m).
        tol: f64,
    },
    /// Points on the positive side of the plane (`(x - point) . normal >= 0`).
    HalfSpace {
        /// A point on the bounding plane (m).
        point: [f64; 3],
        /// Outward normal of the selected side.
        normal: [f64; 3],
    },
    /// Points accepted by a user closure.
    Custom(PointPredicate),
    /// Both ranges.
    And(Box<Range>, Box<Range>),
    /// Either range.
    Or(Box<Range>, Box<Range>),
    /// The complement of a range.
    Not(Box<Range>),
}

impl fmt::Debug for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Range::All => write!(f, "All"),
            Range::Group(g) => write!(f, "Group({g:?})"),
            Range::Box { min, max } => write!(f, "Box({min:?}..{max:?})"),
            Range::Ball { center, radius } => write!(f, "Ball({center:?}, r={radius})"),
            Range::Plane { point, normal, tol } => {
                write!(f, "Plane({point:?}, n={normal:?}, tol={tol})")
            }
            Range::HalfSpace { point, normal } => write!(f, "HalfSpace({point:?}, n={normal:?})"),
            Range::Custom(_) => write!(f, "Custom(..)"),
            Range::And(a, b) => write!(f, "And({a:?}, {b:?})"),
            Range::Or(a, b) => write!(f, "Or({a:?}, {b:?})"),
            Range::Not(a) => write!(f, "Not({a:?})"),
        }
    }
}

impl Range {
    /// A range from a named group.
    pub fn group(name: impl Into<String>) -> Self {
        Range::Group(name.into())
    }

    /// A 2D box `[x0, x1] x [y0, y1]`.
    pub fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Range::Box {
            min: [x0, y0, f64::NEG_INFINITY],
            max: [x1, y1, f64::INFINITY],
        }
    }

    /// A 3D box.
    pub fn cuboid(min: [f64; 3], max: [f64; 3]) -> Self {
        Range::Box { min, max }
    }

    /// Points within `tol` of the plane (line in 2D) through `point` with normal `normal`.
    pub fn plane(point: [f64; 3], normal: [f64; 3], tol: f64) -> Self {
        Range::Plane { point, normal, tol }
    }

    /// A closure range.
    pub fn custom(f: impl Fn(&[f64]) -> bool + Send + Sync + 'static) -> Self {
        Range::Custom(Arc::new(f))
    }

    /// Intersection.
    pub fn and(self, other: Range) -> Self {
        Range::And(Box::new(self), Box::new(other))
    }

    /// Union.
    pub fn or(self, other: Range) -> Self {
        Range::Or(Box::new(self), Box::new(other))
    }

    /// Complement (named to avoid clashing with `std::ops::Not`).
    pub fn complement(self) -> Self {
        Range::Not(Box::new(self))
    }

    /// Checks the range for a mesh of dimension `dim` (2 or 3): only the first `dim`
    /// components of points and normals count.
    ///
    /// A range that can select nothing is an error, as it is almost always a mistake:
    /// NaN or crossed box corners (`min[k] > max[k]`), a box corner at `+∞` as minimum or
    /// `-∞` as maximum, a non-finite ball centre or plane point, a NaN or negative radius
    /// or tolerance, and a plane or half-space normal that is zero or non-finite in the
    /// first `dim` components (e.g. a z-only normal `[0, 0, 1]` in 2D).
    pub fn validate(&self, dim: usize) -> Result<(), crate::MeshError> {
        let bad = |s: String| Err(crate::MeshError::InvalidRange(s));
        if dim != 2 && dim != 3 {
            return bad(format!("dimension {dim}: ranges select in 2D or 3D"));
        }
        let point = |what: &str, p: &[f64; 3]| {
            if p[..dim].iter().all(|v| v.is_finite()) {
                Ok(())
            } else {
                bad(format!(
                    "{what} {p:?} is not finite: the range selects nothing"
                ))
            }
        };
        let normal = |what: &str, n: &[f64; 3]| {
            if n[..dim].iter().any(|v| !v.is_finite()) {
                return bad(format!("{what} {n:?} is not finite"));
            }
            if n[..dim].iter().all(|v| *v == 0.0) {
                let hint = if dim == 2 && n[2] != 0.0 {
                    ": a z-only normal has no direction in 2D"
                } else {
                    ""
                };
                return bad(format!(
                    "{what} {n:?} is zero in the first {dim} components{hint}"
                ));
            }
            Ok(())
        };
        match self {
            Range::Box { min, max } => {
                for k in 0..dim {
                    let (lo, hi) = (min[k], max[k]);
                    if lo.is_nan() || hi.is_nan() {
                        return bad(format!(
                            "box corner min {min:?} / max {max:?} has NaN in component {k}"
                        ));
                    }
                    if lo > hi || lo == f64::INFINITY || hi == f64::NEG_INFINITY {
                        return bad(format!(
                            "box min[{k}] = {lo} and max[{k}] = {hi} select nothing (need min <= max, finite or open towards infinity)"
                        ));
                    }
                }
                Ok(())
            }
            Range::Ball { center, radius } => {
                point("ball centre", center)?;
                if radius.is_nan() || *radius < 0.0 {
                    return bad(format!("ball radius {radius} must be non-negative"));
                }
                Ok(())
            }
            Range::Plane {
                point: p,
                normal: n,
                tol,
            } => {
                if tol.is_nan() || *tol < 0.0 {
                    return bad(format!("plane tolerance {tol} must be non-negative"));
                }
                point("plane point", p)?;
                normal("plane normal", n)
            }
            Range::HalfSpace {
                point: p,
                normal: n,
            } => {
                point("half-space point", p)?;
                normal("half-space normal", n)
            }
            Range::And(a, b) | Range::Or(a, b) => {
                a.validate(dim)?;
                b.validate(dim)
            }
            Range::Not(a) => a.validate(dim),
            Range::All | Range::Group(_) | Range::Custom(_) => Ok(()),
        }
    }

    /// Whether a free point `x` (length `D`, m) lies in the range, for entities that are
    /// not nodes, elements or faces (e.g. joints). Group ranges cannot answer for a
    /// point and are an error.
    pub fn contains_point(&self, x: &[f64]) -> Result<bool, crate::MeshError> {
        self.validate(x.len())?;
        let mut names = Vec::new();
        self.group_names(&mut names);
        if let Some(g) = names.first() {
            return Err(crate::MeshError::InvalidRange(format!(
                "group '{g}' cannot select a free point; use a geometric range"
            )));
        }
        Ok(self.contains(x, &|_| false))
    }

    /// Whether the point `x` (length `D`) lies in the geometric part of the range.
    /// `in_group` answers group membership for the entity being tested.
    pub(crate) fn contains(&self, x: &[f64], in_group: &dyn Fn(&str) -> bool) -> bool {
        let d = x.len();
        match self {
            Range::All => true,
            Range::Group(g) => in_group(g),
            Range::Box { min, max } => (0..d).all(|k| x[k] >= min[k] && x[k] <= max[k]),
            Range::Ball { center, radius } => {
                (0..d).map(|k| (x[k] - center[k]).powi(2)).sum::<f64>() <= radius * radius
            }
            Range::Plane { point, normal, tol } => {
                let nn = (0..d).map(|k| normal[k] * normal[k]).sum::<f64>().sqrt();
                let dist = (0..d).map(|k| (x[k] - point[k]) * normal[k]).sum::<f64>() / nn;
                dist.abs() <= *tol
            }
            Range::HalfSpace { point, normal } => {
                (0..d).map(|k| (x[k] - point[k]) * normal[k]).sum::<f64>() >= 0.0
            }
            Range::Custom(f) => f(x),
            Range::And(a, b) => a.contains(x, in_group) && b.contains(x, in_group),
            Range::Or(a, b) => a.contains(x, in_group) || b.contains(x, in_group),
            Range::Not(a) => !a.contains(x, in_group),
        }
    }

    /// Names of all groups the range refers to.
    pub(crate) fn group_names<'a>(&'a self, out: &mut Vec<&'a str>) {
        match self {
            Range::Group(g) => out.push(g),
            Range::And(a, b) | Range::Or(a, b) => {
                a.group_names(out);
                b.group_names(out);
            }
            Range::Not(a) => a.group_names(out),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(r: &Range, dim: usize) -> String {
        r.validate(dim).unwrap_err().to_string()
    }

    #[test]
    fn ranges_that_select_nothing_are_refused_per_dimension() {
        let z_only = Range::plane([0.0; 3], [0.0, 0.0, 1.0], 0.1);
        assert!(err(&z_only, 2).contains("z-only"));
        assert!(z_only.validate(3).is_ok());
        // A NaN z corner only matters in 3D.
        let nan_z = Range::cuboid([0.0, 0.0, f64::NAN], [1.0; 3]);
        assert!(nan_z.validate(2).is_ok());
        assert!(err(&nan_z, 3).contains("component 2"));
        assert!(err(&Range::rect(1.0, 0.0, 0.0, 1.0), 2).contains("min[0] = 1"));
        assert!(
            Range::rect(0.0, 0.0, 0.0, 1.0).validate(2).is_ok(),
            "a line box"
        );
        assert!(err(&Range::All, 1).contains("dimension 1"));
        let nested = Range::All.or(Range::Ball {
            center: [f64::NAN; 3],
            radius: 1.0,
        });
        assert!(err(&nested, 2).contains("ball centre"));
    }
}
