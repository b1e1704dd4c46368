//! Locating bolt nodes in their host elements: the element of the reference mesh that
//! holds a point and the point's barycentric coordinates there (the linear shape
//! functions of a Tri3 or Tet4), with which the host's motion is interpolated at the
//! bolt node and the grout's reaction is spread back to the host's nodes.

use pcdc_mesh::{Dim, Mesh};

/// Barycentric weights (dimensionless) this close count as equal when choosing a host:
/// a point on an element face lies on it to rounding, which may fall either way.
pub(crate) const TIE: f64 = 1e-12;

/// Barycentric coordinates of `p` in the simplex with vertices `x` (stride `d`, d + 1
/// vertices): weights summing to 1, all in [0, 1] inside.
pub fn barycentric(d: usize, x: &[f64], p: &[f64]) -> [f64; 4] {
    let mut w = [0.0; 4];
    if d == 2 {
        let (x0, y0) = (x[0], x[1]);
        let (a, b, c, e) = (x[2] - x0, x[4] - x0, x[3] - y0, x[5] - y0);
        let det = a * e - b * c;
        let (px, py) = (p[0] - x0, p[1] - y0);
        w[1] = (e * px - b * py) / det;
        w[2] = (a * py - c * px) / det;
        w[0] = 1.0 - w[1] - w[2];
    } else {
        // Columns: edges from vertex 0; solve by Cramer's rule.
        let col = |k: usize| [x[3 * k] - x[0], x[3 * k + 1] - x[1], x[3 * k + 2] - x[2]];
        let (c1, c2, c3) = (col(1), col(2), col(3));
        let r = [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
        let det3 = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
            a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1])
                + c[0] * (a[1] * b[2] - a[2] * b[1])
        };
        let det = det3(c1, c2, c3);
        w[1] = det3(r, c2, c3) / det;
        w[2] = det3(c1, r, c3) / det;
        w[3] = det3(c1, c2, r) / det;
        w[0] = 1.0 - w[1] - w[2] - w[3];
    }
    w
}

/// The smallest height of the simplex with vertices `x` (stride `d`): twice its area
/// over its longest edge in 2D, three times its volume over its largest face in 3D (m).
/// A point whose barycentric weights are all at least `w` stays inside the element
/// while it moves less than `w` times this (each weight changes by at most the distance
/// over the height above its vertex).
pub fn min_height(d: usize, x: &[f64]) -> f64 {
    let v = |q: usize, k: usize| x[d * q + k];
    if d == 2 {
        let det =
            (v(1, 0) - v(0, 0)) * (v(2, 1) - v(0, 1)) - (v(2, 0) - v(0, 0)) * (v(1, 1) - v(0, 1));
        let edge = |a: usize, b: usize| (v(a, 0) - v(b, 0)).hypot(v(a, 1) - v(b, 1));
        det.abs() / edge(0, 1).max(edge(1, 2)).max(edge(0, 2))
    } else {
        let sub = |a: usize, b: usize| [v(a, 0) - v(b, 0), v(a, 1) - v(b, 1), v(a, 2) - v(b, 2)];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let (e1, e2, e3) = (sub(1, 0), sub(2, 0), sub(3, 0));
        let c = cross(e1, e2);
        let vol6 = (c[0] * e3[0] + c[1] * e3[1] + c[2] * e3[2]).abs();
        let faces = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
        let area2 = faces
            .iter()
            .map(|f| norm(cross(sub(f[1], f[0]), sub(f[2], f[0]))))
            .fold(0.0, f64::max);
        vol6 / area2
    }
}

/// The host of a point: element and weights of its `D + 1` nodes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Host {
    /// Element index.
    pub element: usize,
    /// Barycentric weights (the first `D + 1` used).
    pub weights: [f64; 4],
}

