//! Coincident unmerged nodes: Gmsh meshes of several surfaces or volumes that were not
//! made coherent carry two nodes at the same place on a shared boundary. The elements on
//! either side then share no face, so the mesh is silently cut there.

use std::collections::HashMap;
use std::fmt;

/// Relative tolerance of coincidence: two nodes coincide when their distance is at most
/// `COINCIDENT_REL_TOL` times the largest bounding-box extent of the mesh (the default of
/// [`ImportOptions::coincident_rel_tol`]).
pub const COINCIDENT_REL_TOL: f64 = 1e-9;

/// Options of [`read_msh_with`](super::read_msh_with) and
/// [`parse_msh_with`](super::parse_msh_with).
#[derive(Clone, Debug, PartialEq)]
pub struct ImportOptions {
    /// Merge coincident nodes into the one with the lowest tag (the mesh is then joined
    /// there) instead of warning about them. Default `false`.
    pub merge_coincident: bool,
    /// Coincidence tolerance relative to the largest bounding-box extent (-); must be
    /// finite and in `[0, 1e-3]`. Default [`COINCIDENT_REL_TOL`].
    pub coincident_rel_tol: f64,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            merge_coincident: false,
            coincident_rel_tol: COINCIDENT_REL_TOL,
        }
    }
}

/// Something the import accepted but that is probably not what the file meant.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ImportWarning {
    /// Nodes at the same position (within `tol`, m) that were not merged: the mesh is cut
    /// there.
    CoincidentNodes {
        /// Number of nodes that coincide with a node of lower tag.
        count: usize,
        /// The first pair, as Gmsh node tags (lower tag first).
        tags: (u64, u64),
        /// Their position (m).
        position: [f64; 3],
        /// Line of the second node in the file.
        line: usize,
        /// Distance tolerance used (m).
        tol: f64,
    },
}

impl fmt::Display for ImportWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ImportWarning::CoincidentNodes {
                count,
                tags,
                position,
                line,
                tol,
            } => write!(
                f,
                "line {line}: {count} node(s) coincide with another node (within {tol:e} m) \
                 and are not merged, e.g. nodes {} and {} at {position:?}: the elements on \
                 either side share no face, so the mesh is cut there. Make the geometry \
                 coherent in Gmsh (Geometry.AutoCoherence, or Coherence), or import with \
                 ImportOptions {{ merge_coincident: true, .. }}",
                tags.0, tags.1
            ),
        }
    }
}

/// For each point `i` (of `points`, stride 3, only the first `d` components used) that is
/// `active`, the index of the first earlier active point within `tol`, or `i` itself.
pub(super) fn representatives(
    points: &[[f64; 3]],
    active: &[bool],
    d: usize,
    tol: f64,
) -> Vec<usize> {
    let mut rep: Vec<usize> = (0..points.len()).collect();
    if !(tol > 0.0 && tol.is_finite()) {
        return rep;
    }
    // Hash grid with cells of size `tol`: a point within `tol` lies in a neighbouring cell.
    // Saturating casts keep absurd coordinates from overflowing (such points only share
    // cells more often; distances are still checked exactly).
    let cell = |p: &[f64; 3]| {
        let mut c = [0i64; 3];
        for k in 0..d {
            c[k] = (p[k] / tol).floor() as i64;
        }
        c
    };
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let offsets: Vec<[i64; 3]> = (0..3i64.pow(d as u32))
        .map(|mut m| {
            let mut o = [0i64; 3];
            for v in o.iter_mut().take(d) {
                *v = m % 3 - 1;
                m /= 3;
            }
            o
        })
        .collect();
    for i in (0..points.len()).filter(|&i| active[i]) {
        let c = cell(&points[i]);
        'search: for o in &offsets {
            let key = [
                c[0].saturating_add(o[0]),
                c[1].saturating_add(o[1]),
                c[2].saturating_add(o[2]),
            ];
            for &j in grid.get(&key).into_iter().flatten() {
                let d2: f64 = (0..d).map(|k| (points[i][k] - points[j][k]).powi(2)).sum();
                if d2 <= tol * tol {
                    rep[i] = rep[j];
                    break 'search;
                }
            }
        }
        grid.entry(c).or_default().push(i);
    }
    rep
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_coincident_points_only() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0 + 1e-12, 0.0, 0.0],
            [1.0, 1e-6, 0.0],
            [0.0, 0.0, 0.0],
        ];
        let rep = representatives(&pts, &[true, true, true, true, false], 2, 1e-9);
        assert_eq!(rep, vec![0, 1, 1, 3, 4]);
        // A zero tolerance merges nothing.
        assert_eq!(
            representatives(&pts, &[true; 5], 2, 0.0),
            vec![0, 1, 2, 3, 4]
        );
    }
}
