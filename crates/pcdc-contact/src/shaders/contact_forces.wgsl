// Contact forces (one invocation per element): the element walks its sorted candidate
// list, evaluates every pair in canonical order (lower index as contactor) with the
// contact law, and keeps the share that lands on its own three nodes: the arithmetic of
// `Contact::compute_forces` and `apply_model` on the CPU, in the same order.
fn node_x(n: u32, k: u32) -> Real {
    return coords[n * D + k] + disp[n * D + k];
}

fn element_xy(e: u32) -> Tri {
    var t: Tri;
    for (var a = 0u; a < 3u; a = a + 1u) {
        let n = conn[3u * e + a];
        t[a] = array<Real, 2>(node_x(n, 0u), node_x(n, 1u));
    }
    return t;
}

fn mean_edge(t: Tri) -> Real {
    var s = Real(0.0);
    for (var a = 0u; a < 3u; a = a + 1u) {
        let b = (a + 1u) % 3u;
        let dx = t[b][0] - t[a][0];
        let dy = t[b][1] - t[a][1];
        s = s + sqrt(dx * dx + dy * dy);
    }
    return s / 3.0;
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

fn weights(forces: Tri) -> array<Real, 3> {
    var w: array<Real, 3>;
    for (var a = 0u; a < 3u; a = a + 1u) {
        w[a] = sqrt(forces[a][0] * forces[a][0] + forces[a][1] * forces[a][1]);
    }
    let sum = w[0] + w[1] + w[2];
    for (var a = 0u; a < 3u; a = a + 1u) {
        if sum > 0.0 {
            w[a] = w[a] / sum;
        } else {
            w[a] = 1.0 / 3.0;
        }
    }
    return w;
}

fn weighted_velocity(e: u32, w: array<Real, 3>) -> array<Real, 2> {
    var v = array<Real, 2>(0.0, 0.0);
    for (var a = 0u; a < 3u; a = a + 1u) {
        let n = conn[3u * e + a];
        for (var d = 0u; d < 2u; d = d + 1u) {
            v[d] = v[d] + w[a] * vel[n * D + d];
        }
    }
    return v;
}

// The contact law on a pair's normal forces (see `apply_model` on the CPU).
fn apply_model(pair: ptr<function, PairForce>, c: u32, t: u32, h: Real, state: ptr<function, ContactState>) {
    let fc = array<Real, 2>((*pair).c[0][0] + (*pair).c[1][0] + (*pair).c[2][0],
                            (*pair).c[0][1] + (*pair).c[1][1] + (*pair).c[2][1]);
    let fn_mag = sqrt(fc[0] * fc[0] + fc[1] * fc[1]);
    if fn_mag == 0.0 {
        // Separated: the history restarts.
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            (*state)[s] = 0.0;
        }
        return;
    }
    let n = array<Real, 2>(fc[0] / fn_mag, fc[1] / fn_mag);
    let tang = array<Real, 2>(-n[1], n[0]);
    let wc = weights((*pair).c);
    let wt = weights((*pair).t);
    let vc = weighted_velocity(c, wc);
    let vt = weighted_velocity(t, wt);
    let v_rel = (vc[0] - vt[0]) * tang[0] + (vc[1] - vt[1]) * tang[1];
    let s_try = fn_mag / h;
    let r = call_contact_model(MODEL_KIND, s_try, v_rel * p_dt(), h, state, MODEL_AT, c, t);
    if r.normal != s_try {
        let scale = r.normal / s_try;
        for (var a = 0u; a < 3u; a = a + 1u) {
            for (var k = 0u; k < 2u; k = k + 1u) {
                (*pair).c[a][k] = (*pair).c[a][k] * scale;
                (*pair).t[a][k] = (*pair).t[a][k] * scale;
            }
        }
    }
    if r.shear != 0.0 {
        let ft = r.shear * h;
        for (var a = 0u; a < 3u; a = a + 1u) {
            for (var d = 0u; d < 2u; d = d + 1u) {
                (*pair).c[a][d] = (*pair).c[a][d] + wc[a] * ft * tang[d];
                (*pair).t[a][d] = (*pair).t[a][d] - wt[a] * ft * tang[d];
            }
        }
    }
}

// True when every force of the pair is zero (the CPU's `pair == PairForce2::default()`).
fn is_zero(pair: PairForce) -> bool {
    for (var a = 0u; a < 3u; a = a + 1u) {
        for (var d = 0u; d < 2u; d = d + 1u) {
            if pair.c[a][d] != 0.0 || pair.t[a][d] != 0.0 {
                return false;
            }
        }
    }
    return true;
}

fn kernel(e: u32) {
    var own: Tri;
    let me = element_xy(e);
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
        let other = element_xy(f);
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
        var pair = triangle_pair_force(c, t, pair_penalty(ci, ti, MODEL_AT));
        var state: ContactState;
        let base = (e * CAP + k) * NSTATE;
        if is_zero(pair) {
            // Not touching (most candidates): no force, fresh history (as on the CPU).
            for (var s = 0u; s < NSTATE; s = s + 1u) {
                hist[base + s] = 0.0;
            }
            continue;
        }
        let h = 0.5 * (mean_edge(c) + mean_edge(t));
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            state[s] = hist[base + s];
        }
        apply_model(&pair, ci, ti, h, &state);
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            hist[base + s] = state[s];
        }
        var share = pair.t;
        if e < f {
            share = pair.c;
        }
        for (var a = 0u; a < 3u; a = a + 1u) {
            own[a][0] = own[a][0] + share[a][0];
            own[a][1] = own[a][1] + share[a][1];
        }
    }
    for (var a = 0u; a < 3u; a = a + 1u) {
        let slot = SLOT_FIRST + 3u * e + a;
        slots[slot * D] = own[a][0];
        slots[slot * D + 1u] = own[a][1];
    }
}
