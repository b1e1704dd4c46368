// Munjiza's potential contact force between two triangles: the arithmetic of
// `potential2d.rs` (`triangle_pair_force`, closed form), in the same order.
alias Tri = array<array<Real, 2>, 3>;

struct PairForce {
    c: Tri,
    t: Tri,
}

struct Clip {
    ok: bool,
    s0: Real,
    s1: Real,
}

// The target's barycentric coordinates at `x`, relative to its first vertex (as
// `Bary2` in potential2d.rs); `inv` is 1 / det of the edge vectors.
fn bary_eval(t: Tri, inv: Real, x: array<Real, 2>) -> array<Real, 3> {
    let e1 = array<Real, 2>(t[1][0] - t[0][0], t[1][1] - t[0][1]);
    let e2 = array<Real, 2>(t[2][0] - t[0][0], t[2][1] - t[0][1]);
    let g1 = array<Real, 2>(e2[1] * inv, -e2[0] * inv);
    let g2 = array<Real, 2>(-e1[1] * inv, e1[0] * inv);
    let d = array<Real, 2>(x[0] - t[0][0], x[1] - t[0][1]);
    let l1 = g1[0] * d[0] + g1[1] * d[1];
    let l2 = g2[0] * d[0] + g2[1] * d[1];
    return array<Real, 3>(1.0 - l1 - l2, l1, l2);
}

// Clips [0, 1] by three affine conditions f(s) >= 0 given at both ends.
fn clip_range(fa: array<Real, 3>, fb: array<Real, 3>) -> Clip {
    var out = Clip(false, Real(0.0), Real(1.0));
    for (var m = 0u; m < 3u; m = m + 1u) {
        if fa[m] < 0.0 && fb[m] < 0.0 {
            return out;
        }
        if fa[m] < 0.0 {
            out.s0 = max(out.s0, fa[m] / (fa[m] - fb[m]));
        } else if fb[m] < 0.0 {
            out.s1 = min(out.s1, fa[m] / (fa[m] - fb[m]));
        }
    }
    out.ok = out.s1 > out.s0;
    return out;
}

fn mean_product(u0: Real, u1: Real, v0: Real, v1: Real) -> Real {
    return (2.0 * u0 * v0 + u0 * v1 + u1 * v0 + 2.0 * u1 * v1) / 6.0;
}

// −p ∮_{∂c ∩ t} φ_t n_c ds onto fc, its reaction onto ft (closed form, see
// potential2d.rs).
fn one_way(c: Tri, t: Tri, penalty: Real, fc: ptr<function, Tri>, ft: ptr<function, Tri>) {
    let det = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    if det == 0.0 || !(abs(det) <= REAL_MAX) {
        return;
    }
    let inv = 1.0 / det;
    var lv: array<array<Real, 3>, 3>;
    for (var v = 0u; v < 3u; v = v + 1u) {
        lv[v] = bary_eval(t, inv, c[v]);
    }
    for (var i = 0u; i < 3u; i = i + 1u) {
        let i1 = (i + 1u) % 3u;
        let a = c[i];
        let b = c[i1];
        let dx = b[0] - a[0];
        let dy = b[1] - a[1];
        let len = sqrt(dx * dx + dy * dy);
        if len == 0.0 {
            continue;
        }
        let la = lv[i];
        let lb = lv[i1];
        if (la[0] < 0.0 && lb[0] < 0.0) || (la[1] < 0.0 && lb[1] < 0.0) || (la[2] < 0.0 && lb[2] < 0.0) {
            continue;
        }
        let nrm = array<Real, 2>(dy / len, -dx / len);
        for (var k = 0u; k < 3u; k = k + 1u) {
            let k1 = (k + 1u) % 3u;
            let j = (k + 2u) % 3u;
            let cl = clip_range(
                array<Real, 3>(la[j], la[k] - la[j], la[k1] - la[j]),
                array<Real, 3>(lb[j], lb[k] - lb[j], lb[k1] - lb[j]),
            );
            if !cl.ok {
                continue;
            }
            var l0: array<Real, 3>;
            var l1: array<Real, 3>;
            for (var m = 0u; m < 3u; m = m + 1u) {
                l0[m] = la[m] + cl.s0 * (lb[m] - la[m]);
                l1[m] = la[m] + cl.s1 * (lb[m] - la[m]);
            }
            let p0 = max(3.0 * l0[j], 0.0);
            let p1 = max(3.0 * l1[j], 0.0);
            let w = penalty * len * (cl.s1 - cl.s0);
            let qb = w * mean_product(cl.s0, cl.s1, p0, p1);
            let qa = w * 0.5 * (p0 + p1) - qb;
            for (var d = 0u; d < 2u; d = d + 1u) {
                (*fc)[i][d] = (*fc)[i][d] - qa * nrm[d];
                (*fc)[i1][d] = (*fc)[i1][d] - qb * nrm[d];
            }
            for (var m = 0u; m < 3u; m = m + 1u) {
                let q = w * mean_product(l0[m], l1[m], p0, p1);
                for (var d = 0u; d < 2u; d = d + 1u) {
                    (*ft)[m][d] = (*ft)[m][d] + q * nrm[d];
                }
            }
        }
    }
}

// Whether some edge of `a` has all of `b` on or outside its line.
fn separated(a: Tri, b: Tri) -> bool {
    for (var k = 0u; k < 3u; k = k + 1u) {
        let p = a[k];
        let q = a[(k + 1u) % 3u];
        var all_out = true;
        for (var m = 0u; m < 3u; m = m + 1u) {
            let x = b[m];
            if (q[0] - p[0]) * (x[1] - p[1]) - (q[1] - p[1]) * (x[0] - p[0]) > 0.0 {
                all_out = false;
            }
        }
        if all_out {
            return true;
        }
    }
    return false;
}

fn triangle_pair_force(c: Tri, t: Tri, penalty: Real) -> PairForce {
    var out: PairForce;
    for (var k = 0u; k < 2u; k = k + 1u) {
        let cmin = min(min(c[0][k], c[1][k]), c[2][k]);
        let cmax = max(max(c[0][k], c[1][k]), c[2][k]);
        let tmin = min(min(t[0][k], t[1][k]), t[2][k]);
        let tmax = max(max(t[0][k], t[1][k]), t[2][k]);
        if cmax <= tmin || tmax <= cmin {
            return out;
        }
    }
    // Separating edge (see `potential2d.rs`): corner-sharing neighbours stop here.
    if separated(c, t) || separated(t, c) {
        return out;
    }
    var fc: Tri;
    var ft: Tri;
    one_way(c, t, penalty, &fc, &ft);
    one_way(t, c, penalty, &ft, &fc);
    out.c = fc;
    out.t = ft;
    return out;
}
