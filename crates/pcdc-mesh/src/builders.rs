//! Specimen builders: meshes of the standard rock-mechanics specimens.
//!
//! All lengths are in metres. Every builder takes a target element size (m), checks its
//! parameters (returning [`MeshError::InvalidParameter`], never panicking), emits correctly
//! oriented elements (counter-clockwise Tri3, positive Tet4) and builds the mesh with
//! [`Mesh::new`], which checks it again. For each boundary it names, a builder adds a node
//! group and a boundary-face group of the same name; it also adds the element group `"all"`.
//!
//! Curved boundaries are polygons whose nodes lie on the exact curve, so the meshed area or
//! volume is slightly smaller than the exact one (by about `(2π/n)²/6` for `n` nodes per
//! circle). Circular meshes are built from concentric node loops "stitched" into bands of
//! triangles; the cylinder extrudes the disc and splits each prism into three tetrahedra.
//!
//! A size so small that the mesh could not be numbered with 32-bit indices is rejected as
//! [`MeshError::InvalidParameter`]; one whose estimated memory exceeds the
//! [memory limit](crate::memory) (by default half the machine's memory) is rejected as
//! [`MeshError::MemoryLimit`], with the estimate in bytes, before anything is allocated.

use std::f64::consts::{PI, TAU};

use crate::{Dim, Dim2, Dim3, Mesh, MeshError};

/// Largest number of elements 32-bit indices can number.
const MAX_ELEMENTS: f64 = u32::MAX as f64;

/// A named boundary: its nodes, from which its boundary faces are found.
type Boundary = (&'static str, Vec<u32>);

mod quad_hex;
pub use quad_hex::{cuboid_hexes, rectangle_quads, ring_mixed, ring_quads};

// ---------------------------------------------------------------------------------------
// Parameter checks
// ---------------------------------------------------------------------------------------

fn invalid(name: &'static str, value: f64, reason: &'static str) -> MeshError {
    MeshError::InvalidParameter {
        name,
        value,
        reason,
    }
}

fn finite(name: &'static str, v: f64) -> Result<f64, MeshError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(name, v, "must be finite"))
    }
}

pub(crate) fn positive(name: &'static str, v: f64) -> Result<f64, MeshError> {
    if finite(name, v)? > 0.0 {
        Ok(v)
    } else {
        Err(invalid(name, v, "must be positive"))
    }
}

fn at_most(name: &'static str, v: f64, limit: f64, reason: &'static str) -> Result<(), MeshError> {
    if v <= limit {
        Ok(())
    } else {
        Err(invalid(name, v, reason))
    }
}

/// Rejects a size that would give a mesh of `count` elements (an estimate) of dimension
/// `D` that 32-bit indices cannot number, or whose memory estimate
/// ([`crate::memory::mesh_bytes`], with as many nodes as elements, an upper bound) exceeds
/// the [memory limit](crate::memory).
fn check_count<D: Dim>(name: &'static str, size: f64, count: f64) -> Result<(), MeshError> {
    if count.is_nan() || count > MAX_ELEMENTS {
        return Err(invalid(
            name,
            size,
            "too small: the mesh would exceed 2^32 - 1 elements, the limit of 32-bit indices",
        ));
    }
    crate::memory::check_mesh_memory::<D>(name, size, count, count)
}

// ---------------------------------------------------------------------------------------
// Shared construction helpers
// ---------------------------------------------------------------------------------------

/// `(1 - t) a + t b`, exact at `t = 0` and `t = 1`.
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    (1.0 - t) * a + t * b
}

/// Builds the mesh, then for each boundary its node group and the face group of the
/// boundary faces whose nodes all belong to it, and the element group "all".
fn finish<D: Dim>(
    coords: Vec<f64>,
    elements: Vec<u32>,
    boundaries: Vec<Boundary>,
) -> Result<Mesh<D>, MeshError> {
    add_boundaries(Mesh::<D>::new(coords, elements)?, boundaries)
}

/// Adds the boundary node and face groups and the element group `"all"`.
fn add_boundaries<D: Dim>(
    mut mesh: Mesh<D>,
    boundaries: Vec<Boundary>,
) -> Result<Mesh<D>, MeshError> {
    for (name, nodes) in boundaries {
        let mut on = vec![false; mesh.n_nodes()];
        nodes.iter().for_each(|&n| on[n as usize] = true);
        let faces = (mesh.faces().boundary.iter().copied())
            .filter(|&f| mesh.face(f as usize).iter().all(|&n| on[n as usize]))
            .collect();
        mesh.add_node_group(name, nodes)?;
        mesh.add_face_group(name, faces)?;
    }
    mesh.add_element_group("all", (0..mesh.n_elements() as u32).collect())?;
    Ok(mesh)
}

/// Smallest interior angle of a triangle (radians), or `None` unless it is counter-clockwise.
fn min_angle(p: [[f64; 2]; 3]) -> Option<f64> {
    let sub = |a: [f64; 2], b: [f64; 2]| [a[0] - b[0], a[1] - b[1]];
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    if cross(sub(p[1], p[0]), sub(p[2], p[0])) <= 0.0 {
        return None;
    }
    (0..3)
        .map(|k| {
            let (e1, e2) = (sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
            cross(e1, e2).abs().atan2(e1[0] * e2[0] + e1[1] * e2[1])
        })
        .reduce(f64::min)
}

/// A closed counter-clockwise loop of nodes, each with its position `at` along the loop
/// (increasing, less than `at[0] + 1`); loops stitched together share this parameterisation
/// (e.g. the polar angle in turns).
#[derive(Clone, Default)]
struct Loop {
    nodes: Vec<u32>,
    at: Vec<f64>,
}

/// A triangulation under construction.
#[derive(Default)]
struct Planar {
    xy: Vec<f64>,
    tris: Vec<u32>,
}

impl Planar {
    fn node(&mut self, p: [f64; 2]) -> u32 {
        self.xy.extend(p);
        (self.xy.len() / 2 - 1) as u32
    }

    /// Adds the nodes of a loop given as `(point, parameter)` pairs.
    fn add_loop(&mut self, pts: impl IntoIterator<Item = ([f64; 2], f64)>) -> Loop {
        let mut l = Loop::default();
        for (p, at) in pts {
            l.nodes.push(self.node(p));
            l.at.push(at);
        }
        l
    }

    fn point(&self, n: u32) -> [f64; 2] {
        [self.xy[2 * n as usize], self.xy[2 * n as usize + 1]]
    }

    /// Structured `(nx+1) x (ny+1)` grid (node `j*(nx+1)+i` at `point(i, j)`), each cell cut on
    /// its diagonal from `(i, j)` to `(i+1, j+1)`. `point` must keep the cells convex and
    /// counter-clockwise (x growing with `i`, y with `j`).
    fn grid(nx: usize, ny: usize, point: impl Fn(usize, usize) -> [f64; 2]) -> Self {
        let mut p = Planar::default();
        for j in 0..=ny {
            for i in 0..=nx {
                p.node(point(i, j));
            }
        }
        let idx = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
                p.tris.extend([a, b, c, a, c, d]);
            }
        }
        p
    }

    /// Structured strip grown from the straight row of nodes `base` (m), translated by
    /// `offset` in `cols` equal steps; each quadrilateral is cut on a diagonal. Returns the
    /// node columns, column 0 being `base`.
    fn extrude(&mut self, base: &[u32], offset: [f64; 2], cols: usize) -> Vec<Vec<u32>> {
        let (p0, p1) = (self.point(base[0]), self.point(base[base.len() - 1]));
        let ccw = offset[0] * (p1[1] - p0[1]) - offset[1] * (p1[0] - p0[0]) > 0.0;
        let pts: Vec<[f64; 2]> = base.iter().map(|&b| self.point(b)).collect();
        let mut grid = vec![base.to_vec()];
        for c in 1..=cols {
            let f = c as f64 / cols as f64;
            grid.push(
                pts.iter()
                    .map(|q| self.node([q[0] + f * offset[0], q[1] + f * offset[1]]))
                    .collect(),
            );
        }
        for c in 0..cols {
            for j in 0..base.len() - 1 {
                let (a, b, c, d) = (
                    grid[c][j],
                    grid[c + 1][j],
                    grid[c + 1][j + 1],
                    grid[c][j + 1],
                );
                self.tris.extend(if ccw {
                    [a, b, c, a, c, d]
                } else {
                    [a, c, b, a, d, c]
                });
            }
        }
        grid
    }

    /// Triangles from `centre` to each edge of the loop.
    fn fan(&mut self, centre: u32, l: &Loop) {
        let n = &l.nodes;
        for (k, &a) in n.iter().enumerate() {
            self.tris.extend([centre, a, n[(k + 1) % n.len()]]);
        }
    }

    /// Triangulates the band between two loops, `inner` inside `outer`, like a merge: each
    /// step advances along one loop and adds one triangle. A loop may advance only while its
    /// current node does not pass the other loop's next node in the shared parameter (so the
    /// fronts stay abreast); when both may, the triangle with the shorter new edge is taken,
    /// and an inverted candidate never is while the other one is valid.
    fn stitch(&mut self, inner: &Loop, outer: &Loop) {
        let (na, nb) = (inner.nodes.len(), outer.nodes.len());
        let at = |l: &Loop, k: usize| l.at.get(k).copied().unwrap_or(l.at[0] + 1.0);
        let (mut i, mut j) = (0, 0);
        while i < na || j < nb {
            let (a, b) = (inner.nodes[i % na], outer.nodes[j % nb]);
            let (a1, b1) = (inner.nodes[(i + 1) % na], outer.nodes[(j + 1) % nb]);
            let ok = |t: [u32; 3]| min_angle(t.map(|n| self.point(n))).is_some();
            let dist2 = |m: u32, n: u32| {
                let (p, q) = (self.point(m), self.point(n));
                (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
            };
            let may_outer = j < nb && (i == na || at(outer, j) <= at(inner, i + 1));
            let may_inner = i < na && (j == nb || at(inner, i) <= at(outer, j + 1));
            let mut advance_outer = may_outer && (!may_inner || dist2(a, b1) <= dist2(a1, b));
            let (outer_ok, inner_ok) = (j < nb && ok([a, b, b1]), i < na && ok([a, b, a1]));
            let (chosen_ok, other_ok) = if advance_outer {
                (outer_ok, inner_ok)
            } else {
                (inner_ok, outer_ok)
            };
            if !chosen_ok && other_ok {
                advance_outer = !advance_outer;
            }
            if advance_outer {
                self.tris.extend([a, b, b1]);
                j += 1;
            } else {
                self.tris.extend([a, b, a1]);
                i += 1;
            }
        }
    }

    /// Stitches each pair of consecutive loops.
    fn stitch_all(&mut self, loops: &[Loop]) {
        for w in loops.windows(2) {
            self.stitch(&w[0], &w[1]);
        }
    }
}

