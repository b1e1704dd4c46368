//! Unstructured versions of the standard specimens (the structured ones are in
//! [`crate::builders`]), with the same group names.

use std::f64::consts::TAU;

use super::{triangulate, Domain, Loop, MesherOptions, SizeField};
use crate::builders::positive;
use crate::{Dim2, Mesh, MeshError};

/// Points on a circle of radius `r` about `c` (m), about `h` apart (at least 8).
fn circle(c: [f64; 2], r: f64, h: f64) -> Vec<[f64; 2]> {
    let n = ((TAU * r / h).round() as usize).max(8);
    Loop::circle(c, r, n).points
}

/// Rectangle `[x0, x0 + width] × [y0, y0 + height]` (m), unstructured, element size
/// `options.size`. Groups (nodes and boundary faces): `"left"`, `"right"`, `"bottom"`,
/// `"top"`; elements `"all"`.
pub fn rectangle(
    x0: f64,
    y0: f64,
    width: f64,
    height: f64,
    options: &MesherOptions,
) -> Result<Mesh<Dim2>, MeshError> {
    positive("width", width)?;
    positive("height", height)?;
    let (x1, y1) = (x0 + width, y0 + height);
    let outer = Loop {
        points: vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
        names: ["bottom", "right", "top", "left"]
            .map(String::from)
            .to_vec(),
    };
    triangulate(&Domain::new(outer), options)
}

/// Disc of radius `radius` (m) about `center`, unstructured, uniform size `size` (m),
/// seed `seed`. Groups: `"boundary"` (nodes and faces), `"all"` (elements).
pub fn disc(center: [f64; 2], radius: f64, size: f64, seed: u64) -> Result<Mesh<Dim2>, MeshError> {
    positive("radius", radius)?;
    positive("size", size)?;
    let outer = Loop::named(circle(center, radius, size), "boundary");
    triangulate(
        &Domain::new(outer),
        &MesherOptions::uniform(size).seed(seed),
    )
}

/// Plate `[-half_width, half_width] × [-half_height, half_height]` (m) with a centred
/// hole of radius `radius` (m), graded from `size_hole` at the hole to `size_outer`
/// (growth 0.3 per metre of distance). Groups: `"hole"`, `"left"`, `"right"`,
/// `"bottom"`, `"top"`; elements `"all"`.
pub fn plate_with_hole(
    half_width: f64,
    half_height: f64,
    radius: f64,
    size_hole: f64,
    size_outer: f64,
    seed: u64,
) -> Result<Mesh<Dim2>, MeshError> {
    positive("half_width", half_width)?;
    positive("half_height", half_height)?;
    positive("radius", radius)?;
    positive("size_hole", size_hole)?;
    if radius >= half_width.min(half_height) {
        return Err(MeshError::InvalidParameter {
            name: "radius",
            value: radius,
            reason: "must be smaller than the plate's half width and half height",
        });
    }
    let (w, h) = (half_width, half_height);
    let outer = Loop {
        points: vec![[-w, -h], [w, -h], [w, h], [-w, h]],
        names: ["bottom", "right", "top", "left"]
            .map(String::from)
            .to_vec(),
    };
    let hole = Loop::named(circle([0.0, 0.0], radius, size_hole), "hole");
    let options = MesherOptions {
        size: SizeField::Graded {
            near: size_hole,
            far: size_outer,
            growth: 0.3,
        },
        seed,
        ..MesherOptions::uniform(size_hole)
    };
    triangulate(&Domain::new(outer).hole(hole), &options)
}

/// Annulus `r_in ≤ |x − center| ≤ r_out` (m), graded linearly from `size_in` at the
/// inner circle to `size_out` at the outer one. Groups: `"inner"`, `"outer"`; elements
/// `"all"`.
pub fn ring(
    center: [f64; 2],
    r_in: f64,
    r_out: f64,
    size_in: f64,
    size_out: f64,
    seed: u64,
) -> Result<Mesh<Dim2>, MeshError> {
    positive("r_in", r_in)?;
    positive("r_out", r_out)?;
    positive("size_in", size_in)?;
    positive("size_out", size_out)?;
    if r_in >= r_out {
        return Err(MeshError::InvalidParameter {
            name: "r_in",
            value: r_in,
            reason: "must be smaller than r_out",
        });
    }
    let growth = ((size_out - size_in) / (r_out - r_in)).max(1e-3);
    let outer = Loop::named(circle(center, r_out, size_out.max(size_in)), "outer");
    let inner = Loop::named(circle(center, r_in, size_in), "inner");
    let options = MesherOptions {
        size: SizeField::Graded {
            near: size_in,
            far: size_out.max(size_in),
            growth,
        },
        seed,
        ..MesherOptions::uniform(size_in)
    };
    triangulate(&Domain::new(outer).hole(inner), &options)
}
