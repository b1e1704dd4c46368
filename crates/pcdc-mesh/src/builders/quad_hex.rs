//! Structured Quad4 and Hex8 (and mixed Tri3/Quad4) specimens.

use std::f64::consts::PI;

use super::{at_most, check_count, finite, invalid, positive, Boundary};
use crate::{Dim, Dim2, Dim3, ElementKind, Mesh, MeshError};

/// Like `finish` for cells: builds the mesh from cells, then the boundary node and face
/// groups and the element group `"all"`.
fn finish_cells<D: Dim>(
    coords: Vec<f64>,
    kinds: Vec<ElementKind>,
    conn: Vec<u32>,
    boundaries: Vec<Boundary>,
) -> Result<Mesh<D>, MeshError> {
    let mesh = Mesh::<D>::from_cells(coords, kinds, conn)?;
    super::add_boundaries(mesh, boundaries)
}

/// Rectangle `[x0, x0 + width] x [y0, y0 + height]` (m) of `ceil(width/size)` by
/// `ceil(height/size)` Quad4 cells (each computed as two triangles with a shared
/// volumetric strain, [`crate::cells`]).
///
/// `size` (m) must not exceed the larger of `width` and `height`.
///
/// Groups (nodes and boundary faces): `"left"`, `"right"`, `"bottom"`, `"top"`;
/// elements: `"all"`.
pub fn rectangle_quads(
    x0: f64,
    y0: f64,
    width: f64,
    height: f64,
    size: f64,
) -> Result<Mesh<Dim2>, MeshError> {
    finite("x0", x0)?;
    finite("y0", y0)?;
    positive("width", width)?;
    positive("height", height)?;
    positive("size", size)?;
    at_most(
        "size",
        size,
        width.max(height),
        "must not exceed the larger of width and height",
    )?;
    let (nx, ny) = ((width / size).ceil(), (height / size).ceil());
    check_count::<Dim2>("size", size, 2.0 * nx * ny)?;
    let (nx, ny) = (nx as usize, ny as usize);
    let idx = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut coords = Vec::with_capacity(2 * (nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            coords.push(x0 + width * (i as f64 / nx as f64));
            coords.push(y0 + height * (j as f64 / ny as f64));
        }
    }
    let mut conn = Vec::with_capacity(4 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            conn.extend([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    let boundaries = vec![
        ("left", (0..=ny).map(|j| idx(0, j)).collect()),
        ("right", (0..=ny).map(|j| idx(nx, j)).collect()),
        ("bottom", (0..=nx).map(|i| idx(i, 0)).collect()),
        ("top", (0..=nx).map(|i| idx(i, ny)).collect()),
    ];
    finish_cells(coords, vec![ElementKind::Quad4; nx * ny], conn, boundaries)
}

/// Cuboid `origin + [0, size_xyz[0]] x [0, size_xyz[1]] x [0, size_xyz[2]]` (m) of
/// `ceil(size_xyz[k]/size)` Hex8 cells along each axis (each computed as five or six
/// tetrahedra with a shared volumetric strain, [`crate::cells`]).
///
/// `size` (m) must not exceed the largest side.
///
/// Groups (nodes and boundary faces): `"xmin"`, `"xmax"`, `"ymin"`, `"ymax"`, `"zmin"`,
/// `"zmax"`; elements: `"all"`.
pub fn cuboid_hexes(
    origin: [f64; 3],
    size_xyz: [f64; 3],
    size: f64,
) -> Result<Mesh<Dim3>, MeshError> {
    let grid = super::CuboidGrid::new(origin, size_xyz, size, 6.0)?;
    let (n, idx) = (grid.n, |i, j, k| grid.idx(i, j, k));
    let mut conn = Vec::with_capacity(8 * n[0] * n[1] * n[2]);
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                conn.extend([
                    idx(i, j, k),
                    idx(i + 1, j, k),
                    idx(i + 1, j + 1, k),
                    idx(i, j + 1, k),
                    idx(i, j, k + 1),
                    idx(i + 1, j, k + 1),
                    idx(i + 1, j + 1, k + 1),
                    idx(i, j + 1, k + 1),
                ]);
            }
        }
    }
    let boundaries = grid.boundaries();
    let cells = n[0] * n[1] * n[2];
    finish_cells(
        grid.coords,
        vec![ElementKind::Hex8; cells],
        conn,
        boundaries,
    )
}