/// `n` equally spaced points on a circle, counter-clockwise from angle 0, with their
/// loop parameter (fraction of a turn).
fn circle(c: [f64; 2], r: f64, n: usize) -> impl Iterator<Item = ([f64; 2], f64)> {
    (0..n).map(move |m| {
        let at = m as f64 / n as f64;
        let a = TAU * at;
        ([c[0] + r * a.cos(), c[1] + r * a.sin()], at)
    })
}

/// Largest growth of the element size per unit distance in graded meshes: a faster
/// requested growth is slowed down (the coarse end gets finer elements than requested).
const GRADATION: f64 = 0.5;

/// Element size varying linearly across a radial length `len` from `h0` to `h1`, with the
/// slope limited to [`GRADATION`] (the finer end keeps its size).
struct Grading {
    len: f64,
    h0: f64,
    h1: f64,
}

impl Grading {
    fn new(len: f64, h0: f64, h1: f64) -> Self {
        let cap = GRADATION * len;
        Grading {
            len,
            h0: h0.min(h1 + cap),
            h1: h1.min(h0 + cap),
        }
    }

    /// Size at the fraction `t` of the length.
    fn size(&self, t: f64) -> f64 {
        lerp(self.h0, self.h1, t)
    }

    /// Number of steps across the length (the continuous count `∫ dx / h(x)`).
    fn count(&self) -> f64 {
        let ratio = self.h1 / self.h0;
        if (ratio - 1.0).abs() < 1e-9 {
            self.len / self.h0
        } else {
            self.len * ratio.ln() / (self.h1 - self.h0)
        }
    }

    /// Fractions `0 = t_0 < t_1 < ... < t_N = 1` of the length, in geometric steps growing
    /// from about `h0` to about `h1`.
    fn levels(&self) -> Vec<f64> {
        let n = (self.count().round() as usize).max(1);
        let g = (self.h1 / self.h0).powf(1.0 / n as f64);
        (0..=n)
            .map(|k| {
                if (g - 1.0).abs() < 1e-12 {
                    k as f64 / n as f64
                } else {
                    (g.powi(k as i32) - 1.0) / (g.powi(n as i32) - 1.0)
                }
            })
            .collect()
    }
}

/// Node count of a loop given the count `prev` of the loop inside it: at most a factor 2
/// coarser or finer, so every stitched band stays well shaped even when the requested sizes
/// change faster than the loops allow.
fn limit_growth(prev: f64, n: f64) -> f64 {
    n.clamp((prev / 2.0).ceil(), 2.0 * prev)
}

/// Uniform disc triangulation: centre node, fan, and `ceil(radius/size)` stitched circles
/// with about `2π k` nodes on circle `k`. Returns it with the boundary loop.
fn disc_planar(center: [f64; 2], radius: f64, size: f64) -> Result<(Planar, Vec<u32>), MeshError> {
    let nr = (radius / size).ceil();
    check_count::<Dim2>("size", size, 7.0 * nr * nr)?;
    let nr = nr as usize;
    let mut p = Planar::default();
    let c = p.node(center);
    let loops: Vec<Loop> = (1..=nr)
        .map(|k| {
            let n = ((TAU * k as f64).round() as usize).max(6);
            p.add_loop(circle(center, radius * k as f64 / nr as f64, n))
        })
        .collect();
    p.fan(c, &loops[0]);
    p.stitch_all(&loops);
    let rim = loops.last().map(|l| l.nodes.clone()).unwrap_or_default();
    Ok((p, rim))
}

// ---------------------------------------------------------------------------------------
// 2D builders
// ---------------------------------------------------------------------------------------

/// Rectangle `[x0, x0 + width] x [y0, y0 + height]` (m): `nx = ceil(width/size)` by
/// `ny = ceil(height/size)` cells, each cut on its diagonal from lower-left to upper-right
/// into two right triangles (the project's standard benchmark mesh, `2 nx ny` elements).
///
/// `size` (m) must not exceed the larger of `width` and `height`.
///
/// Groups (nodes and boundary faces): `"left"`, `"right"`, `"bottom"`, `"top"`; elements: `"all"`.
pub fn rectangle(
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
    let p = Planar::grid(nx, ny, |i, j| {
        [
            x0 + width * (i as f64 / nx as f64),
            y0 + height * (j as f64 / ny as f64),
        ]
    });
    let idx = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let boundaries = vec![
        ("left", (0..=ny).map(|j| idx(0, j)).collect()),
        ("right", (0..=ny).map(|j| idx(nx, j)).collect()),
        ("bottom", (0..=nx).map(|i| idx(i, 0)).collect()),
        ("top", (0..=nx).map(|i| idx(i, ny)).collect()),
    ];
    finish(p.xy, p.tris, boundaries)
}

