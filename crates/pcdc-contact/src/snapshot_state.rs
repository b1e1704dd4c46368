//! The checks a restore makes on the contact physics' state fields before accepting
//! them (the values come from a file; layout in the [`crate::physics`] module docs).
//!
//! A restore accepts only what a broad-phase build can produce: per element a count n,
//! an integer in `0..=capacity`; the first n candidates integers naming an element of
//! the mesh other than the element itself, strictly increasing; the lists symmetric (f
//! lists e when e lists f); and every candidate and history entry past the list zero.
//! History values of listed pairs are not constrained (they index nothing; a non-finite
//! one would stop the run through the watchdog). Reference positions are not
//! constrained either (a NaN one forces a rebuild).

use pcdc_compute::ComputeError;

fn corrupt(what: String) -> ComputeError {
    ComputeError::SnapshotCorrupt(format!("contact state: {what}"))
}

/// The list length of element `e`, checked.
fn count_of(count: &[f64], e: usize, capacity: usize) -> Result<usize, ComputeError> {
    let n = count[e];
    if !(n >= 0.0 && n <= capacity as f64 && n.fract() == 0.0) {
        return Err(corrupt(format!(
            "element {e}: candidate count {n} is not an integer in 0..={capacity}"
        )));
    }
    Ok(n as usize)
}

/// Checks the count, candidate and history fields of a mesh of `n_elements` elements,
/// `capacity` candidates per element and `stride` history values per pair.
pub(crate) fn check(
    count: &[f64],
    cand: &[f64],
    hist: &[f64],
    n_elements: usize,
    capacity: usize,
    stride: usize,
) -> Result<(), ComputeError> {
    if count.len() != n_elements
        || cand.len() != n_elements * capacity
        || hist.len() != n_elements * capacity * stride
    {
        return Err(corrupt(format!(
            "{} counts, {} candidates and {} history values for {n_elements} elements of \
             capacity {capacity} with {stride} values per pair",
            count.len(),
            cand.len(),
            hist.len()
        )));
    }
    for e in 0..n_elements {
        let n = count_of(count, e, capacity)?;
        let row = &cand[e * capacity..(e + 1) * capacity];
        let mut last = -1.0;
        for &f in &row[..n] {
            if !(f >= 0.0 && f < n_elements as f64 && f.fract() == 0.0) {
                return Err(corrupt(format!(
                    "element {e}: candidate {f} is out of range (mesh of {n_elements} elements)"
                )));
            }
            if f as usize == e {
                return Err(corrupt(format!("element {e} lists itself as a candidate")));
            }
            if f <= last {
                return Err(corrupt(format!(
                    "element {e}: candidate {f} after {last} is out of order"
                )));
            }
            last = f;
        }
        let hrow = &hist[e * capacity * stride..(e + 1) * capacity * stride];
        if row[n..]
            .iter()
            .chain(&hrow[n * stride..])
            .any(|&x| x != 0.0)
        {
            return Err(corrupt(format!(
                "element {e}: non-zero candidate or history entry past its {n} candidates"
            )));
        }
    }
    for e in 0..n_elements {
        let n = count[e] as usize;
        for &f in &cand[e * capacity..e * capacity + n] {
            let f = f as usize;
            let m = count[f] as usize;
            let other = &cand[f * capacity..f * capacity + m];
            if other
                .binary_search_by(|x| x.total_cmp(&(e as f64)))
                .is_err()
            {
                return Err(corrupt(format!(
                    "element {e} lists {f} as a candidate but {f} does not list {e}"
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three elements, all candidates of each other, capacity 3, two history values per
    /// pair: (count, candidates, history).
    fn state() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let cand = vec![1.0, 2.0, 0.0, 0.0, 2.0, 0.0, 0.0, 1.0, 0.0];
        let mut hist = vec![0.0; 18];
        for e in 0..3 {
            for k in 0..4 {
                hist[6 * e + k] = 0.5 * (k + 1) as f64;
            }
        }
        (vec![2.0; 3], cand, hist)
    }

    #[test]
    fn valid_state_passes() {
        let (n, c, h) = state();
        check(&n, &c, &h, 3, 3, 2).unwrap();
        // Before the first build: all zero.
        check(&[0.0; 3], &[0.0; 9], &[0.0; 18], 3, 3, 2).unwrap();
    }

    #[test]
    fn bad_states_are_errors() {
        type Edit = fn(&mut Vec<f64>, &mut Vec<f64>, &mut Vec<f64>);
        let edits: [(&str, Edit); 9] = [
            ("out of range", |_, c, _| c[1] = 7.0),
            ("out of range", |_, c, _| c[1] = 1.5),
            ("out of range", |_, c, _| c[1] = f64::NAN),
            ("itself", |_, c, _| c[0] = 0.0),
            ("order", |_, c, _| c.swap(0, 1)),
            ("does not list", |n, c, h| {
                n[1] = 1.0;
                c[3] = 2.0;
                c[4] = 0.0;
                h[8..12].fill(0.0);
            }),
            ("count", |n, _, _| n[2] = 4.0),
            ("count", |n, _, _| n[2] = -1.0),
            ("past its", |_, _, h| h[5] = 1.0),
        ];
        for (expect, edit) in edits {
            let (mut n, mut c, mut h) = state();
            edit(&mut n, &mut c, &mut h);
            let e = check(&n, &c, &h, 3, 3, 2).unwrap_err().to_string();
            assert!(
                e.contains("contact state") && e.contains(expect),
                "{expect}: {e}"
            );
        }
        // Wrong lengths.
        let (n, c, h) = state();
        assert!(check(&n, &c, &h, 3, 3, 3).is_err());
        assert!(check(&n, &c, &h[1..], 3, 3, 2).is_err());
        assert!(check(&n[1..], &c, &h, 3, 3, 2).is_err());
    }
}