/// Annulus `r_in <= |x - center| <= r_out` (m) of Quad4 cells on a polar grid: `n`
/// cells around (`2π r_in / size_in` rounded up to a multiple of 4, so that nodes lie on
/// both axes), radii growing geometrically by `1 + 2π/n` so that every cell is close to
/// square (the size at `r_out` is `r_out / r_in` times `size_in`; the last ring is
/// stretched to end at `r_out`).
///
/// Requires `r_in < r_out` and `size_in <= r_in`.
///
/// Groups (nodes and boundary faces): `"inner"`, `"outer"`; elements: `"all"`.
pub fn ring_quads(
    center: [f64; 2],
    r_in: f64,
    r_out: f64,
    size_in: f64,
) -> Result<Mesh<Dim2>, MeshError> {
    ring_cells(center, r_in, r_out, size_in, false)
}

/// The [`ring_quads`] annulus as a mixed mesh: the polar cells alternate like a
/// checkerboard between one Quad4 and two Tri3 (cut on alternating diagonals), so that
/// both kinds meet everywhere. Same requirements and groups as [`ring_quads`], plus the
/// element groups `"quads"` and `"triangles"`.
pub fn ring_mixed(
    center: [f64; 2],
    r_in: f64,
    r_out: f64,
    size_in: f64,
) -> Result<Mesh<Dim2>, MeshError> {
    ring_cells(center, r_in, r_out, size_in, true)
}

fn ring_cells(
    center: [f64; 2],
    r_in: f64,
    r_out: f64,
    size_in: f64,
    mixed: bool,
) -> Result<Mesh<Dim2>, MeshError> {
    finite("center[0]", center[0])?;
    finite("center[1]", center[1])?;
    positive("r_in", r_in)?;
    positive("r_out", r_out)?;
    positive("size_in", size_in)?;
    if r_out <= r_in {
        return Err(invalid("r_out", r_out, "must exceed r_in"));
    }
    at_most("size_in", size_in, r_in, "must not exceed r_in")?;
    let n = (((2.0 * PI * r_in / size_in) / 4.0).ceil() * 4.0).max(8.0);
    let growth = 1.0 + 2.0 * PI / n;
    let rings = ((r_out / r_in).ln() / growth.ln()).round().max(1.0);
    check_count::<Dim2>("size_in", size_in, 2.0 * n * rings)?;
    let (n, rings) = (n as usize, rings as usize);
    // Geometric radii scaled so that the last one is r_out exactly.
    let q = (r_out / r_in).powf(1.0 / rings as f64);
    let radius = |k: usize| {
        if k == rings {
            r_out
        } else {
            r_in * q.powi(k as i32)
        }
    };
    let idx = |k: usize, i: usize| (k * n + i % n) as u32;
    let mut coords = Vec::with_capacity(2 * n * (rings + 1));
    for k in 0..=rings {
        for i in 0..n {
            let t = 2.0 * PI * i as f64 / n as f64;
            coords.push(center[0] + radius(k) * t.cos());
            coords.push(center[1] + radius(k) * t.sin());
        }
    }
    let (mut kinds, mut conn) = (Vec::new(), Vec::new());
    for k in 0..rings {
        for i in 0..n {
            let (a, b, c, d) = (idx(k, i), idx(k + 1, i), idx(k + 1, i + 1), idx(k, i + 1));
            // Counter-clockwise: outwards, then around.
            if !mixed || (i + k) % 2 == 0 {
                kinds.push(ElementKind::Quad4);
                conn.extend([a, b, c, d]);
            } else {
                kinds.extend([ElementKind::Tri3; 2]);
                if (i / 2 + k) % 2 == 0 {
                    conn.extend([a, b, c, a, c, d]);
                } else {
                    conn.extend([a, b, d, b, c, d]);
                }
            }
        }
    }
    let boundaries = vec![
        ("inner", (0..n).map(|i| idx(0, i)).collect()),
        ("outer", (0..n).map(|i| idx(rings, i)).collect()),
    ];
    let mut mesh: Mesh<Dim2> = finish_cells(coords, kinds, conn, boundaries)?;
    if mixed {
        let (mut quads, mut tris) = (Vec::new(), Vec::new());
        for c in 0..mesh.n_cells() {
            let target = if mesh.cell_kind(c) == ElementKind::Quad4 {
                &mut quads
            } else {
                &mut tris
            };
            target.extend(mesh.cell_elements(c).map(|e| e as u32));
        }
        mesh.add_element_group("quads", quads)?;
        mesh.add_element_group("triangles", tris)?;
    }
    Ok(mesh)
}
