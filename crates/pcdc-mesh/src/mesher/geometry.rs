//! Planar geometry of a meshing domain: its segments, the checks on them, and a fast
//! point-in-domain test.

use super::{domain_error, Domain};
use crate::MeshError;

/// One straight piece of the domain's boundary or of a constraint line.
#[derive(Clone, Debug)]
pub(super) struct Segment {
    pub a: [f64; 2],
    pub b: [f64; 2],
    /// `Some(k)`: edge of loop `k` (0 the outer boundary, `k ≥ 1` hole `k − 1`);
    /// `None`: a piece of a constraint line.
    pub loop_index: Option<usize>,
    /// The group name its nodes and faces join, if any.
    pub name: Option<String>,
}

/// Every segment of the domain: the outer loop's edges, each hole's, then the lines'.
pub(super) fn segments(domain: &Domain) -> Vec<Segment> {
    let mut out = Vec::new();
    for (k, lp) in std::iter::once(&domain.outer)
        .chain(&domain.holes)
        .enumerate()
    {
        let n = lp.points.len();
        for i in 0..n {
            out.push(Segment {
                a: lp.points[i],
                b: lp.points[(i + 1) % n],
                loop_index: Some(k),
                name: lp.edge_name(i).map(str::to_owned),
            });
        }
    }
    for line in &domain.lines {
        for w in line.points.windows(2) {
            out.push(Segment {
                a: w[0],
                b: w[1],
                loop_index: None,
                name: line.name.clone(),
            });
        }
    }
    out
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Distance from `p` to the segment `a`–`b` (m).
pub(super) fn point_segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ab, ap) = (sub(b, a), sub(p, a));
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(ap, ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - t * ab[0], ap[1] - t * ab[1]];
    dot(d, d).sqrt()
}

/// Whether the closed segments `p`–`q` and `r`–`s` share a point (touching counts).
fn segments_meet(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2], tol: f64) -> bool {
    let d1 = cross(sub(q, p), sub(r, p));
    let d2 = cross(sub(q, p), sub(s, p));
    let d3 = cross(sub(s, r), sub(p, r));
    let d4 = cross(sub(s, r), sub(q, r));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    // Touching or collinear overlap: an end point within `tol` of the other segment.
    point_segment_distance(r, p, q) <= tol
        || point_segment_distance(s, p, q) <= tol
        || point_segment_distance(p, r, s) <= tol
        || point_segment_distance(q, r, s) <= tol
}

/// Checks the domain: finite points, loops of at least three points and lines of at
/// least two, no edge shorter than `tol`, no two segments meeting except consecutive
/// edges of one loop or line at their shared point, holes and lines inside the outer
/// boundary and outside every other hole.
pub(super) fn check(domain: &Domain, segs: &[Segment], tol: f64) -> Result<(), MeshError> {
    let loops = std::iter::once(("outer boundary".to_owned(), &domain.outer.points))
        .chain((domain.holes.iter().enumerate()).map(|(k, h)| (format!("hole {k}"), &h.points)));
    for (what, pts) in loops {
        if pts.len() < 3 {
            return Err(domain_error(what, "needs at least three points"));
        }
    }
    for (k, l) in domain.lines.iter().enumerate() {
        if l.points.len() < 2 {
            return Err(domain_error(
                format!("line {k}"),
                "needs at least two points",
            ));
        }
    }
    for (i, s) in segs.iter().enumerate() {
        let what = describe(domain, segs, i);
        if !(s.a.iter().chain(&s.b).all(|v| v.is_finite())) {
            return Err(domain_error(what, "has a non-finite coordinate"));
        }
        let d = sub(s.b, s.a);
        if dot(d, d).sqrt() <= tol {
            return Err(domain_error(
                what,
                "has coincident end points (an edge of zero length)",
            ));
        }
    }
    for i in 0..segs.len() {
        for j in i + 1..segs.len() {
            let (s, t) = (&segs[i], &segs[j]);
            if !segments_meet(s.a, s.b, t.a, t.b, tol) {
                continue;
            }
            if adjacent(domain, segs, i, j) {
                // Consecutive edges share one point; they must not fold back onto
                // each other.
                let (u, v) = (sub(s.b, s.a), sub(t.b, t.a));
                let folded = cross(u, v).abs() <= 1e-12 * dot(u, u).sqrt() * dot(v, v).sqrt()
                    && dot(u, v) < 0.0;
                if !folded {
                    continue;
                }
            }
            return Err(domain_error(
                describe(domain, segs, i),
                format!(
                    "meets {} (the boundary must not intersect itself, holes and lines must not touch the boundary, other holes or other lines)",
                    describe(domain, segs, j)
                ),
            ));
        }
    }
    let inside = Inside::new(segs);
    for (k, h) in domain.holes.iter().enumerate() {
        let p = h.points[0];
        if !point_in_loop(p, &domain.outer.points) {
            return Err(domain_error(
                format!("hole {k}"),
                "lies outside the outer boundary",
            ));
        }
        for (m, other) in domain.holes.iter().enumerate() {
            if m != k && point_in_loop(p, &other.points) {
                return Err(domain_error(
                    format!("hole {k}"),
                    format!("lies inside hole {m} (holes must not be nested)"),
                ));
            }
        }
    }
    for (k, l) in domain.lines.iter().enumerate() {
        if !inside.contains(l.points[0]) {
            return Err(domain_error(
                format!("line {k}"),
                "lies outside the domain (outside the outer boundary or inside a hole)",
            ));
        }
    }
    Ok(())
}

