//! Unstructured 2D quality meshing: constrained Delaunay triangulation with refinement,
//! for specimens and for user polygons with holes and internal constraint lines.
//!
//! A [`Domain`] is an outer boundary [`Loop`], optional holes (loops inside it) and
//! optional constraint [`Polyline`]s inside it (pre-existing fractures, layer contacts:
//! they become mesh edges, so joints lie exactly on them). [`triangulate`] meshes it
//! with Tri3 elements to a target size ([`SizeField`]: uniform, or graded from the
//! holes and lines) and a minimum angle ([`MesherOptions::min_angle_deg`]):
//!
//! 1. the loops and lines are divided into pieces of about the local size h(x);
//! 2. the interior is filled by a seeded Poisson-disk sample (Bridson's algorithm) of
//!    radius 0.74 h(x), which gives the node density of an equilateral mesh of edge
//!    h with no preferred direction: the edges of the mesh point every way with equal
//!    likelihood, unlike a structured pattern whose joint lines a crack can follow;
//! 3. the points and the constraint edges are triangulated by
//!    [spade](https://docs.rs/spade)'s constrained Delaunay triangulation, and spade's
//!    Delaunay refinement (Ruppert/Chew) inserts points until no angle is below the
//!    limit (except at sharper input corners) and no triangle exceeds three times the
//!    area of the equilateral triangle of the local size;
//! 4. the triangles outside the outer loop or inside a hole are dropped (even-odd rule
//!    across the loops' edges; the lines do not count).
//!
//! Why spade: it is a maintained, pure-Rust, dependency-light crate with exact
//! predicates (the `robust` crate), constrained triangulation and Ruppert refinement
//! with an angle limit, which is what a hand-written mesher would take weeks to make as
//! robust. It is behind the `mesher` feature (on by default).
//!
//! The same domain, options and seed give the same mesh on every platform (the sample
//! uses the portable PCG generator of `rand_pcg`); another seed gives another mesh of
//! the same statistics, for mesh-sensitivity studies.
//!
//! Groups: a named loop edge or line gives a node group (its nodes) and a face group
//! (the faces along it: boundary faces for loop edges, interior faces for lines) of
//! that name; the element group `"all"` holds every element.
//!
//! Element size and count: the mean triangle area is close to √3/4 h², the area of the
//! equilateral triangle of edge h (within about 10 %, measured in the tests), so a
//! region of area A gets about 2.3 A / h² elements, as the structured patterns.

mod geometry;
mod sampling;
mod specimens;

pub use specimens::{disc, plate_with_hole, rectangle, ring};

use serde::{Deserialize, Serialize};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use crate::{Dim2, Mesh, MeshError};
use geometry::{Inside, Segment};
use sampling::Size;

/// Default smallest angle of the triangles (degrees): Ruppert refinement terminates
/// reliably up to about 30°; 28° leaves a margin.
pub const DEFAULT_MIN_ANGLE_DEG: f64 = 28.0;

/// Largest accepted angle limit (degrees): above it refinement may not terminate.
pub const MAX_MIN_ANGLE_DEG: f64 = 33.0;

/// Smallest element size as a fraction of the domain's extent (its bounding box's
/// larger side): a finer size is refused as a mistake (over 10 000 elements across).
pub const MIN_SIZE_FRACTION: f64 = 1e-4;

/// A closed polygon (m): `points` in order (either orientation), the closing edge from
/// the last point back to the first implied (do not repeat the first point).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Loop {
    /// Vertices (m).
    pub points: Vec<[f64; 2]>,
    /// Group names of the edges: empty (no groups), one name for every edge, or one
    /// per edge (`names[i]` for the edge from point `i` to point `i + 1`; an empty
    /// string leaves that edge unnamed).
    #[serde(default)]
    pub names: Vec<String>,
}

impl Loop {
    /// A loop with unnamed edges.
    pub fn new(points: Vec<[f64; 2]>) -> Self {
        Loop {
            points,
            names: Vec::new(),
        }
    }

    /// A loop whose every edge joins the group `name`.
    pub fn named(points: Vec<[f64; 2]>, name: &str) -> Self {
        Loop {
            points,
            names: vec![name.to_owned()],
        }
    }

    /// A circle of `n` equally spaced points of radius `radius` (m) about `center`.
    pub fn circle(center: [f64; 2], radius: f64, n: usize) -> Self {
        let step = std::f64::consts::TAU / n as f64;
        Loop::new(
            (0..n)
                .map(|k| {
                    let a = k as f64 * step;
                    [center[0] + radius * a.cos(), center[1] + radius * a.sin()]
                })
                .collect(),
        )
    }