/// Annulus `r_in <= |x - center| <= r_out` (m), graded: the element size varies linearly
/// with radius from `size_in` at `r_in` to `size_out` at `r_out` (m).
///
/// Nodes lie on concentric circles whose spacing grows geometrically (the last circle is
/// exactly `r_out`); circle `k` carries `max(8, round(2π r_k / h(r_k)))` equally spaced nodes
/// (kept within a factor 2 of the previous circle's count) and consecutive circles are
/// stitched. With `r_out = 25 r_in`, `size_in = r_in/10`,
/// `size_out = 2.5 r_in` (a Kirsch problem) this gives about four thousand elements.
///
/// Requires `r_in < r_out`, `size_in <= r_in` and both sizes at most the thickness
/// `r_out - r_in`. The size grows by at most half the distance travelled (a faster growth
/// is slowed, giving finer elements than `size_out` near `r_out`).
///
/// Groups (nodes and boundary faces): `"inner"`, `"outer"`; elements: `"all"`.
pub fn ring(
    center: [f64; 2],
    r_in: f64,
    r_out: f64,
    size_in: f64,
    size_out: f64,
) -> Result<Mesh<Dim2>, MeshError> {
    finite("center[0]", center[0])?;
    finite("center[1]", center[1])?;
    positive("r_in", r_in)?;
    positive("r_out", r_out)?;
    positive("size_in", size_in)?;
    positive("size_out", size_out)?;
    if r_in >= r_out {
        return Err(invalid("r_in", r_in, "must be smaller than r_out"));
    }
    at_most("size_in", size_in, r_in, "must not exceed r_in")?;
    let thickness = r_out - r_in;
    at_most(
        "size_in",
        size_in,
        thickness,
        "must not exceed the ring thickness r_out - r_in",
    )?;
    at_most(
        "size_out",
        size_out,
        thickness,
        "must not exceed the ring thickness r_out - r_in",
    )?;
    let grading = Grading::new(thickness, size_in, size_out);
    check_count::<Dim2>("size_in", size_in, 16.0 * grading.count())?;
    let levels = grading.levels();
    let mut counts: Vec<f64> = (levels.iter())
        .map(|&t| {
            (TAU * lerp(r_in, r_out, t) / grading.size(t))
                .round()
                .max(8.0)
        })
        .collect();
    for k in 1..counts.len() {
        counts[k] = limit_growth(counts[k - 1], counts[k]);
    }
    check_count::<Dim2>("size_in", size_in, 2.0 * counts.iter().sum::<f64>())?;
    let mut p = Planar::default();
    let loops: Vec<Loop> = (levels.iter().zip(&counts))
        .map(|(&t, &n)| p.add_loop(circle(center, lerp(r_in, r_out, t), n as usize)))
        .collect();
    p.stitch_all(&loops);
    let boundaries = vec![
        ("inner", loops[0].nodes.clone()),
        ("outer", loops[loops.len() - 1].nodes.clone()),
    ];
    finish(p.xy, p.tris, boundaries)
}

/// Disc `|x - center| <= radius` (m) of uniform element size `size` (m): a centre node with
/// a fan of six triangles, then `ceil(radius/size)` equally spaced circles, circle `k`
/// with about `2π k` nodes, stitched together.
///
/// Requires `size <= radius`.
///
/// Groups (nodes and boundary faces): `"boundary"`; elements: `"all"`.
pub fn disc(center: [f64; 2], radius: f64, size: f64) -> Result<Mesh<Dim2>, MeshError> {
    finite("center[0]", center[0])?;
    finite("center[1]", center[1])?;
    positive("radius", radius)?;
    positive("size", size)?;
    at_most("size", size, radius, "must not exceed radius")?;
    let (p, rim) = disc_planar(center, radius, size)?;
    finish(p.xy, p.tris, vec![("boundary", rim)])
}

/// Plate `[-half_width, half_width] x [-half_height, half_height]` (m) with a centred
/// circular hole of radius `radius` (m), graded from `size_hole` at the hole to
/// `size_outer` at the outer edge (m).
///
/// Around the hole, a square core of half-side `a = min(half_width, half_height)` is meshed
/// by node loops that morph the hole into the square as `t` goes from 0 to 1 (geometric
/// steps): in polar form `r(φ, t) = (1 - t) radius + t r_square(φ)`, so the loops are
/// star-shaped and nested. Each loop has four sectors ending on the diagonals (so the
/// square's corners are nodes); within a sector the nodes go from equal angles on the hole
/// to equal spacing on the square. Consecutive loops are stitched. The rest of a
/// non-square plate is two structured wings continuing the core's edge nodes (a wing
/// shorter than a quarter of the edge spacing is absorbed by stretching the core).
///
/// Requires `radius < a`, `size_hole <= radius`, `size_hole <= a - radius` (the ligament)
/// and `size_outer <= a`.
///
/// Groups (nodes and boundary faces): `"hole"`, `"left"`, `"right"`, `"bottom"`, `"top"`;
/// elements: `"all"`.
pub fn plate_with_hole(
    half_width: f64,
    half_height: f64,
    radius: f64,
    size_hole: f64,
    size_outer: f64,
) -> Result<Mesh<Dim2>, MeshError> {
    let hw = positive("half_width", half_width)?;
    let hh = positive("half_height", half_height)?;
    positive("radius", radius)?;
    positive("size_hole", size_hole)?;
    positive("size_outer", size_outer)?;
    let a = hw.min(hh);
    if radius >= a {
        return Err(invalid(
            "radius",
            radius,
            "must be smaller than half_width and half_height",
        ));
    }
    at_most("size_hole", size_hole, radius, "must not exceed radius")?;
    at_most(
        "size_hole",
        size_hole,
        a - radius,
        "must not exceed the ligament min(half_width, half_height) - radius",
    )?;
    at_most(
        "size_outer",
        size_outer,
        a,
        "must not exceed half_width and half_height",
    )?;

    // Radial spacing follows the geometric mean of the shortest and longest hole-to-edge
    // distances of the square core, balancing the stretch between its sides and corners.
    let len = ((a - radius) * (a * 2f64.sqrt() - radius)).sqrt();
    let grading = Grading::new(len, size_hole, size_outer);
    check_count::<Dim2>("size_hole", size_hole, 16.0 * grading.count())?;
    let levels = grading.levels();
    let mut counts: Vec<f64> = (levels.iter())
        .map(|&t| {
            (lerp(radius * PI / 2.0, 2.0 * a, t) / grading.size(t))
                .round()
                .max(2.0)
        })
        .collect();
    for k in 1..counts.len() {
        counts[k] = limit_growth(counts[k - 1], counts[k]);
    }
    // Wing columns; a wing shorter than a quarter of the edge spacing is absorbed by the core.
    let (n_side, wing) = (counts[counts.len() - 1], hw.max(hh) - a);
    let wing_cols = if wing < 0.5 * a / n_side {
        0.0
    } else {
        (wing * n_side / (2.0 * a)).ceil()
    };
    let estimate = 8.0 * counts.iter().sum::<f64>() + 4.0 * wing_cols * n_side;
    check_count::<Dim2>("size_outer", size_outer, estimate)?;

    // Core [-ex, ex] x [-ey, ey]: sector q runs from corner q to corner q+1 (right, top,
    // left, bottom side) and from angle hole[q] to hole[q+1] on the hole.
    let (ex, ey) = if wing_cols == 0.0 { (hw, hh) } else { (a, a) };
    let corners = [[ex, -ey], [ex, ey], [-ex, ey], [-ex, -ey], [ex, -ey]];
    let beta = ey.atan2(ex);
    let corner_angles = [-beta, beta, PI - beta, PI + beta];
    let hole = [-PI / 4.0, PI / 4.0, 0.75 * PI, 1.25 * PI, 1.75 * PI];
    let mut p = Planar::default();
    let loops: Vec<Loop> = (levels.iter().zip(&counts))
        .map(|(&t, &n)| {
            let n = n as usize;
            let mut pts = Vec::with_capacity(4 * n);
            for q in 0..4 {
                let (c, d) = (corners[q], corners[q + 1]);
                for m in 0..n {
                    let u = m as f64 / n as f64;
                    let edge = [lerp(c[0], d[0], u), lerp(c[1], d[1], u)];
                    // Polar angle: equally spaced on the hole, moving to the edge node's angle.
                    let to_edge =
                        (c[0] * edge[1] - c[1] * edge[0]).atan2(c[0] * edge[0] + c[1] * edge[1]);
                    let phi = lerp(lerp(hole[q], hole[q + 1], u), corner_angles[q] + to_edge, t);
                    let (cos, sin) = (phi.cos(), phi.sin());
                    let r = lerp(radius, (ex / cos.abs()).min(ey / sin.abs()), t);
                    let xy = if t < 1.0 { [r * cos, r * sin] } else { edge };
                    pts.push((xy, (phi - hole[0]) / TAU));
                }
            }
            p.add_loop(pts)
        })
        .collect();
    p.stitch_all(&loops);

    // Outer loop sides: right and left bottom-to-top, top and bottom left-to-right.
    let (outer, n) = (&loops[loops.len() - 1].nodes, n_side as usize);
    let side = |q: usize, reverse: bool| -> Vec<u32> {
        let mut v: Vec<u32> = (q * n..=(q + 1) * n)
            .map(|k| outer[k % outer.len()])
            .collect();
        if reverse {
            v.reverse();
        }
        v
    };
    let [mut right, mut top, mut left, mut bottom] =
        [side(0, false), side(1, true), side(2, true), side(3, false)];
    if wing_cols > 0.0 {
        // Wings along x for a wide plate, along y for a tall one.
        let cols = wing_cols as usize;
        let wide = hw > hh;
        let offset = if wide { [wing, 0.0] } else { [0.0, wing] };
        let (plus, minus, lo, hi) = if wide {
            (&mut right, &mut left, &mut bottom, &mut top)
        } else {
            (&mut top, &mut bottom, &mut left, &mut right)
        };
        for (sign, far) in [(1.0, plus), (-1.0, minus)] {
            let grid = p.extrude(far, offset.map(|v| sign * v), cols);
            lo.extend(grid.iter().map(|col| col[0]));
            hi.extend(grid.iter().map(|col| col[col.len() - 1]));
            *far = grid[cols].clone();
        }
    }
    let boundaries = vec![
        ("hole", loops[0].nodes.clone()),
        ("left", left),
        ("right", right),
        ("bottom", bottom),
        ("top", top),
    ];
    finish(p.xy, p.tris, boundaries)
}

