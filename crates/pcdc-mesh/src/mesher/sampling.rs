//! Where the mesher puts its nodes: the size field, the subdivision of the boundary and
//! constraint lines, and a Poisson-disk sample of the interior.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::geometry::{point_segment_distance, Inside, Segment};
use super::SizeField;

/// Distance between interior nodes as a fraction of the local element size: a maximal
/// Poisson-disk sample of radius r has about 0.70 / r² points per unit area, an
/// equilateral mesh of edge h 1.155 / h², so r ≈ 0.78 h would give the node count of the
/// equilateral mesh of that size; the refinement and the boundary add a few, and 0.74 h
/// gives the mean triangle area √3/4 h² (measured on rectangles and discs, tests).
pub(super) const DISK_RADIUS: f64 = 0.74;

/// Candidates tried around each active point before it retires (Bridson's k).
const TRIES: usize = 30;

/// The local element size h(x) (m), tabulated on a background grid for a graded field.
pub(super) struct Size {
    uniform: Option<f64>,
    min: f64,
    max: f64,
    x0: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    grid: Vec<f64>,
}

impl Size {
    /// The size field over the bounding box `lo`–`hi`; a graded field measures the
    /// distance to the `features` (the holes' edges and the lines).
    pub(super) fn new(
        field: &SizeField,
        lo: [f64; 2],
        hi: [f64; 2],
        features: &[&Segment],
    ) -> Self {
        match *field {
            SizeField::Uniform { size } => Size {
                uniform: Some(size),
                min: size,
                max: size,
                x0: lo,
                cell: 1.0,
                nx: 0,
                ny: 0,
                grid: Vec::new(),
            },
            SizeField::Graded { near, far, growth } => {
                // Grid spacing of half the finest size (the field is linear in the
                // distance, so bilinear interpolation errs by a fraction of `near`), but
                // at most 2000 × 2000 nodes for a very wide gradation.
                let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
                let cell = (0.5 * near).max(extent / 2000.0);
                let nx = (((hi[0] - lo[0]) / cell).ceil() as usize).max(1);
                let ny = (((hi[1] - lo[1]) / cell).ceil() as usize).max(1);
                let mut grid = Vec::with_capacity((nx + 1) * (ny + 1));
                for j in 0..=ny {
                    for i in 0..=nx {
                        let p = [lo[0] + i as f64 * cell, lo[1] + j as f64 * cell];
                        let d = features
                            .iter()
                            .map(|s| point_segment_distance(p, s.a, s.b))
                            .fold(f64::INFINITY, f64::min);
                        grid.push((near + growth * d).min(far));
                    }
                }
                Size {
                    uniform: None,
                    min: near,
                    max: far,
                    x0: lo,
                    cell,
                    nx,
                    ny,
                    grid,
                }
            }
        }
    }

    /// h(p) (m).
    pub(super) fn at(&self, p: [f64; 2]) -> f64 {
        if let Some(h) = self.uniform {
            return h;
        }
        let fx = ((p[0] - self.x0[0]) / self.cell).clamp(0.0, self.nx as f64);
        let fy = ((p[1] - self.x0[1]) / self.cell).clamp(0.0, self.ny as f64);
        let (i, j) = (
            (fx as usize).min(self.nx - 1),
            (fy as usize).min(self.ny - 1),
        );
        let (tx, ty) = (fx - i as f64, fy - j as f64);
        let g = |i: usize, j: usize| self.grid[j * (self.nx + 1) + i];
        (1.0 - ty) * ((1.0 - tx) * g(i, j) + tx * g(i + 1, j))
            + ty * ((1.0 - tx) * g(i, j + 1) + tx * g(i + 1, j + 1))
    }

    /// The smallest and largest size (m).
    pub(super) fn range(&self) -> (f64, f64) {
        (self.min, self.max)
    }
}

/// The points dividing segment `a`–`b` into pieces of about the local size: as many
/// pieces as the integral of 1/h along it (at least one), placed so that each spans an
/// equal share of that integral. Returns the interior points only (not `a`, `b`).
pub(super) fn subdivide(a: [f64; 2], b: [f64; 2], size: &Size) -> Vec<[f64; 2]> {
    const SAMPLES: usize = 64;
    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    // Cumulative ∫ ds / h at the sample ends (midpoint rule).
    let mut cum = vec![0.0; SAMPLES + 1];
    for k in 0..SAMPLES {
        let t = (k as f64 + 0.5) / SAMPLES as f64;
        cum[k + 1] = cum[k] + len / SAMPLES as f64 / size.at(at(t));
    }
    let n = (cum[SAMPLES].round() as usize).max(1);
    let mut out = Vec::with_capacity(n - 1);
    let mut k = 0;
    for m in 1..n {
        let target = cum[SAMPLES] * m as f64 / n as f64;
        while cum[k + 1] < target {
            k += 1;
        }
        let t = (k as f64 + (target - cum[k]) / (cum[k + 1] - cum[k])) / SAMPLES as f64;
        out.push(at(t));
    }
    out
}