    /// The group name of edge `i`, if any.
    fn edge_name(&self, i: usize) -> Option<&str> {
        let name = match self.names.len() {
            0 => return None,
            1 => &self.names[0],
            _ => self.names.get(i)?,
        };
        (!name.is_empty()).then_some(name.as_str())
    }
}

/// An open polyline (m) inside the domain whose pieces become mesh edges.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Polyline {
    /// Vertices (m), at least two.
    pub points: Vec<[f64; 2]>,
    /// Group name of its nodes and faces, if any.
    #[serde(default)]
    pub name: Option<String>,
}

/// A planar region to mesh: an outer boundary, holes, constraint lines.
///
/// The outer loop must not intersect itself; holes lie inside it, apart from it and
/// from each other (not nested); lines lie strictly inside the meshed region (they may
/// not touch a loop or each other: end a fracture that reaches a free surface just
/// inside it). [`triangulate`] checks all this and names the offending edge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    /// The outer boundary.
    pub outer: Loop,
    /// Holes.
    #[serde(default)]
    pub holes: Vec<Loop>,
    /// Constraint lines.
    #[serde(default)]
    pub lines: Vec<Polyline>,
}

impl Domain {
    /// A domain bounded by `outer`, with no holes or lines.
    pub fn new(outer: Loop) -> Self {
        Domain {
            outer,
            holes: Vec::new(),
            lines: Vec::new(),
        }
    }

    /// Adds a hole.
    pub fn hole(mut self, hole: Loop) -> Self {
        self.holes.push(hole);
        self
    }

    /// Adds a constraint line through `points` (m), named `name` if given.
    pub fn line(mut self, points: Vec<[f64; 2]>, name: Option<&str>) -> Self {
        self.lines.push(Polyline {
            points,
            name: name.map(str::to_owned),
        });
        self
    }
}

/// Target element size h(x) (m): the edge of the equilateral triangle whose area the
/// elements have near x.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SizeField {
    /// The same size everywhere.
    Uniform {
        /// Element size (m).
        size: f64,
    },
    /// Graded from the holes and constraint lines: h = min(far, near + growth d), with
    /// d the distance to the nearest hole edge or line (m).
    Graded {
        /// Size on the holes and lines (m).
        near: f64,
        /// Largest size (m).
        far: f64,
        /// Growth of the size per metre of distance (dimensionless, > 0; 0.2-0.5 gives
        /// a smooth gradation).
        growth: f64,
    },
}

/// What [`triangulate`] aims for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MesherOptions {
    /// Element size.
    pub size: SizeField,
    /// Smallest triangle angle (degrees, 0 to [`MAX_MIN_ANGLE_DEG`]; default
    /// [`DEFAULT_MIN_ANGLE_DEG`]); sharper corners of the input keep their angle.
    #[serde(default = "default_min_angle")]
    pub min_angle_deg: f64,
    /// Seed of the interior sample: the same seed gives the same mesh.
    #[serde(default)]
    pub seed: u64,
}

fn default_min_angle() -> f64 {
    DEFAULT_MIN_ANGLE_DEG
}

impl MesherOptions {
    /// Uniform size `size` (m), the default angle limit, seed 0.
    pub fn uniform(size: f64) -> Self {
        MesherOptions {
            size: SizeField::Uniform { size },
            min_angle_deg: DEFAULT_MIN_ANGLE_DEG,
            seed: 0,
        }
    }

