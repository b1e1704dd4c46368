//! The elements that can touch anything this step (CPU backend): the unsealed ones (see
//! the `exclusion` module) and their nodes, re-derived only when the set of broken
//! bonds changes, so that intact rock costs nothing per step beyond one scan of the
//! broken flags.
//!
//! Only the nodes of unsealed elements are watched for the candidate lists' rebuild:
//! a pair with a sealed element skips the narrow phase whatever its list holds, and a
//! pair of unsealed elements has every node watched since the last build (an element
//! that unseals is watched from then on against the positions of that build), so a
//! list in use is always complete.

use pcdc_mesh::{Dim, Mesh};
use rayon::prelude::*;

use crate::exclusion::BondedRegions;

/// Faces per block of the broken-flags scan (a block of zeros is one vectorised test).
const SCAN_BLOCK: usize = 64;

/// Sealed flags and watched nodes, with the broken faces they were derived from.
#[derive(Debug, Default)]
pub(crate) struct ActiveSet {
    /// The broken faces (sorted) the flags were derived from; `None` before the first step.
    seen: Option<Vec<u32>>,
    /// The null elements (sorted) the flags were derived from.
    seen_null: Vec<u32>,
    /// Per element: sealed (nothing can touch it).
    pub sealed: Vec<bool>,
    /// The nodes of the unsealed elements, sorted and unique.
    pub nodes: Vec<u32>,
}

impl ActiveSet {
    /// Brings the vertex flags of `regions`, the sealed flags and the watched nodes up to
    /// date with `broken` (per face, non-zero once broken); without regions nothing is
    /// sealed. Bonds only break, but a restored snapshot may change them any way, so the
    /// whole set of broken faces is compared, not a count. Returns whether the set was
    /// re-derived (always on the first call).
    /// A null element (`null[e] != 0`, the null model of excavation) is sealed too.
    pub fn refresh<D: Dim>(
        &mut self,
        regions: Option<&mut BondedRegions>,
        broken: &[f64],
        null: &[f64],
        mesh: &Mesh<D>,
    ) -> bool {
        if self.seen.as_deref().is_some_and(|s| same_broken(s, broken))
            && same_broken(&self.seen_null, null)
        {
            return false;
        }
        let ne = mesh.n_elements();
        match regions {
            Some(r) => {
                r.update(broken);
                let r = &*r;
                self.sealed.resize(ne, false);
                self.sealed
                    .par_iter_mut()
                    .enumerate()
                    .with_min_len(4096)
                    .for_each(|(e, s)| *s = r.sealed(e));
            }
            None => {
                self.sealed.clear();
                self.sealed.resize(ne, false);
            }
        }
        for (e, s) in self.sealed.iter_mut().enumerate() {
            *s |= null.get(e).is_some_and(|&v| v != 0.0);
        }
        self.seen_null = broken_faces(null);
        self.nodes.clear();
        for e in (0..ne).filter(|&e| !self.sealed[e]) {
            self.nodes.extend_from_slice(mesh.element(e));
        }
        self.nodes.sort_unstable();
        self.nodes.dedup();
        self.seen = Some(broken_faces(broken));
        true
    }
}

/// The faces with a non-zero broken flag, in order.
fn broken_faces(broken: &[f64]) -> Vec<u32> {
    (0..broken.len())
        .filter(|&f| broken[f] != 0.0)
        .map(|f| f as u32)
        .collect()
}

/// Whether the faces with a non-zero flag in `broken` are exactly `seen` (sorted,
/// unique). Runs every step, so it is parallel (a serial scan of every face would be a
/// serial section of the step) and allocates nothing: each block of faces compares its
/// broken faces, in order, with its own segment of `seen` (found by binary search), and
/// a block of zeros costs one vectorised test per `SCAN_BLOCK` faces.
fn same_broken(seen: &[u32], broken: &[f64]) -> bool {
    const BLOCK: usize = SCAN_BLOCK * 64;
    let in_range = seen.last().is_none_or(|&f| (f as usize) < broken.len());
    in_range
        && broken.par_chunks(BLOCK).enumerate().all(|(b, block)| {
            let lo = b * BLOCK;
            let start = seen.partition_point(|&f| (f as usize) < lo);
            let end = seen.partition_point(|&f| (f as usize) < lo + block.len());
            let mut expect = seen[start..end].iter();
            let matches = block.chunks(SCAN_BLOCK).enumerate().all(|(c, chunk)| {
                !chunk.iter().fold(false, |any, &x| any | (x != 0.0))
                    || (0..chunk.len())
                        .filter(|&i| chunk[i] != 0.0)
                        .all(|i| expect.next() == Some(&((lo + c * SCAN_BLOCK + i) as u32)))
            });
            matches && expect.next().is_none()
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn broken_sets_compare_exactly() {
        let mut broken = vec![0.0; 300];
        assert!(same_broken(&[], &broken));
        broken[70] = 1.0;
        assert!(!same_broken(&[], &broken));
        assert!(same_broken(&[70], &broken));
        broken[299] = 1.0;
        assert!(!same_broken(&[70], &broken));
        assert_eq!(broken_faces(&broken), vec![70, 299]);
        assert!(same_broken(&[70, 299], &broken));
        // Same count, other faces (a restored snapshot): a change.
        assert!(!same_broken(&[71, 299], &broken));
        broken[70] = f64::NAN;
        assert!(
            same_broken(&[70, 299], &broken),
            "NaN counts as broken, as in the flags"
        );
        // Across the parallel scan's blocks.
        let mut broken = vec![0.0; 10_000];
        broken[4095] = 1.0;
        broken[4096] = 1.0;
        broken[9999] = 1.0;
        assert!(same_broken(&[4095, 4096, 9999], &broken));
        assert!(!same_broken(&[4095, 9999], &broken));
        assert!(!same_broken(&[4095, 4096, 9998], &broken));
        assert!(!same_broken(&[4095, 4096, 9999, 10_000], &broken));
    }
}