/// Cells of the sampler's background grid for the bounding box `lo`–`hi` and the
/// smallest size `h_min` (one cell of side 0.74 h_min / √2 per possible sample).
pub(super) fn grid_cells(lo: [f64; 2], hi: [f64; 2], h_min: f64) -> f64 {
    let cell = DISK_RADIUS * h_min / std::f64::consts::SQRT_2;
    ((hi[0] - lo[0]) / cell).ceil().max(1.0) * ((hi[1] - lo[1]) / cell).ceil().max(1.0)
}

/// A Poisson-disk sample of the domain's interior (Bridson's algorithm with a radius
/// that follows the size field, r(x) = [`DISK_RADIUS`] h(x)), grown from the boundary
/// points `fixed`, which it keeps clear of. Seeded: the same seed gives the same points.
pub(super) fn poisson(
    fixed: &[[f64; 2]],
    inside: &Inside,
    size: &Size,
    lo: [f64; 2],
    hi: [f64; 2],
    seed: u64,
) -> Vec<[f64; 2]> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let (h_min, h_max) = size.range();
    let cell = DISK_RADIUS * h_min / std::f64::consts::SQRT_2;
    let nx = (((hi[0] - lo[0]) / cell).ceil() as usize).max(1);
    let ny = (((hi[1] - lo[1]) / cell).ceil() as usize).max(1);
    // Each cell holds at most one sample: two samples are at least r_min apart, the
    // cell's diagonal.
    let mut grid = vec![u32::MAX; nx * ny];
    let cell_of = |p: [f64; 2]| -> (usize, usize) {
        (
            (((p[0] - lo[0]) / cell).floor().max(0.0) as usize).min(nx - 1),
            (((p[1] - lo[1]) / cell).floor().max(0.0) as usize).min(ny - 1),
        )
    };
    let reach = (DISK_RADIUS * h_max / cell).ceil() as isize;
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut active: Vec<u32> = Vec::new();
    // Boundary points closer together than a cell (near sharp corners) cannot all
    // occupy their cell: the extra ones go to an overflow list, flagged per cell.
    let mut overflow: std::collections::HashMap<usize, Vec<u32>> = Default::default();
    let mut flagged = vec![false; nx * ny];
    for &p in fixed {
        let (i, j) = cell_of(p);
        let c = j * nx + i;
        if grid[c] == u32::MAX {
            grid[c] = points.len() as u32;
        } else {
            flagged[c] = true;
            overflow.entry(c).or_default().push(points.len() as u32);
        }
        active.push(points.len() as u32);
        points.push(p);
    }
    let n_fixed = points.len();
    let far_enough = |grid: &[u32], points: &[[f64; 2]], p: [f64; 2], r: f64| -> bool {
        let (ci, cj) = cell_of(p);
        let k = ((r / cell).ceil() as isize).min(reach);
        let close = |q: u32| {
            let q = points[q as usize];
            (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) < r * r
        };
        for dj in -k..=k {
            let j = cj as isize + dj;
            if j < 0 || j >= ny as isize {
                continue;
            }
            for di in -k..=k {
                let i = ci as isize + di;
                if i < 0 || i >= nx as isize {
                    continue;
                }
                let c = j as usize * nx + i as usize;
                if grid[c] != u32::MAX && close(grid[c]) {
                    return false;
                }
                if flagged[c] && overflow[&c].iter().any(|&q| close(q)) {
                    return false;
                }
            }
        }
        true
    };
    while !active.is_empty() {
        let slot = rng.random_range(0..active.len());
        let a = points[active[slot] as usize];
        let ra = DISK_RADIUS * size.at(a);
        let mut placed = false;
        for _ in 0..TRIES {
            let angle = rng.random::<f64>() * std::f64::consts::TAU;
            let dist = ra * (1.0 + rng.random::<f64>());
            let p = [a[0] + dist * angle.cos(), a[1] + dist * angle.sin()];
            if !(p[0] > lo[0] && p[0] < hi[0] && p[1] > lo[1] && p[1] < hi[1]) {
                continue;
            }
            let r = DISK_RADIUS * size.at(p);
            if !inside.contains(p) || !far_enough(&grid, &points, p, r) {
                continue;
            }
            let (i, j) = cell_of(p);
            if grid[j * nx + i] != u32::MAX {
                continue;
            }
            grid[j * nx + i] = points.len() as u32;
            active.push(points.len() as u32);
            points.push(p);
            placed = true;
            break;
        }
        if !placed {
            active.swap_remove(slot);
        }
    }
    points.split_off(n_fixed)
}
