//! The contact physics' own snapshot state: the candidate list of every element and the
//! pair histories, and the checks a restore makes before accepting them.
//!
//! Layout, little-endian: the number of lists (`u64`: 0 before the first step, else one
//! per element), then per element its list length (`u64`), its partners (`u32` each)
//! and `n_state` history values (`f64`) per partner.
//!
//! A restore accepts only what a broad-phase build can produce: one list per element
//! (or none), every partner an element of the mesh other than the element itself, each
//! list strictly increasing, the lists symmetric (f lists e when e lists f), exactly
//! `n_state` values per pair and no byte left over. History values are not constrained
//! (they index nothing; a non-finite one would stop the run through the watchdog).

use pcdc_compute::ComputeError;

/// Candidate lists and pair histories, in element order.
pub(crate) type ContactState = (Vec<Vec<u32>>, Vec<Vec<f64>>);

fn corrupt(what: String) -> ComputeError {
    ComputeError::SnapshotCorrupt(format!("contact state: {what}"))
}

/// Encodes the lists and histories (a history shorter than its list is padded with 0).
pub(crate) fn encode(cand: &[Vec<u32>], slips: &[Vec<f64>], n_state: usize) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&(cand.len() as u64).to_le_bytes());
    let empty = Vec::new();
    for (e, list) in cand.iter().enumerate() {
        let slip = slips.get(e).unwrap_or(&empty);
        out.extend_from_slice(&(list.len() as u64).to_le_bytes());
        for f in list {
            out.extend_from_slice(&f.to_le_bytes());
        }
        for k in 0..list.len() * n_state {
            out.extend_from_slice(&slip.get(k).copied().unwrap_or(0.0).to_le_bytes());
        }
    }
    out
}

/// A little-endian reader that reports running out of bytes as an error.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], ComputeError> {
        let mut b = [0; N];
        let s = self
            .bytes
            .get(self.pos..)
            .and_then(|r| r.get(..N))
            .ok_or_else(|| corrupt(format!("truncated at byte {}", self.pos)))?;
        b.copy_from_slice(s);
        self.pos += N;
        Ok(b)
    }

    fn left(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }
}

/// Decodes and checks a state for a mesh of `n_elements` elements and a law with
/// `n_state` history values per pair.
pub(crate) fn decode(
    bytes: &[u8],
    n_elements: usize,
    n_state: usize,
) -> Result<ContactState, ComputeError> {
    let mut r = Reader { bytes, pos: 0 };
    let count = u64::from_le_bytes(r.take()?);
    if count != 0 && count != n_elements as u64 {
        return Err(corrupt(format!(
            "{count} candidate lists for a mesh of {n_elements} elements"
        )));
    }
    let pair_bytes = 4 + 8 * n_state as u64;
    let (mut cand, mut slips) = (Vec::new(), Vec::new());
    for e in 0..count as usize {
        let len = u64::from_le_bytes(r.take()?);
        if len >= n_elements as u64 || len * pair_bytes > r.left() as u64 {
            return Err(corrupt(format!(
                "element {e} has {len} candidates (mesh of {n_elements} elements, {} bytes left)",
                r.left()
            )));
        }
        let mut list = Vec::with_capacity(len as usize);
        for _ in 0..len {
            let f = u32::from_le_bytes(r.take()?);
            if f as usize >= n_elements || f as usize == e || list.last().is_some_and(|&l| l >= f) {
                return Err(corrupt(format!(
                    "element {e}: candidate {f} is out of range (mesh of {n_elements} elements), the element itself, or out of order"
                )));
            }
            list.push(f);
        }
        let slip = (0..len as usize * n_state)
            .map(|_| r.take().map(f64::from_le_bytes))
            .collect::<Result<Vec<f64>, _>>()?;
        cand.push(list);
        slips.push(slip);
    }
    if r.left() != 0 {
        return Err(corrupt(format!("{} bytes left over", r.left())));
    }
    for (e, list) in cand.iter().enumerate() {
        if let Some(&f) = list
            .iter()
            .find(|&&f| cand[f as usize].binary_search(&(e as u32)).is_err())
        {
            return Err(corrupt(format!(
                "element {e} lists {f} as a candidate but {f} does not list {e}"
            )));
        }
    }
    Ok((cand, slips))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three elements, all candidates of each other, two history values per pair.
    fn lists() -> ContactState {
        let cand = vec![vec![1, 2], vec![0, 2], vec![0, 1]];
        let slips = cand
            .iter()
            .map(|l| (0..2 * l.len()).map(|k| k as f64 * 0.5).collect())
            .collect();
        (cand, slips)
    }

    #[test]
    fn round_trip() {
        let (cand, slips) = lists();
        let bytes = encode(&cand, &slips, 2);
        assert_eq!(decode(&bytes, 3, 2).unwrap(), (cand, slips));
        assert_eq!(decode(&encode(&[], &[], 2), 3, 2).unwrap().0.len(), 0);
    }

    #[test]
    fn bad_states_are_errors() {
        let (cand, slips) = lists();
        type Edit = fn(&mut Vec<Vec<u32>>);
        let edits: [(&str, Edit); 4] = [
            ("out of range", |c| c[0][1] = 7),
            ("itself", |c| c[0][0] = 0),
            ("order", |c| c[0] = vec![2, 1]),
            ("does not list", |c| {
                c[1] = vec![2];
                c[0] = vec![1, 2];
            }),
        ];
        for (expect, edit) in edits {
            let mut c = cand.clone();
            edit(&mut c);
            let e = decode(&encode(&c, &slips, 2), 3, 2)
                .unwrap_err()
                .to_string();
            assert!(e.contains(expect), "{expect}: {e}");
        }
        let bytes = encode(&cand, &slips, 2);
        // Another mesh size, another history length, truncation, extra bytes.
        assert!(decode(&bytes, 4, 2).is_err());
        assert!(decode(&bytes, 3, 1).is_err());
        assert!(decode(&bytes, 3, 3).is_err());
        for len in 0..bytes.len() {
            assert!(decode(&bytes[..len], 3, 2).is_err(), "{len}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode(&longer, 3, 2).is_err());
        // A huge list length is refused before anything is allocated.
        let mut huge = bytes.clone();
        huge[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(decode(&huge, 3, 2).is_err());
    }
}