/// Dog-bone (direct tension) specimen centred at the origin (m): `x` in
/// `[-width/2, width/2]`, `y` in `[-height/2, height/2]`, each long side cut by a circular
/// arc of radius `neck_radius` centred at `(±(neck_width/2 + neck_radius), 0)`, so the
/// width is `neck_width` at `y = 0` and grows to `width` where the arcs meet the straight
/// grips.
///
/// A structured grid follows the varying width: `max(2, ceil(neck_width/size))` columns (so
/// the neck has elements of about `size`, the grips wider ones) and rows of at most `size`,
/// with row boundaries where the arcs meet the grips. Quality is good for usual specimens
/// (`neck_width` over half of `width`, `neck_radius` above `width - neck_width`); the cells
/// get skewed as the shoulders approach a step.
///
/// Requires `neck_width < width`, `neck_radius > (width - neck_width)/2` (the arcs reach the
/// full width), the arcs to end within the height, and `size <= neck_width`.
///
/// Groups (nodes and boundary faces): `"top"`, `"bottom"`, `"sides"`; elements: `"all"`
/// and `"neck"` (elements whose centroid has `|y| <= neck_width/2`).
pub fn dog_bone(
    width: f64,
    height: f64,
    neck_radius: f64,
    neck_width: f64,
    size: f64,
) -> Result<Mesh<Dim2>, MeshError> {
    positive("width", width)?;
    positive("height", height)?;
    positive("neck_radius", neck_radius)?;
    positive("neck_width", neck_width)?;
    positive("size", size)?;
    if neck_width >= width {
        return Err(invalid(
            "neck_width",
            neck_width,
            "must be smaller than width",
        ));
    }
    let centre = neck_width / 2.0 + neck_radius;
    let d = centre - width / 2.0;
    if d <= 0.0 {
        return Err(invalid(
            "neck_radius",
            neck_radius,
            "must exceed (width - neck_width)/2 for the arcs to reach the full width",
        ));
    }
    let y_meet = (neck_radius * neck_radius - d * d).sqrt();
    if y_meet >= height / 2.0 {
        return Err(invalid(
            "height",
            height,
            "too short: the neck arcs must meet the full width within the height",
        ));
    }
    at_most("size", size, neck_width, "must not exceed neck_width")?;
    let nx = (neck_width / size).ceil().max(2.0);
    // Rows break where the arcs meet the grips, unless the grips are shorter than half a row.
    let y_break = if height / 2.0 - y_meet < 0.5 * size {
        height / 2.0
    } else {
        y_meet
    };
    let segments = [
        (-height / 2.0, -y_break),
        (-y_break, y_break),
        (y_break, height / 2.0),
    ];
    let rows = segments.map(|(a, b)| ((b - a) / size).ceil());
    check_count::<Dim2>("size", size, 2.0 * nx * rows.iter().sum::<f64>())?;

    let nx = nx as usize;
    let mut ys = vec![-height / 2.0];
    for ((a, b), n) in segments.into_iter().zip(rows) {
        ys.extend((1..=n as usize).map(|k| lerp(a, b, k as f64 / n)));
    }
    let ny = ys.len() - 1;
    let half = |y: f64| {
        if y.abs() < y_meet {
            centre - (neck_radius * neck_radius - y * y).sqrt()
        } else {
            width / 2.0
        }
    };
    let p = Planar::grid(nx, ny, |i, j| {
        let h = half(ys[j]);
        [lerp(-h, h, i as f64 / nx as f64), ys[j]]
    });
    let idx = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let boundaries = vec![
        ("top", (0..=nx).map(|i| idx(i, ny)).collect()),
        ("bottom", (0..=nx).map(|i| idx(i, 0)).collect()),
        (
            "sides",
            (0..=ny).flat_map(|j| [idx(0, j), idx(nx, j)]).collect(),
        ),
    ];
    let mut mesh: Mesh<Dim2> = finish(p.xy, p.tris, boundaries)?;
    let mut c = [0.0; 2];
    let neck = (0..mesh.n_elements() as u32)
        .filter(|&e| {
            mesh.element_centroid(e as usize, &mut c);
            c[1].abs() <= neck_width / 2.0
        })
        .collect();
    mesh.add_element_group("neck", neck)?;
    Ok(mesh)
}

// ---------------------------------------------------------------------------------------
// 3D builders
// ---------------------------------------------------------------------------------------

/// Cuboid `origin + [0, size_xyz[0]] x [0, size_xyz[1]] x [0, size_xyz[2]]` (m):
/// `ceil(size_xyz[k]/size)` cells along each axis, each split into the six tetrahedra of
/// the Kuhn (Freudenthal) subdivision, which is conforming between neighbouring cells.
///
/// `size` (m) must not exceed the largest side.
///
/// Groups (nodes and boundary faces): `"xmin"`, `"xmax"`, `"ymin"`, `"ymax"`, `"zmin"`,
/// `"zmax"`; elements: `"all"`.
pub fn cuboid(origin: [f64; 3], size_xyz: [f64; 3], size: f64) -> Result<Mesh<Dim3>, MeshError> {
    let grid = CuboidGrid::new(origin, size_xyz, size, 6.0)?;
    let (n, idx) = (grid.n, |i, j, k| grid.idx(i, j, k));
    // Kuhn tetrahedra: paths 000 -> e_p0 -> e_p0 + e_p1 -> 111 for each permutation p of the
    // axes; the signed volume has the sign of the permutation, so odd ones swap two nodes.
    const PERMS: [([usize; 3], bool); 6] = [
        ([0, 1, 2], true),
        ([1, 2, 0], true),
        ([2, 0, 1], true),
        ([0, 2, 1], false),
        ([2, 1, 0], false),
        ([1, 0, 2], false),
    ];
    let mut tets = Vec::with_capacity(6 * 4 * n[0] * n[1] * n[2]);
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                for (perm, even) in PERMS {
                    let mut v = [i, j, k];
                    let mut path = [idx(i, j, k); 4];
                    for s in 0..3 {
                        v[perm[s]] += 1;
                        path[s + 1] = idx(v[0], v[1], v[2]);
                    }
                    if !even {
                        path.swap(0, 1);
                    }
                    tets.extend(path);
                }
            }
        }
    }
    let boundaries = grid.boundaries();
    finish(grid.coords, tets, boundaries)
}

/// The checked parameters, node grid and boundary groups of a [`cuboid`] or
/// [`cuboid_hexes`]: `n[k]` cells along axis k, nodes numbered x fastest.
struct CuboidGrid {
    n: [usize; 3],
    coords: Vec<f64>,
}