    /// The same options with another seed.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    fn check(&self) -> Result<(f64, f64), MeshError> {
        let bad = |name, value: f64, reason| {
            Err(MeshError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if !(self.min_angle_deg >= 0.0 && self.min_angle_deg <= MAX_MIN_ANGLE_DEG) {
            return bad(
                "min_angle_deg",
                self.min_angle_deg,
                "must lie in 0-33 degrees (above about 30 degrees refinement may not terminate)",
            );
        }
        match self.size {
            SizeField::Uniform { size } => {
                if !(size.is_finite() && size > 0.0) {
                    return bad("size", size, "must be finite and positive");
                }
                Ok((size, size))
            }
            SizeField::Graded { near, far, growth } => {
                if !(near.is_finite() && near > 0.0) {
                    return bad("near", near, "must be finite and positive");
                }
                if !(far.is_finite() && far >= near) {
                    return bad("far", far, "must be finite and at least near");
                }
                if !(growth.is_finite() && growth > 0.0) {
                    return bad("growth", growth, "must be finite and positive");
                }
                Ok((near, far))
            }
        }
    }
}

pub(crate) fn domain_error(what: impl Into<String>, reason: impl Into<String>) -> MeshError {
    MeshError::Domain {
        what: what.into(),
        reason: reason.into(),
    }
}

/// Area (m²) of the equilateral triangle of edge `h`.
fn equilateral_area(h: f64) -> f64 {
    0.75f64.sqrt() / 2.0 * h * h
}

/// Meshes `domain` with Tri3 elements (counter-clockwise) as the module docs describe.
///
/// Errors: an ill-formed domain ([`MeshError::Domain`], naming the loop, line or edge),
/// bad options ([`MeshError::InvalidParameter`]), a size below
/// [`MIN_SIZE_FRACTION`] of the domain's extent or above the extent, a mesh beyond the
/// memory limit ([`MeshError::MemoryLimit`]), or refinement that could not reach the
/// angle limit ([`MeshError::Mesher`]).
pub fn triangulate(domain: &Domain, options: &MesherOptions) -> Result<Mesh<Dim2>, MeshError> {
    let (h_min, h_max) = options.check()?;
    let segs = geometry::segments(domain);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in segs.iter().flat_map(|s| [s.a, s.b]) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if !(extent.is_finite() && extent > 0.0) {
        geometry::check(domain, &segs, 0.0)?;
        return Err(domain_error("outer boundary", "has no extent"));
    }
    geometry::check(domain, &segs, 1e-9 * extent)?;
    if h_min < MIN_SIZE_FRACTION * extent {
        return Err(MeshError::InvalidParameter {
            name: "size",
            value: h_min,
            reason: "is below 1e-4 of the domain's extent (over 10 000 elements across): a unit mistake?",
        });
    }
    if h_max > extent {
        return Err(MeshError::InvalidParameter {
            name: "size",
            value: h_max,
            reason: "exceeds the domain's extent",
        });
    }
    let features: Vec<&Segment> = segs.iter().filter(|s| s.loop_index != Some(0)).collect();
    if matches!(options.size, SizeField::Graded { .. }) && features.is_empty() {
        return Err(MeshError::InvalidParameter {
            name: "size",
            value: h_min,
            reason: "a graded size grows from the holes and lines, and the domain has none",
        });
    }
    // The sampler's grid spans the bounding box at the finest size: a wide gradation
    // (a tiny `near` in a large domain) must not allocate gigabytes for it.
    if sampling::grid_cells(lo, hi, h_min) > 6.4e7 {
        return Err(MeshError::InvalidParameter {
            name: "near",
            value: h_min,
            reason: "is too small for the domain's extent: the sampler's grid would exceed 64 million cells (about 256 MB); use a larger finest size or mesh a smaller domain",
        });
    }
    let inside = Inside::new(&segs);
    let size = Size::new(&options.size, lo, hi, &features);
    check_count(&size, h_min, lo, hi, &inside)?;

    // 1. Loops and lines, divided; constraint edges between consecutive points.
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut edges: Vec<[usize; 2]> = Vec::new();
    for lp in std::iter::once(&domain.outer).chain(&domain.holes) {
        let first = pts.len();
        let n = lp.points.len();
        for i in 0..n {
            pts.push(lp.points[i]);
            pts.extend(sampling::subdivide(
                lp.points[i],
                lp.points[(i + 1) % n],
                &size,
            ));
        }
        let m = pts.len() - first;
        edges.extend((0..m).map(|i| [first + i, first + (i + 1) % m]));
    }
    for line in &domain.lines {
        let first = pts.len();
        for w in line.points.windows(2) {
            pts.push(w[0]);
            pts.extend(sampling::subdivide(w[0], w[1], &size));
        }
        pts.push(*line.points.last().expect("checked: two points"));
        edges.extend((first..pts.len() - 1).map(|i| [i, i + 1]));
    }
    // 2. The interior sample.
    let interior = sampling::poisson(&pts, &inside, &size, lo, hi, options.seed);
    pts.extend(interior);
    // 3. Triangulate and refine.
    let mut conflict = None;
    let vertices: Vec<Point2<f64>> = pts.iter().map(|p| Point2::new(p[0], p[1])).collect();
    let mut cdt =
        ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(vertices, edges, |e| {
            conflict = Some(e)
        })
        .map_err(|e| MeshError::Mesher(format!("triangulation failed: {e:?}")))?;
    if let Some([a, b]) = conflict {
        return Err(MeshError::Mesher(format!(
            "the constraint edge {:?}-{:?} crosses another one",
            pts[a], pts[b]
        )));
    }
    refine(&mut cdt, options, &size, &inside, domain.lines.is_empty())?;
    // 4. Keep the triangles inside.
    extract(&cdt, &segs, 1e-9 * extent)
}

/// The memory and index-width guard, from the expected element count ∫ dA / A(h).
fn check_count(
    size: &Size,
    h_min: f64,
    lo: [f64; 2],
    hi: [f64; 2],
    inside: &Inside,
) -> Result<(), MeshError> {
    // Integrate over a coarse grid of at most 256 × 256 cells.
    let n = 256;
    let (dx, dy) = ((hi[0] - lo[0]) / n as f64, (hi[1] - lo[1]) / n as f64);
    let mut count = 0.0;
    for j in 0..n {
        for i in 0..n {
            let p = [lo[0] + (i as f64 + 0.5) * dx, lo[1] + (j as f64 + 0.5) * dy];
            if inside.contains(p) {
                count += dx * dy / equilateral_area(size.at(p));
            }
        }
    }
    if count > u32::MAX as f64 / 2.0 {
        return Err(MeshError::InvalidParameter {
            name: "size",
            value: h_min,
            reason: "too small: the mesh would exceed the limit of 32-bit indices",
        });
    }
    crate::memory::check_mesh_memory::<Dim2>("size", h_min, count, count)
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Delaunay refinement to the angle limit, then until no triangle inside the domain
/// exceeds three times the equilateral area of its local size.
fn refine(
    cdt: &mut Cdt,
    options: &MesherOptions,
    size: &Size,
    inside: &Inside,
    exclude_outer: bool,
) -> Result<(), MeshError> {
    let (_, h_max) = size.range();
    let limit = AngleLimit::from_deg(options.min_angle_deg);
    for round in 0..12 {
        let params = RefinementParameters::<f64>::new()
            .with_angle_limit(limit)
            .with_max_allowed_area(3.0 * equilateral_area(h_max))
            // Without lines spade's own inside/outside test is exact and spares the
            // refinement of holes; with lines (open constraints) it is not, so the
            // outside is refined too and dropped afterwards.
            .exclude_outer_faces(exclude_outer)
            .with_max_additional_vertices(4 * cdt.num_vertices() + 1000);
        let result = cdt.refine(params);
        if !result.refinement_complete {
            return Err(MeshError::Mesher(format!(
                "refinement to a {}° angle limit did not finish; lower min_angle_deg or smooth the sharp corners of the domain",
                options.min_angle_deg
            )));
        }
        // Graded sizes: split triangles far above their local size at their centroid.
        let big: Vec<Point2<f64>> = cdt
            .inner_faces()
            .filter_map(|f| {
                let c = f.center();
                let p = [c.x, c.y];
                (f.area() > 3.0 * equilateral_area(size.at(p)) && inside.contains(p)).then_some(c)
            })
            .collect();
        if big.is_empty() {
            return Ok(());
        }
        if round == 11 {
            break;
        }
        for c in big {
            cdt.insert(c)
                .map_err(|e| MeshError::Mesher(format!("insertion failed: {e:?}")))?;
        }
    }
    Err(MeshError::Mesher(
        "the size field could not be met after 12 rounds of refinement".into(),
    ))
}

/// The triangles inside the domain as a mesh with its groups.
fn extract(cdt: &Cdt, segs: &[Segment], tol: f64) -> Result<Mesh<Dim2>, MeshError> {
    // Segments each constraint-edge vertex lies on.
    let nv = cdt.num_vertices();
    let mut on: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut tagged = vec![false; nv];
    for e in cdt.undirected_edges().filter(|e| e.is_constraint_edge()) {
        for v in e.vertices() {
            let i = v.fix().index();
            if tagged[i] {
                continue;
            }
            tagged[i] = true;
            let p = v.position();
            on[i] = (segs.iter().enumerate())
                .filter(|(_, s)| geometry::point_segment_distance([p.x, p.y], s.a, s.b) <= tol)
                .map(|(k, _)| k as u32)
                .collect();
        }
    }
    // The segment an edge between two vertices lies along, if any.
    let along =
        |a: usize, b: usize| -> Option<u32> { on[a].iter().copied().find(|s| on[b].contains(s)) };
    let is_loop_edge = |e: spade::handles::DirectedEdgeHandle<'_, _, _, _, _>| {
        let [a, b] = e.vertices().map(|v| v.fix().index());
        e.is_constraint_edge() && along(a, b).is_some_and(|s| segs[s as usize].loop_index.is_some())
    };
    // Inside/outside by parity across loop edges, flooding from the convex hull.
    // Face indices count the outer face (index 0) too.
    let nf = cdt.num_all_faces();
    let mut parity: Vec<Option<bool>> = vec![None; nf];
    let mut queue = std::collections::VecDeque::new();
    for e in cdt.convex_hull() {
        let e = e.rev();
        if let Some(f) = e.face().as_inner() {
            let idx = f.fix().index();
            if parity[idx].is_none() {
                parity[idx] = Some(is_loop_edge(e));
                queue.push_back(f);
            }
        }
    }
    while let Some(f) = queue.pop_front() {
        let p = parity[f.fix().index()].expect("queued faces have a parity");
        for e in f.adjacent_edges() {
            if let Some(g) = e.rev().face().as_inner() {
                let idx = g.fix().index();
                if parity[idx].is_none() {
                    parity[idx] = Some(p ^ is_loop_edge(e));
                    queue.push_back(g);
                }
            }
        }
    }
    // Renumber the vertices of the inside triangles.
    let mut new_index = vec![u32::MAX; nv];
    let mut coords = Vec::new();
    let mut conn = Vec::new();
    for f in cdt.inner_faces() {
        if parity[f.fix().index()] != Some(true) {
            continue;
        }
        for v in f.vertices() {
            let i = v.fix().index();
            if new_index[i] == u32::MAX {
                new_index[i] = (coords.len() / 2) as u32;
                let p = v.position();
                coords.extend_from_slice(&[p.x, p.y]);
            }
            conn.push(new_index[i]);
        }
    }
    let mut mesh = Mesh::<Dim2>::new(coords, conn)?;
    // Groups of the named segments.
    let mut old_of = vec![0usize; mesh.n_nodes()];
    for (old, &new) in new_index.iter().enumerate() {
        if new != u32::MAX {
            old_of[new as usize] = old;
        }
    }
    let mut names: Vec<&str> = segs.iter().filter_map(|s| s.name.as_deref()).collect();
    names.sort_unstable();
    names.dedup();
    for name in names {
        let named = |s: &u32| segs[*s as usize].name.as_deref() == Some(name);
        let nodes: Vec<u32> = (0..mesh.n_nodes() as u32)
            .filter(|&n| on[old_of[n as usize]].iter().any(named))
            .collect();
        let faces: Vec<u32> = (0..mesh.faces().len() as u32)
            .filter(|&f| {
                let fa = mesh.face(f as usize);
                along(old_of[fa[0] as usize], old_of[fa[1] as usize]).is_some_and(|s| named(&s))
            })
            .collect();
        mesh.add_node_group(name, nodes)?;
        mesh.add_face_group(name, faces)?;
    }
    mesh.add_element_group("all", (0..mesh.n_elements() as u32).collect())?;
    Ok(mesh)
}

/// Shape statistics of a triangle mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// Smallest interior angle of any triangle (degrees).
    pub min_angle_deg: f64,
    /// Mean edge length over the elements' edges (m; interior edges counted twice).
    pub mean_edge: f64,
    /// Mean element area (m²).
    pub mean_area: f64,
}

