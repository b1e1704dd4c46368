// Broad phase, step 5b (one invocation per element, only when rebuilding): the sorted
// list of elements whose boxes overlap this one's and that share no node with it (the
// same test as the CPU's `grid_candidates` / `grid_candidates_3d`), from the buckets of
// the 3 x 3 (2D) or 3 x 3 x 3 (3D) cells around its box centre; then the pair history
// of partners that were already candidates, and zeros past the new list where the old
// one was longer (the fields hold zeros past every list, as on the CPU).
fn shares_node(e: u32, f: u32) -> bool {
    for (var a = 0u; a < NPE; a = a + 1u) {
        let n = conn[NPE * f + a];
        for (var b = 0u; b < NPE; b = b + 1u) {
            if n == conn[NPE * e + b] {
                return true;
            }
        }
    }
    return false;
}

fn overlaps(e: u32, f: u32) -> bool {
    for (var k = 0u; k < D; k = k + 1u) {
        if boxes[2u * D * f + k] > boxes[2u * D * e + D + k]
            || boxes[2u * D * e + k] > boxes[2u * D * f + D + k] {
            return false;
        }
    }
    return true;
}

fn kernel(e: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    let c = centre_cell(e, grid[0]);
    // Neighbouring cells along z: none in 2D (c.z = 0 there).
    let rz = i32(D) - 2;
    var seen: array<u32, NCELLS>;
    var nseen = 0u;
    var list: array<u32, CAP>;
    var n = 0u;
    var overflow = false;
    for (var dz = -rz; dz <= rz; dz = dz + 1) {
        for (var dy = -1; dy <= 1; dy = dy + 1) {
            for (var dx = -1; dx <= 1; dx = dx + 1) {
                let b = bucket(c + vec3<i32>(dx, dy, dz));
                // Two cells may hash to one bucket: visit each bucket once.
                var dup = false;
                for (var s = 0u; s < nseen; s = s + 1u) {
                    dup = dup || seen[s] == b;
                }
                if dup {
                    continue;
                }
                seen[nseen] = b;
                nseen = nseen + 1u;
                for (var j = bucket_start[b]; j < bucket_start[b + 1u]; j = j + 1u) {
                    let f = bucket_items[j];
                    if f == e || !overlaps(e, f) || shares_node(e, f) {
                        continue;
                    }
                    if n == CAP {
                        overflow = true;
                        continue;
                    }
                    // Insertion into the sorted list.
                    var at = n;
                    while at > 0u && list[at - 1u] > f {
                        list[at] = list[at - 1u];
                        at = at - 1u;
                    }
                    list[at] = f;
                    n = n + 1u;
                }
            }
        }
    }
    if overflow {
        atomicMin(&status[2], OVERFLOW_CODE);
        atomicMin(&status[3], e);
    }
    let n_old = ncand_old[e];
    for (var k = 0u; k < n; k = k + 1u) {
        let f = list[k];
        cand[e * CAP + k] = Real(f);
        // Binary search of the partner in the old (sorted) list.
        var lo = 0u;
        var hi = n_old;
        while lo < hi {
            let mid = (lo + hi) / 2u;
            if cand_old[e * CAP + mid] < f {
                lo = mid + 1u;
            } else {
                hi = mid;
            }
        }
        let found = lo < n_old && cand_old[e * CAP + lo] == f;
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            var v = Real(0.0);
            if found {
                v = hist_old[(e * CAP + lo) * NSTATE + s];
            }
            hist[(e * CAP + k) * NSTATE + s] = v;
        }
    }
    for (var k = n; k < n_old; k = k + 1u) {
        cand[e * CAP + k] = 0.0;
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            hist[(e * CAP + k) * NSTATE + s] = 0.0;
        }
    }
    ncand[e] = Real(n);
}