impl CuboidGrid {
    /// Checks the parameters (with `per_cell` elements per cell for the size guard) and
    /// lays out the nodes.
    fn new(
        origin: [f64; 3],
        size_xyz: [f64; 3],
        size: f64,
        per_cell: f64,
    ) -> Result<Self, MeshError> {
        for (k, name) in ["origin[0]", "origin[1]", "origin[2]"]
            .into_iter()
            .enumerate()
        {
            finite(name, origin[k])?;
        }
        for (k, name) in ["size_xyz[0]", "size_xyz[1]", "size_xyz[2]"]
            .into_iter()
            .enumerate()
        {
            positive(name, size_xyz[k])?;
        }
        positive("size", size)?;
        let largest = size_xyz.iter().copied().fold(0.0, f64::max);
        at_most("size", size, largest, "must not exceed the largest side")?;
        let nf = size_xyz.map(|l| (l / size).ceil());
        check_count::<Dim3>("size", size, per_cell * nf[0] * nf[1] * nf[2])?;
        let n = nf.map(|v| v as usize);
        let mut coords = Vec::with_capacity(3 * (n[0] + 1) * (n[1] + 1) * (n[2] + 1));
        for k in 0..=n[2] {
            for j in 0..=n[1] {
                for i in 0..=n[0] {
                    let f = [i, j, k];
                    coords.extend(
                        (0..3).map(|a| origin[a] + size_xyz[a] * (f[a] as f64 / n[a] as f64)),
                    );
                }
            }
        }
        Ok(CuboidGrid { n, coords })
    }

    /// Index of grid node (i, j, k).
    fn idx(&self, i: usize, j: usize, k: usize) -> u32 {
        ((k * (self.n[1] + 1) + j) * (self.n[0] + 1) + i) as u32
    }

    /// The node groups of the six faces.
    fn boundaries(&self) -> Vec<Boundary> {
        let n = self.n;
        let face = |axis: usize, at: usize| {
            let mut nodes = Vec::new();
            for k in 0..=n[2] {
                for j in 0..=n[1] {
                    for i in 0..=n[0] {
                        if [i, j, k][axis] == at {
                            nodes.push(self.idx(i, j, k));
                        }
                    }
                }
            }
            nodes
        };
        vec![
            ("xmin", face(0, 0)),
            ("xmax", face(0, n[0])),
            ("ymin", face(1, 0)),
            ("ymax", face(1, n[1])),
            ("zmin", face(2, 0)),
            ("zmax", face(2, n[2])),
        ]
    }
}

/// Cylinder of radius `radius` (m) around the z axis, from `z = 0` to `z = height` (m): the
/// [`disc`] triangulation of size `size` (m) extruded in `ceil(height/size)` layers, each
/// prism split into three tetrahedra. Every quadrilateral side face of a prism is cut on
/// the diagonal from its lowest global node index, which makes neighbouring prisms conform.
///
/// Requires `size <= radius`.
///
/// Groups (nodes and boundary faces): `"bottom"`, `"top"`, `"side"`; elements: `"all"`.
pub fn cylinder(radius: f64, height: f64, size: f64) -> Result<Mesh<Dim3>, MeshError> {
    positive("radius", radius)?;
    positive("height", height)?;
    positive("size", size)?;
    at_most("size", size, radius, "must not exceed radius")?;
    let (disc, rim) = disc_planar([0.0, 0.0], radius, size)?;
    let nzf = (height / size).ceil();
    check_count::<Dim3>("size", size, 3.0 * nzf * (disc.tris.len() / 3) as f64)?;
    let (nz, n2) = (nzf as usize, disc.xy.len() / 2);
    let (coords, tets) = extrude(&disc.xy, &disc.tris, height, nz);
    let layer = |k: usize| ((k * n2) as u32..((k + 1) * n2) as u32).collect();
    let side = (0..=nz)
        .flat_map(|k| rim.iter().map(move |&v| (k * n2) as u32 + v))
        .collect();
    finish(
        coords,
        tets,
        vec![("bottom", layer(0)), ("top", layer(nz)), ("side", side)],
    )
}

/// Extrudes a counter-clockwise planar triangulation (`xy` stride 2, `tris` stride 3) from
/// z = 0 to `height` in `nz` layers, each prism split into three tetrahedra; every side
/// quadrilateral is cut on the diagonal from its lowest global node index, so
/// neighbouring prisms conform. Nodes of layer k are `k * n2 .. (k + 1) * n2`.
fn extrude(xy: &[f64], tris: &[u32], height: f64, nz: usize) -> (Vec<f64>, Vec<u32>) {
    let n2 = xy.len() / 2;
    let mut coords = Vec::with_capacity(3 * n2 * (nz + 1));
    for k in 0..=nz {
        let z = height * (k as f64 / nz as f64);
        for p in xy.chunks_exact(2) {
            coords.extend([p[0], p[1], z]);
        }
    }
    let mut tets = Vec::with_capacity(12 * nz * tris.len() / 3);
    for tri in tris.chunks_exact(3) {
        // Sort the counter-clockwise triangle by node index: v0 < v1 < v2. The sorted order is
        // still counter-clockwise iff it is a rotation of (a, b, c).
        let r = (0..3).min_by_key(|&k| tri[k]).unwrap_or(0);
        let (v0, x, y) = (tri[r], tri[(r + 1) % 3], tri[(r + 2) % 3]);
        let ccw = x < y;
        let (v1, v2) = if ccw { (x, y) } else { (y, x) };
        for k in 0..nz {
            let (lo, hi) = ((k * n2) as u32, ((k + 1) * n2) as u32);
            let (b0, b1, b2, t0, t1, t2) = (lo + v0, lo + v1, lo + v2, hi + v0, hi + v1, hi + v2);
            // Side quads are cut from their lowest node (a bottom one): b0-t1, b1-t2, b0-t2.
            for mut t in [[b0, b1, b2, t2], [b0, b1, t2, t1], [b0, t0, t1, t2]] {
                if !ccw {
                    t.swap(0, 1);
                }
                tets.extend(t);
            }
        }
    }
    (coords, tets)
}

