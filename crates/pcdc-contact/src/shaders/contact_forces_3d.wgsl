// Contact forces between tetrahedra (one invocation per element): the element walks its
// sorted candidate list, evaluates every pair in canonical order (lower index as
// contactor) with the contact law, and keeps the share that lands on its own four
// nodes: the arithmetic of the 3D branch of `Contact::compute_forces` and of
// `apply_model3` on the CPU, in the same order.
fn node_x(n: u32, k: u32) -> Real {
    return coords[n * D + k] + disp[n * D + k];
}

fn element_xyz(e: u32) -> Tet {
    var t: Tet;
    for (var a = 0u; a < 4u; a = a + 1u) {
        let n = conn[4u * e + a];
        t[a] = V3(node_x(n, 0u), node_x(n, 1u), node_x(n, 2u));
    }
    return t;
}

fn mean_edge3(t: Tet) -> Real {
    var s = Real(0.0);
    for (var a = 0u; a < 4u; a = a + 1u) {
        for (var b = a + 1u; b < 4u; b = b + 1u) {
            let d = sub3(t[b], t[a]);
            s = s + sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
    }
    return s / 6.0;
}

// The bond face between elements e and f (0xffffffff when not bonded).
fn bond_face(e: u32, f: u32) -> u32 {
    var lo = bond_ptr[e];
    var hi = bond_ptr[e + 1u];
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if bond_list[2u * mid] < f {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    if lo < bond_ptr[e + 1u] && bond_list[2u * lo] == f {
        return bond_list[2u * lo + 1u];
    }
    return 0xffffffffu;
}

fn weights3(forces: Tet) -> L4 {
    var w: L4;
    for (var a = 0u; a < 4u; a = a + 1u) {
        let f = forces[a];
        w[a] = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    }
    let sum = w[0] + w[1] + w[2] + w[3];
    for (var a = 0u; a < 4u; a = a + 1u) {
        if sum > 0.0 {
            w[a] = w[a] / sum;
        } else {
            w[a] = 0.25;
        }
    }
    return w;
}

fn weighted_velocity3(e: u32, w: L4) -> V3 {
    var v = V3(0.0, 0.0, 0.0);
    for (var a = 0u; a < 4u; a = a + 1u) {
        let n = conn[4u * e + a];
        for (var d = 0u; d < 3u; d = d + 1u) {
            v[d] = v[d] + w[a] * vel[n * D + d];
        }
    }
    return v;
}

fn separate(state: ptr<function, ContactState>) {
    for (var s = 0u; s < NSTATE; s = s + 1u) {
        (*state)[s] = 0.0;
    }
}

// The contact law on a pair's normal forces (see `apply_model3` on the CPU).
fn apply_model3(pair: ptr<function, PairForce>, c: u32, t: u32, h: Real, state: ptr<function, ContactState>) {
    var fc: V3;
    for (var d = 0u; d < 3u; d = d + 1u) {
        fc[d] = (*pair).c[0][d] + (*pair).c[1][d] + (*pair).c[2][d] + (*pair).c[3][d];
    }
    let fn_mag = sqrt(fc[0] * fc[0] + fc[1] * fc[1] + fc[2] * fc[2]);
    if fn_mag == 0.0 {
        // Separated: the history restarts.
        separate(state);
        return;
    }
    let n = V3(fc[0] / fn_mag, fc[1] / fn_mag, fc[2] / fn_mag);
    let wc = weights3((*pair).c);
    let wt = weights3((*pair).t);
    let vc = weighted_velocity3(c, wc);
    let vt = weighted_velocity3(t, wt);
    let rel = sub3(vc, vt);
    let vn = rel[0] * n[0] + rel[1] * n[1] + rel[2] * n[2];
    let tv = V3(rel[0] - vn * n[0], rel[1] - vn * n[1], rel[2] - vn * n[2]);
    let vt_mag = sqrt(tv[0] * tv[0] + tv[1] * tv[1] + tv[2] * tv[2]);
    let area = h * h;
    let s_try = fn_mag / area;
    let r = call_contact_model(MODEL_KIND, s_try, vt_mag * p_dt(), h, state, MODEL_AT, c, t);
    if r.normal != s_try {
        let scale = r.normal / s_try;
        for (var a = 0u; a < 4u; a = a + 1u) {
            for (var k = 0u; k < 3u; k = k + 1u) {
                (*pair).c[a][k] = (*pair).c[a][k] * scale;
                (*pair).t[a][k] = (*pair).t[a][k] * scale;
            }
        }
    }
    if r.shear != 0.0 && vt_mag > 0.0 {
        let ft = r.shear * area;
        let tang = V3(tv[0] / vt_mag, tv[1] / vt_mag, tv[2] / vt_mag);
        for (var a = 0u; a < 4u; a = a + 1u) {
            for (var d = 0u; d < 3u; d = d + 1u) {
                (*pair).c[a][d] = (*pair).c[a][d] + wc[a] * ft * tang[d];
                (*pair).t[a][d] = (*pair).t[a][d] - wt[a] * ft * tang[d];
            }
        }
    }
}

// True when every force of the pair is zero (the CPU's `pair == PairForce3::default()`).
fn is_zero(pair: PairForce) -> bool {
    for (var a = 0u; a < 4u; a = a + 1u) {
        for (var d = 0u; d < 3u; d = d + 1u) {
            if pair.c[a][d] != 0.0 || pair.t[a][d] != 0.0 {
                return false;
            }
        }
    }
    return true;
}

fn kernel(e: u32) {
    var own: Tet;
    let me = element_xyz(e);
    var n = min(u32(ncand[e]), CAP);
    // Inside intact rock nothing can touch (regions.wgsl).
    if sealed(e) {
        n = 0u;
    }
    for (var k = 0u; k < n; k = k + 1u) {
        let f = u32(cand[e * CAP + k]);
        if sealed(f) || share_intact_vertex(e, f) {
            continue;
        }
        // Bonded neighbours interact through their joint until it breaks.
        let face = bond_face(e, f);
        if face != 0xffffffffu {
            if broken[face] == 0.0 {
                continue;
            }
        }
        let other = element_xyz(f);
        var ci = e;
        var ti = f;
        var c = me;
        var t = other;
        if f < e {
            ci = f;
            ti = e;
            c = other;
            t = me;
        }
        var pair = tet_pair_force(c, t, pair_penalty(ci, ti, MODEL_AT));
        var state: ContactState;
        let base = (e * CAP + k) * NSTATE;
        if is_zero(pair) {
            // Not touching (most candidates): no force, fresh history.
            for (var s = 0u; s < NSTATE; s = s + 1u) {
                hist[base + s] = 0.0;
            }
            continue;
        }
        let h = 0.5 * (mean_edge3(c) + mean_edge3(t));
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            state[s] = hist[base + s];
        }
        apply_model3(&pair, ci, ti, h, &state);
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            hist[base + s] = state[s];
        }
        var share = pair.t;
        if e < f {
            share = pair.c;
        }
        for (var a = 0u; a < 4u; a = a + 1u) {
            for (var d = 0u; d < 3u; d = d + 1u) {
                own[a][d] = own[a][d] + share[a][d];
            }
        }
    }
    for (var a = 0u; a < 4u; a = a + 1u) {
        let slot = SLOT_FIRST + 4u * e + a;
        for (var d = 0u; d < 3u; d = d + 1u) {
            slots[slot * D + d] = own[a][d];
        }
    }
}