/// A uniform bucket grid over the elements' bounding boxes, to locate many points.
pub struct Locator<'a, D: Dim> {
    mesh: &'a Mesh<D>,
    lo: [f64; 3],
    cell: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<'a, D: Dim> Locator<'a, D> {
    /// Buckets the elements of `mesh` (about one element per cell).
    pub fn new(mesh: &'a Mesh<D>) -> Self {
        let d = D::D;
        let (lo_v, hi_v) = mesh.bounding_box();
        let mut lo = [0.0; 3];
        let mut ext = [0.0f64; 3];
        for k in 0..d {
            lo[k] = lo_v[k];
            ext[k] = hi_v[k] - lo_v[k];
        }
        let volume: f64 = ext[..d].iter().map(|e| e.max(1e-300)).product();
        let n = mesh.n_elements().max(1) as f64;
        let cell = (volume / n).powf(1.0 / d as f64).max(1e-300);
        let mut dims = [1usize; 3];
        for k in 0..d {
            dims[k] = ((ext[k] / cell).ceil() as usize).clamp(1, 1 << 20);
        }
        let mut loc = Locator {
            mesh,
            lo,
            cell,
            dims,
            start: Vec::new(),
            items: Vec::new(),
        };
        let total = dims[0] * dims[1] * dims[2];
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); total];
        let mut x = vec![0.0; D::NODES_PER_ELEM * d];
        for e in 0..mesh.n_elements() {
            mesh.element_coords(e, &mut x);
            let (a, b) = loc.cell_range(&x);
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        lists[(k * dims[1] + j) * dims[0] + i].push(e as u32);
                    }
                }
            }
        }
        loc.start.push(0);
        for l in lists {
            loc.items.extend(l);
            loc.start.push(loc.items.len() as u32);
        }
        loc
    }

    /// The bucket size (m), about one element across.
    pub(crate) fn cell(&self) -> f64 {
        self.cell
    }

    fn cell_of(&self, v: f64, k: usize) -> usize {
        (((v - self.lo[k]) / self.cell).floor().max(0.0) as usize).min(self.dims[k] - 1)
    }

    fn cell_range(&self, x: &[f64]) -> ([usize; 3], [usize; 3]) {
        let d = D::D;
        let (mut a, mut b) = ([0usize; 3], [0usize; 3]);
        for k in 0..d {
            let (mn, mx) = x
                .iter()
                .skip(k)
                .step_by(d)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(m, n), &v| {
                    (m.min(v), n.max(v))
                });
            a[k] = self.cell_of(mn, k);
            b[k] = self.cell_of(mx, k);
        }
        (a, b)
    }

    /// The element holding `p` (m): the one whose smallest barycentric weight is largest
    /// (so a point on a shared face or vertex picks one element: the lowest index among
    /// those within 1e-12 of the largest, so that rounding, e.g. of a change of units,
    /// does not pick another), if that weight is above `-tol` (relative). `None` outside
    /// the mesh.
    pub fn locate(&self, p: &[f64], tol: f64) -> Option<Host> {
        let d = D::D;
        let mut c = [0usize; 3];
        for k in 0..d {
            let v = p[k];
            if v < self.lo[k] - tol * self.cell * 10.0
                || v > self.lo[k] + self.dims[k] as f64 * self.cell + tol * self.cell * 10.0
            {
                return None;
            }
            c[k] = self.cell_of(v, k);
        }
        let cell = (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0];
        let mut best: Option<(f64, Host)> = None;
        let mut x = vec![0.0; D::NODES_PER_ELEM * d];
        for &e in &self.items[self.start[cell] as usize..self.start[cell + 1] as usize] {
            self.mesh.element_coords(e as usize, &mut x);
            let w = barycentric(d, &x, p);
            let min = w[..=d].iter().cloned().fold(f64::INFINITY, f64::min);
            let better = match &best {
                None => true,
                Some((m, h)) => min > *m + TIE || (min >= *m - TIE && (e as usize) < h.element),
            };
            if better {
                best = Some((
                    min,
                    Host {
                        element: e as usize,
                        weights: w,
                    },
                ));
            }
        }
        best.filter(|(m, _)| *m >= -tol).map(|(_, h)| h)
    }
}