/// Thick-walled (hollow) cylinder `r_in <= sqrt(x² + y²) <= r_out` around the z axis,
/// from z = 0 to `height` (m): the graded [`ring`] triangulation (size `size_in` at
/// `r_in` to `size_out` at `r_out`, m) extruded in `ceil(height/size_out)` layers of
/// tetrahedra, as [`cylinder`] extrudes its disc.
///
/// Requires what [`ring`] requires, and `size_out <= height`.
///
/// Groups (nodes and boundary faces): `"inner"`, `"outer"`, `"bottom"`, `"top"`;
/// elements: `"all"`.
pub fn hollow_cylinder(
    r_in: f64,
    r_out: f64,
    height: f64,
    size_in: f64,
    size_out: f64,
) -> Result<Mesh<Dim3>, MeshError> {
    positive("height", height)?;
    let flat = ring([0.0, 0.0], r_in, r_out, size_in, size_out)?;
    at_most("size_out", size_out, height, "must not exceed height")?;
    let nzf = (height / size_out).ceil();
    check_count::<Dim3>("size_out", size_out, 3.0 * nzf * flat.n_elements() as f64)?;
    let (nz, n2) = (nzf as usize, flat.n_nodes());
    let (coords, tets) = extrude(flat.coords(), flat.elements(), height, nz);
    let layer = |k: usize| ((k * n2) as u32..((k + 1) * n2) as u32).collect();
    let rim = |name: &str| -> Vec<u32> {
        let g = &flat.groups().nodes[name];
        (0..=nz)
            .flat_map(|k| g.iter().map(move |&v| (k * n2) as u32 + v))
            .collect()
    };
    finish(
        coords,
        tets,
        vec![
            ("inner", rim("inner")),
            ("outer", rim("outer")),
            ("bottom", layer(0)),
            ("top", layer(nz)),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hollow_cylinder_volume_and_groups() {
        let m = hollow_cylinder(0.1, 1.0, 0.2, 0.02, 0.2).unwrap();
        let v: f64 = (0..m.n_elements()).map(|e| m.element_measure(e)).sum();
        // Polygonal circles lose a little area: within 1 % of π (r_o² − r_i²) h.
        let exact = std::f64::consts::PI * (1.0 - 0.01) * 0.2;
        assert!(rel(v, exact) < 0.01, "{v} vs {exact}");
        let r = |x: &[f64]| (x[0] * x[0] + x[1] * x[1]).sqrt();
        check_groups(
            &m,
            &[
                ("inner", &|x: &[f64]| r(x) - 0.1),
                ("outer", &|x: &[f64]| r(x) - 1.0),
                ("bottom", &|x: &[f64]| x[2]),
                ("top", &|x: &[f64]| x[2] - 0.2),
            ],
        );
        assert!(hollow_cylinder(0.1, 1.0, 0.1, 0.02, 0.2).is_err());
    }

    fn measure<D: Dim>(m: &Mesh<D>) -> f64 {
        (0..m.n_elements()).map(|e| m.element_measure(e)).sum()
    }

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    type DistFn<'a> = &'a dyn Fn(&[f64]) -> f64;

    /// Each named group is non-empty, its nodes lie on its boundary (`dist` ~ 0) and are
    /// exactly the nodes of its faces; the face groups are disjoint and their union is the
    /// mesh boundary; "all" holds every element.
    fn check_groups<D: Dim>(m: &Mesh<D>, expected: &[(&str, DistFn)]) {
        let g = m.groups();
        assert_eq!(g.elements["all"].len(), m.n_elements());
        let mut union = Vec::new();
        for (name, dist) in expected {
            let (nodes, faces) = (&g.nodes[*name], &g.faces[*name]);
            assert!(
                !nodes.is_empty() && !faces.is_empty(),
                "group {name} is empty"
            );
            for &n in nodes {
                let d = dist(m.node(n as usize));
                assert!(
                    d.abs() < 1e-9,
                    "node {n} of {name} at {:?} is {d} off",
                    m.node(n as usize)
                );
            }
            assert_eq!(
                &m.nodes_of_faces(faces),
                nodes,
                "{name}: face nodes != node group"
            );
            union.extend_from_slice(faces);
        }
        let total = union.len();
        union.sort_unstable();
        union.dedup();
        assert_eq!(union.len(), total, "face groups overlap");
        assert_eq!(
            union,
            m.faces().boundary,
            "face groups do not cover the boundary exactly"
        );
    }

    /// Smallest interior angle (degrees) of a 2D mesh.
    fn min_angle_deg(m: &Mesh<Dim2>) -> f64 {
        (0..m.n_elements())
            .map(|e| {
                let t = m.element(e);
                let p = [0, 1, 2].map(|k| [m.node(t[k] as usize)[0], m.node(t[k] as usize)[1]]);
                min_angle(p).expect("inverted triangle").to_degrees()
            })
            .fold(180.0, f64::min)
    }

    /// Smallest normalised radius ratio `3 r_in / r_circ` (1 for a regular tetrahedron).
    fn min_radius_ratio(m: &Mesh<Dim3>) -> f64 {
        let sub = |a: &[f64], b: &[f64]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let norm = |a: [f64; 3]| dot(a, a).sqrt();
        (0..m.n_elements())
            .map(|e| {
                let p: Vec<&[f64]> = m.element(e).iter().map(|&n| m.node(n as usize)).collect();
                let (a, b, c) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
                let vol6 = dot(a, cross(b, c));
                let faces = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
                let area: f64 = faces
                    .iter()
                    .map(|f| 0.5 * norm(cross(sub(p[f[1]], p[f[0]]), sub(p[f[2]], p[f[0]]))))
                    .sum();
                let r_in = 0.5 * vol6 / area;
                let (bc, ca, ab) = (cross(b, c), cross(c, a), cross(a, b));
                let o: [f64; 3] = std::array::from_fn(|k| {
                    dot(a, a) * bc[k] + dot(b, b) * ca[k] + dot(c, c) * ab[k]
                });
                let r_circ = norm(o) / (2.0 * vol6);
                3.0 * r_in / r_circ
            })
            .fold(1.0, f64::min)
    }

    fn boundary_area(m: &Mesh<Dim3>) -> f64 {
        let mut n = [0.0; 3];
        m.faces()
            .boundary
            .iter()
            .map(|&f| m.face_measure_normal(f as usize, &mut n))
            .sum()
    }

    /// Area of the polygon through the nodes of a group (those with `keep`), sorted by angle
    /// around `c`.
    fn polygon_area<D: Dim>(
        m: &Mesh<D>,
        group: &str,
        c: [f64; 2],
        keep: impl Fn(&[f64]) -> bool,
    ) -> f64 {
        let mut pts: Vec<[f64; 2]> = (m.groups().nodes[group].iter().map(|&n| m.node(n as usize)))
            .filter(|p| keep(p))
            .map(|p| [p[0] - c[0], p[1] - c[1]])
            .collect();
        pts.sort_by(|p, q| p[1].atan2(p[0]).total_cmp(&q[1].atan2(q[0])));
        (0..pts.len())
            .map(|k| {
                let (p, q) = (pts[k], pts[(k + 1) % pts.len()]);
                0.5 * (p[0] * q[1] - q[0] * p[1])
            })
            .sum()
    }

    fn is_invalid<D: Dim>(r: Result<Mesh<D>, MeshError>, param: &str) -> bool {
        matches!(r, Err(MeshError::InvalidParameter { name, .. }) if name == param)
    }

    #[test]
    fn builders_rectangle() {
        let (x0, y0, w, h, s) = (1.0, -2.0, 3.0, 2.0, 0.23);
        let m = rectangle(x0, y0, w, h, s).unwrap();
        let (nx, ny) = ((w / s).ceil() as usize, (h / s).ceil() as usize);
        assert_eq!(m.n_elements(), 2 * nx * ny);
        assert_eq!(m.n_nodes(), (nx + 1) * (ny + 1));
        assert!(rel(measure(&m), w * h) < 1e-12);
        assert!(m.edge_length_range().1 <= s * 2f64.sqrt() + 1e-12);
        check_groups(
            &m,
            &[
                ("left", &|p| p[0] - x0),
                ("right", &|p| p[0] - (x0 + w)),
                ("bottom", &|p| p[1] - y0),
                ("top", &|p| p[1] - (y0 + h)),
            ],
        );
        assert!(min_angle_deg(&m) > 30.0);
        assert!(rectangle(x0, y0, w, h, 2.0 * s).unwrap().n_elements() < m.n_elements());
        // A single column still separates the groups.
        let thin = rectangle(0.0, 0.0, 0.1, 1.0, 0.2).unwrap();
        assert_eq!(thin.groups().faces["left"].len(), 5);
        assert_eq!(thin.groups().faces["bottom"].len(), 1);
    }

    #[test]
    fn builders_disc() {
        let (c, r, s) = ([0.5, -1.0], 2.0, 0.1);
        let m = disc(c, r, s).unwrap();
        let a = measure(&m);
        assert!(rel(a, PI * r * r) < 0.01, "area {a}");
        // The triangles tile the boundary polygon exactly (no overlap, no gap).
        assert!(rel(a, polygon_area(&m, "boundary", c, |_| true)) < 1e-10);
        check_groups(
            &m,
            &[("boundary", &|p| (p[0] - c[0]).hypot(p[1] - c[1]) - r)],
        );
        let q = min_angle_deg(&m);
        eprintln!(
            "disc r=2 size=0.1: {} elements, {} nodes, min angle {q:.1} deg",
            m.n_elements(),
            m.n_nodes()
        );
        assert!(q > 15.0);
        assert!(disc(c, r, 0.25).unwrap().n_elements() < m.n_elements());
        // Coarsest disc: a hexagon fan.
        let hex = disc(c, 1.0, 1.0).unwrap();
        assert_eq!(hex.n_elements(), 6);
        assert!(min_angle_deg(&hex) > 59.0);
    }

    #[test]
    fn builders_ring_kirsch() {
        let c = [1.0, 2.0];
        for (r_in, r_out, s_in, s_out) in [
            (1.0, 25.0, 0.1, 2.5),
            (0.5, 3.0, 0.05, 0.4),
            (1.0, 2.0, 0.1, 0.1),
            (1.0, 4.0, 0.5, 0.05),
        ] {
            let m = ring(c, r_in, r_out, s_in, s_out).unwrap();
            let a = measure(&m);
            let exact = PI * (r_out * r_out - r_in * r_in);
            assert!(rel(a, exact) < 0.01, "area {a} vs {exact}");
            let poly =
                polygon_area(&m, "outer", c, |_| true) - polygon_area(&m, "inner", c, |_| true);
            assert!(rel(a, poly) < 1e-10);
            let dist = |r: f64| move |p: &[f64]| (p[0] - c[0]).hypot(p[1] - c[1]) - r;
            check_groups(&m, &[("inner", &dist(r_in)), ("outer", &dist(r_out))]);
            let q = min_angle_deg(&m);
            eprintln!(
                "ring r_in={r_in} r_out={r_out} size_in={s_in} size_out={s_out}: {} elements, {} nodes, \
                 {} inner / {} outer boundary nodes, edges {:.3?}, min angle {q:.1} deg",
                m.n_elements(),
                m.n_nodes(),
                m.groups().nodes["inner"].len(),
                m.groups().nodes["outer"].len(),
                m.edge_length_range()
            );
            assert!(q > 15.0);
            let coarse = ring(c, r_in, r_out, 2.0 * s_in, 2.0 * s_out).unwrap();
            assert!(coarse.n_elements() < m.n_elements());
        }
        let kirsch = ring([0.0, 0.0], 1.0, 25.0, 0.1, 2.5).unwrap();
        assert!(
            (1000..10_000).contains(&kirsch.n_elements()),
            "{}",
            kirsch.n_elements()
        );
    }

    #[test]
    fn builders_plate_with_hole() {
        let cases = [
            (5.0, 5.0, 1.0, 0.1, 0.5),
            (0.1, 0.1, 0.01, 0.001, 0.01),
            (6.0, 4.0, 1.0, 0.1, 0.6),
            (1.0, 3.0, 0.3, 0.02, 0.2),
        ];
        for (hw, hh, r, s_hole, s_out) in cases {
            let m = plate_with_hole(hw, hh, r, s_hole, s_out).unwrap();
            let a = measure(&m);
            let exact = 4.0 * hw * hh - PI * r * r;
            assert!(rel(a, exact) < 0.01, "area {a} vs {exact}");
            assert!(
                rel(
                    a,
                    4.0 * hw * hh - polygon_area(&m, "hole", [0.0, 0.0], |_| true)
                ) < 1e-10
            );
            check_groups(
                &m,
                &[
                    ("hole", &|p| p[0].hypot(p[1]) - r),
                    ("left", &|p| p[0] + hw),
                    ("right", &|p| p[0] - hw),
                    ("bottom", &|p| p[1] + hh),
                    ("top", &|p| p[1] - hh),
                ],
            );
            let q = min_angle_deg(&m);
            eprintln!(
                "plate {hw}x{hh} hole {r} sizes {s_hole}/{s_out}: {} elements, {} nodes, min angle {q:.1} deg",
                m.n_elements(),
                m.n_nodes()
            );
            assert!(q > 15.0);
            assert!(
                plate_with_hole(hw, hh, r, 2.0 * s_hole, 2.0 * s_out)
                    .unwrap()
                    .n_elements()
                    < m.n_elements()
            );
        }
    }

    #[test]
    fn builders_dog_bone() {
        let (w, h, rho, wn, s) = (0.05, 0.15, 0.05, 0.025, 0.002);
        let m = dog_bone(w, h, rho, wn, s).unwrap();
        let c = wn / 2.0 + rho;
        let y_m = (rho * rho - (c - w / 2.0).powi(2)).sqrt();
        let half = |y: f64| {
            if y.abs() < y_m {
                c - (rho * rho - y * y).sqrt()
            } else {
                w / 2.0
            }
        };
        // Exact area: rectangle minus four arc cut-outs.
        let int_sqrt =
            0.5 * (y_m * (rho * rho - y_m * y_m).sqrt() + rho * rho * (y_m / rho).asin());
        let exact = w * h - 4.0 * ((w / 2.0 - c) * y_m + int_sqrt);
        let a = measure(&m);
        assert!(rel(a, exact) < 0.01, "area {a} vs {exact}");
        assert!(
            a > exact,
            "the chords of the concave sides lie outside the material"
        );
        check_groups(
            &m,
            &[
                ("top", &|p| p[1] - h / 2.0),
                ("bottom", &|p| p[1] + h / 2.0),
                ("sides", &|p| p[0].abs() - half(p[1])),
            ],
        );
        let neck = &m.groups().elements["neck"];
        assert!(!neck.is_empty() && neck.len() < m.n_elements());
        let mut cen = [0.0; 2];
        let neck_area: f64 = neck.iter().map(|&e| m.element_measure(e as usize)).sum();
        for e in 0..m.n_elements() {
            m.element_centroid(e, &mut cen);
            assert_eq!(
                neck.binary_search(&(e as u32)).is_ok(),
                cen[1].abs() <= wn / 2.0
            );
        }
        let q = min_angle_deg(&m);
        eprintln!(
            "dog bone: {} elements ({} in the neck, area {neck_area:.3e}), min angle {q:.1} deg",
            m.n_elements(),
            neck.len()
        );
        assert!(q > 15.0);
        assert!(dog_bone(w, h, rho, wn, 2.0 * s).unwrap().n_elements() < m.n_elements());
    }

    #[test]
    fn builders_cuboid() {
        let (o, l, s) = ([1.0, 2.0, -3.0], [1.0, 0.5, 0.75], 0.1);
        let m = cuboid(o, l, s).unwrap();
        let n = l.map(|v| (v / s).ceil() as usize);
        assert_eq!(m.n_elements(), 6 * n[0] * n[1] * n[2]);
        assert!(rel(measure(&m), l[0] * l[1] * l[2]) < 1e-12);
        // Conformity: the boundary faces have exactly the surface area (no interior holes).
        let surface = 2.0 * (l[0] * l[1] + l[1] * l[2] + l[2] * l[0]);
        assert!(rel(boundary_area(&m), surface) < 1e-12);
        assert_eq!(
            m.faces().boundary.len(),
            4 * (n[0] * n[1] + n[1] * n[2] + n[2] * n[0])
        );
        check_groups(
            &m,
            &[
                ("xmin", &|p| p[0] - o[0]),
                ("xmax", &|p| p[0] - (o[0] + l[0])),
                ("ymin", &|p| p[1] - o[1]),
                ("ymax", &|p| p[1] - (o[1] + l[1])),
                ("zmin", &|p| p[2] - o[2]),
                ("zmax", &|p| p[2] - (o[2] + l[2])),
            ],
        );
        let q = min_radius_ratio(&m);
        eprintln!(
            "cuboid: {} elements, min radius ratio {q:.3}",
            m.n_elements()
        );
        assert!(q > 0.5);
        assert!(cuboid(o, l, 2.0 * s).unwrap().n_elements() < m.n_elements());
    }

    #[test]
    fn builders_cylinder() {
        let (r, h, s) = (0.5, 1.2, 0.1);
        let m = cylinder(r, h, s).unwrap();
        let base = polygon_area(&m, "side", [0.0, 0.0], |p| p[2] == 0.0);
        let v = measure(&m);
        assert!(rel(v, PI * r * r * h) < 0.01, "volume {v}");
        assert!(rel(v, base * h) < 1e-10);
        // Conformity: boundary area = two polygon caps + polygon perimeter x height.
        let rim = m.groups().nodes["side"].len() / ((h / s).ceil() as usize + 1);
        let perimeter = rim as f64 * 2.0 * r * (PI / rim as f64).sin();
        assert!(rel(boundary_area(&m), 2.0 * base + perimeter * h) < 1e-10);
        check_groups(
            &m,
            &[
                ("bottom", &|p| p[2]),
                ("top", &|p| p[2] - h),
                ("side", &|p| p[0].hypot(p[1]) - r),
            ],
        );
        let q = min_radius_ratio(&m);
        eprintln!(
            "cylinder r=0.5 h=1.2 size=0.1: {} elements, {} nodes, min radius ratio {q:.3}",
            m.n_elements(),
            m.n_nodes()
        );
        assert!(q > 0.4);
        assert!(cylinder(r, h, 2.0 * s).unwrap().n_elements() < m.n_elements());
    }

    #[test]
    fn builders_invalid_parameters() {
        let nan = f64::NAN;
        assert!(is_invalid(rectangle(0.0, 0.0, 1.0, 1.0, 0.0), "size"));
        assert!(is_invalid(rectangle(0.0, 0.0, -1.0, 1.0, 0.1), "width"));
        assert!(is_invalid(rectangle(nan, 0.0, 1.0, 1.0, 0.1), "x0"));
        assert!(is_invalid(
            rectangle(0.0, 0.0, 1.0, f64::INFINITY, 0.1),
            "height"
        ));
        assert!(is_invalid(rectangle(0.0, 0.0, 1.0, 1.0, 2.0), "size"));
        assert!(is_invalid(rectangle(0.0, 0.0, 1.0, 1.0, 1e-9), "size"));
        assert!(is_invalid(ring([0.0, 0.0], 2.0, 1.0, 0.1, 0.1), "r_in"));
        assert!(is_invalid(ring([0.0, 0.0], 1.0, 1.0, 0.1, 0.1), "r_in"));
        assert!(is_invalid(
            ring([0.0, nan], 1.0, 2.0, 0.1, 0.1),
            "center[1]"
        ));
        assert!(is_invalid(ring([0.0, 0.0], 1.0, 2.0, nan, 0.1), "size_in"));
        assert!(is_invalid(ring([0.0, 0.0], 1.0, 2.0, 0.1, 3.0), "size_out"));
        assert!(is_invalid(
            ring([0.0, 0.0], 1.0, 2.0, 1e-12, 0.1),
            "size_in"
        ));
        assert!(is_invalid(disc([0.0, 0.0], 1.0, 1.5), "size"));
        assert!(is_invalid(disc([0.0, 0.0], -1.0, 0.5), "radius"));
        assert!(is_invalid(disc([0.0, 0.0], 1.0, 1e-6), "size"));
        assert!(is_invalid(
            plate_with_hole(1.0, 1.0, 1.0, 0.1, 0.2),
            "radius"
        ));
        assert!(is_invalid(
            plate_with_hole(1.0, 0.5, 0.6, 0.1, 0.2),
            "radius"
        ));
        assert!(is_invalid(
            plate_with_hole(1.0, 1.0, 0.5, 0.6, 0.2),
            "size_hole"
        ));
        assert!(is_invalid(
            plate_with_hole(1.0, 1.0, 0.5, 0.1, 2.0),
            "size_outer"
        ));
        assert!(is_invalid(
            plate_with_hole(1.0, 0.0, 0.5, 0.1, 0.2),
            "half_height"
        ));
        assert!(is_invalid(dog_bone(1.0, 3.0, 1.0, 1.0, 0.1), "neck_width"));
        assert!(is_invalid(dog_bone(1.0, 3.0, 0.2, 0.5, 0.1), "neck_radius"));
        assert!(is_invalid(dog_bone(1.0, 1.0, 1.0, 0.5, 0.1), "height"));
        assert!(is_invalid(dog_bone(1.0, 3.0, 1.0, 0.5, 0.6), "size"));
        assert!(is_invalid(
            dog_bone(1.0, 3.0, 1.0, 0.5, f64::NEG_INFINITY),
            "size"
        ));
        assert!(is_invalid(
            cuboid([0.0; 3], [1.0, 0.0, 1.0], 0.1),
            "size_xyz[1]"
        ));
        assert!(is_invalid(
            cuboid([0.0, 0.0, nan], [1.0; 3], 0.1),
            "origin[2]"
        ));
        assert!(is_invalid(cuboid([0.0; 3], [1.0; 3], 1.5), "size"));
        assert!(is_invalid(cuboid([0.0; 3], [1.0; 3], 1e-4), "size"));
        assert!(is_invalid(cylinder(1.0, 1.0, 2.0), "size"));
        assert!(is_invalid(cylinder(1.0, -1.0, 0.1), "height"));
        assert!(is_invalid(cylinder(1.0, 1e9, 0.01), "size"));
        let msg = ring([0.0, 0.0], 2.0, 1.0, 0.1, 0.1)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("r_in") && msg.contains("smaller than r_out"),
            "{msg}"
        );
    }

    /// Valid parameters across wide ranges (thin ligaments, elongated plates, steep or
    /// inverted gradings, thin rings, short grips) give a valid mesh or InvalidParameter,
    /// never another error; the quality floor is reported.
    #[test]
    fn builders_parameter_sweep() {
        let ok_or_invalid = |r: Result<Mesh<Dim2>, MeshError>, what: String| match r {
            Ok(m) => min_angle_deg(&m),
            Err(MeshError::InvalidParameter { .. }) => 180.0,
            Err(e) => panic!("{what}: {e}"),
        };
        let f = [0.03, 0.2, 0.5, 1.0];
        let mut worst = [180.0f64; 3];
        for (hw, hh) in [
            (1.0, 1.0),
            (1.0, 1.0 + 1e-12),
            (1.05, 1.0),
            (1.5, 1.0),
            (1.0, 5.0),
            (10.0, 1.0),
        ] {
            for rf in [0.05, 0.5, 0.95] {
                let r = rf * f64::min(hw, hh);
                for (a, b) in f.iter().flat_map(|&a| f.map(|b| (a, b))) {
                    let m = plate_with_hole(hw, hh, r, a * r, b * hw.min(hh));
                    worst[0] =
                        worst[0].min(ok_or_invalid(m, format!("plate {hw} {hh} {r} {a} {b}")));
                }
            }
        }
        for r_out in [1.001, 1.1, 3.0, 100.0] {
            for (a, b) in f.iter().flat_map(|&a| f.map(|b| (a, b))) {
                let m = ring([0.3, -0.2], 1.0, r_out, a, b * r_out);
                worst[1] = worst[1].min(ok_or_invalid(m, format!("ring {r_out} {a} {b}")));
            }
        }
        for (wn, rho, grip) in [
            (0.5f64, 0.5f64, 0.001),
            (0.5, 1.0, 0.5),
            (0.7, 3.0, 0.2),
            (0.7, 0.3, 1.0),
        ] {
            let d = wn / 2.0 + rho - 0.5;
            let height = 2.0 * ((rho * rho - d * d).sqrt() + grip);
            for s in [0.05, 0.2, wn] {
                let m = dog_bone(1.0, height, rho, wn, s);
                worst[2] =
                    worst[2].min(ok_or_invalid(m, format!("dog bone {wn} {rho} {grip} {s}")));
            }
        }
        eprintln!(
            "sweep: min angles plate {:.1}, ring {:.1}, dog bone {:.1} deg",
            worst[0], worst[1], worst[2]
        );
        assert!(worst.iter().all(|&q| q > 10.0));
    }
}

/// Joins separate bodies into one mesh (nodes and elements concatenated in order, node
/// indices offset), e.g. a block resting on a base for contact. Bodies keep their own
/// nodes, so they interact only through contact. Returns the mesh and, per body, its
/// node indices in the joined mesh; groups of the inputs are not carried over. A body
/// that was split already ([`crate::split_nodes`]) is refused ([`MeshError::AlreadySplit`]):
/// join first, then split, so that the union carries the interfaces.
pub fn union<D: Dim>(bodies: &[&Mesh<D>]) -> Result<(Mesh<D>, Vec<Vec<u32>>), MeshError> {
    if bodies.is_empty() {
        return Err(MeshError::Empty);
    }
    if let Some(b) = bodies.iter().find(|b| b.interfaces().is_split()) {
        return Err(MeshError::AlreadySplit {
            interfaces: b.interfaces().len(),
            hint: "join the bodies first, then split the union",
        });
    }
    let (mut coords, mut conn, mut nodes) = (Vec::new(), Vec::new(), Vec::new());
    for b in bodies {
        let off = (coords.len() / D::D) as u32;
        nodes.push((off..off + b.n_nodes() as u32).collect());
        coords.extend_from_slice(b.coords());
        conn.extend(b.elements().iter().map(|n| n + off));
    }
    Ok((Mesh::new(coords, conn)?, nodes))
}

#[cfg(test)]
mod union_tests {
    use super::*;

    #[test]
    fn union_keeps_bodies_apart() {
        let a = rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let b = rectangle(2.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let (m, nodes) = union(&[&a, &b]).unwrap();
        assert_eq!(m.n_nodes(), a.n_nodes() + b.n_nodes());
        assert_eq!(m.n_elements(), a.n_elements() + b.n_elements());
        assert_eq!(nodes[1][0] as usize, a.n_nodes());
        assert!(nodes[1].iter().all(|&n| m.node(n as usize)[0] >= 2.0));
        assert!(union::<Dim2>(&[]).is_err());
    }
}