/// The [`Quality`] of a 2D mesh's triangles.
pub fn quality(mesh: &Mesh<Dim2>) -> Quality {
    let (mut min_angle, mut edge_sum, mut area_sum) = (f64::INFINITY, 0.0, 0.0);
    let x = mesh.coords();
    let ne = mesh.n_elements();
    for e in 0..ne {
        let t = mesh.element(e);
        let p: Vec<[f64; 2]> = t
            .iter()
            .map(|&n| [x[2 * n as usize], x[2 * n as usize + 1]])
            .collect();
        for k in 0..3 {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
            let ang = (u[0] * v[1] - u[1] * v[0])
                .abs()
                .atan2(u[0] * v[0] + u[1] * v[1]);
            min_angle = min_angle.min(ang.to_degrees());
            edge_sum += (u[0] * u[0] + u[1] * u[1]).sqrt();
        }
        let (u, v) = (
            [p[1][0] - p[0][0], p[1][1] - p[0][1]],
            [p[2][0] - p[0][0], p[2][1] - p[0][1]],
        );
        area_sum += 0.5 * (u[0] * v[1] - u[1] * v[0]);
    }
    Quality {
        min_angle_deg: min_angle,
        mean_edge: edge_sum / (3 * ne.max(1)) as f64,
        mean_area: area_sum / ne.max(1) as f64,
    }
}