/// Whether segments `i < j` are consecutive edges of one loop or line.
fn adjacent(domain: &Domain, segs: &[Segment], i: usize, j: usize) -> bool {
    let (s, t) = (&segs[i], &segs[j]);
    if s.loop_index != t.loop_index {
        return false;
    }
    match s.loop_index {
        Some(k) => {
            let n = if k == 0 {
                domain.outer.points.len()
            } else {
                domain.holes[k - 1].points.len()
            };
            let first = segs
                .iter()
                .position(|g| g.loop_index == Some(k))
                .unwrap_or(0);
            let (a, b) = (i - first, j - first);
            b == a + 1 || (a == 0 && b == n - 1)
        }
        // Lines: consecutive in the list and sharing a point (pieces of one line).
        None => j == i + 1 && s.b == t.a,
    }
}

/// "edge 3 of hole 1 ((x, y)-(x, y))" for error messages.
fn describe(domain: &Domain, segs: &[Segment], i: usize) -> String {
    let s = &segs[i];
    let first = segs
        .iter()
        .position(|g| g.loop_index == s.loop_index)
        .unwrap_or(0);
    let owner = match s.loop_index {
        Some(0) => "the outer boundary".to_owned(),
        Some(k) => format!("hole {}", k - 1),
        None => {
            // Which line: count the lines' pieces.
            let mut at = first;
            let mut line = 0;
            for (m, l) in domain.lines.iter().enumerate() {
                let pieces = l.points.len().saturating_sub(1);
                if i < at + pieces {
                    line = m;
                    break;
                }
                at += pieces;
            }
            return format!("piece {} of line {line} ({:?}-{:?})", i - at, s.a, s.b);
        }
    };
    format!("edge {} of {owner} ({:?}-{:?})", i - first, s.a, s.b)
}

/// Even-odd point-in-polygon test.
pub(super) fn point_in_loop(p: [f64; 2], pts: &[[f64; 2]]) -> bool {
    let n = pts.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (pts[i], pts[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Point-in-domain test over the loop segments, bucketed in horizontal bands so that a
/// query looks only at the segments spanning its height (even-odd rule: inside the outer
/// boundary and outside every hole).
pub(super) struct Inside {
    y0: f64,
    dy: f64,
    bands: Vec<Vec<([f64; 2], [f64; 2])>>,
}

impl Inside {
    pub(super) fn new(segs: &[Segment]) -> Self {
        let loops: Vec<&Segment> = segs.iter().filter(|s| s.loop_index.is_some()).collect();
        let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &loops {
            y0 = y0.min(s.a[1]).min(s.b[1]);
            y1 = y1.max(s.a[1]).max(s.b[1]);
        }
        let nb = (loops.len() / 4).clamp(1, 4096);
        let dy = ((y1 - y0) / nb as f64).max(f64::MIN_POSITIVE);
        let mut bands = vec![Vec::new(); nb];
        for s in loops {
            let lo = s.a[1].min(s.b[1]);
            let hi = s.a[1].max(s.b[1]);
            let (i0, i1) = (
                (((lo - y0) / dy).floor().max(0.0) as usize).min(nb - 1),
                (((hi - y0) / dy).floor().max(0.0) as usize).min(nb - 1),
            );
            for band in &mut bands[i0..=i1] {
                band.push((s.a, s.b));
            }
        }
        Inside { y0, dy, bands }
    }

    /// Whether `p` lies inside the domain (even-odd over every loop).
    pub(super) fn contains(&self, p: [f64; 2]) -> bool {
        let f = (p[1] - self.y0) / self.dy;
        if !(f >= 0.0 && f <= self.bands.len() as f64) {
            return false;
        }
        let band = &self.bands[(f as usize).min(self.bands.len() - 1)];
        let mut inside = false;
        for &(a, b) in band {
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p[0] < x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}
