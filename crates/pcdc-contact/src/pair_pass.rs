//! The CPU pair pass: every touching pair of candidates evaluated once per step, its two
//! force shares summed in a fixed order whatever the thread count (see [`pair_pass`]).

use rayon::prelude::*;

/// Elements per task of the pair pass (the unit of its deterministic order).
pub(crate) const PAIR_BLOCK: usize = 256;

/// Pair histories up to this many values are compared on the stack.
const SMALL_HISTORY: usize = 4;

/// The pair pass: every touching pair evaluated once, by its lower-index element (the
/// contactor), and its two shares summed in a fixed order whatever the thread count.
/// Element e's `S` slot values are zeroed, then receive the contactor shares of e's
/// pairs with higher-index candidates (list order), then the target shares of the pairs
/// whose contactor is a lower-index element (contactors in ascending order). `eval`
/// returns a pair's (contactor, target) shares, or `None` when it exerts no force.
/// Sealed elements are skipped; their slots are zeroed only when `zero_sealed` (the
/// sealed set changed), as nothing else writes them.
///
/// A pair's history lives in both elements' rows (the GPU kernel, one invocation per
/// element, evaluates each pair from both sides and keeps both copies in step): the
/// contactor's copy is the one updated here, and a change is copied into the target's
/// row afterwards, so that both copies stay equal and snapshots mean the same on both
/// backends.
#[allow(clippy::too_many_arguments)]
pub(crate) fn pair_pass<'a, const S: usize, L, E>(
    slots: &mut [f64],
    hist: &mut [f64],
    row: usize,
    lists: &L,
    sealed: &[bool],
    zero_sealed: bool,
    shares: &mut Vec<Vec<(u32, [f64; S])>>,
    mirrors: &mut Vec<Vec<f64>>,
    eval: &E,
    stride: usize,
    ns: usize,
) where
    L: Fn(usize) -> &'a [f64] + Sync,
    E: Fn(usize, usize, &mut [f64]) -> Option<([f64; S], [f64; S])> + Sync,
{
    let ne = slots.len() / S;
    let blocks = ne.div_ceil(PAIR_BLOCK);
    shares.resize_with(blocks, Vec::new);
    mirrors.resize_with(blocks, Vec::new);
    slots
        .par_chunks_mut(S * PAIR_BLOCK)
        .zip(hist.par_chunks_mut(row * PAIR_BLOCK))
        .zip(shares.par_iter_mut().zip(mirrors.par_iter_mut()))
        .enumerate()
        .for_each(|(b, ((slots, hist), (out, mirror)))| {
            out.clear();
            mirror.clear();
            for (i, (slot, slip)) in slots
                .chunks_exact_mut(S)
                .zip(hist.chunks_exact_mut(row))
                .enumerate()
            {
                let e = b * PAIR_BLOCK + i;
                // Inside intact rock nothing can touch (see the `exclusion` module).
                if sealed.get(e).copied().unwrap_or(false) {
                    if zero_sealed {
                        slot.fill(0.0);
                    }
                    continue;
                }
                slot.fill(0.0);
                let list = lists(e);
                // Lists are sorted: the higher-index candidates are a suffix.
                let from = list.partition_point(|&f| f as usize <= e);
                for (k, &f) in list.iter().enumerate().skip(from) {
                    let state = &mut slip[k * stride..k * stride + ns];
                    // The history before (on the stack for the usual few values), to
                    // record it only if the pair changes it.
                    // (Element-wise loops: a run-time length would call memcpy.)
                    let mark = mirror.len();
                    let mut before = [0.0; SMALL_HISTORY];
                    if ns <= SMALL_HISTORY {
                        for (b, &x) in before.iter_mut().zip(&*state) {
                            *b = x;
                        }
                    } else {
                        mirror.extend_from_slice(state);
                    }
                    let force = eval(e, f as usize, state);
                    let same = if ns <= SMALL_HISTORY {
                        before.iter().zip(&*state).all(|(b, x)| b == x)
                    } else {
                        let same = mirror[mark..].iter().zip(&*state).all(|(b, x)| b == x);
                        mirror.truncate(mark);
                        same
                    };
                    if !same {
                        mirror.push(f);
                        mirror.push(e as f64);
                        for &x in &*state {
                            mirror.push(x);
                        }
                    }
                    if let Some((c, t)) = force {
                        for (s, v) in slot.iter_mut().zip(c) {
                            *s += v;
                        }
                        out.push((f as u32, t));
                    }
                }
            }
        });
    // The target shares, contactors in ascending order (blocks in order, elements in
    // order within a block). Serial, but one addition per touching pair.
    for out in shares.iter() {
        for (f, t) in out {
            let f = *f as usize;
            for (s, v) in slots[f * S..(f + 1) * S].iter_mut().zip(t) {
                *s += v;
            }
        }
    }
    // The changed histories into the targets' rows (where the target lists the
    // contactor: candidate lists are symmetric).
    for m in mirrors.iter() {
        for entry in m.chunks_exact(2 + ns) {
            let (f, e) = (entry[0] as usize, entry[1]);
            if let Ok(k) = lists(f).binary_search_by(|x| x.total_cmp(&e)) {
                hist[f * row + k * stride..f * row + k * stride + ns].copy_from_slice(&entry[2..]);
            }
        }
    }
}

/// Whether two boxes (lows then highs, `d` components each) are apart; touching counts
/// as apart, exactly the first test of [`triangle_pair_force`] and [`tet_pair_force`],
/// whose force is then zero.
#[inline]
pub(crate) fn boxes_apart(a: &[f64], b: &[f64], d: usize) -> bool {
    (0..d).any(|k| a[d + k] <= b[k] || b[d + k] <= a[k])
}
