// Munjiza's potential contact force between two triangles: the arithmetic of
// `potential2d.rs` (`triangle_pair_force`), in the same order.
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

fn barycentric(t: Tri, p: array<Real, 2>) -> array<Real, 3> {
    let area2 = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
    var l: array<Real, 3>;
    for (var k = 0u; k < 3u; k = k + 1u) {
        let a = t[(k + 1u) % 3u];
        let b = t[(k + 2u) % 3u];
        l[k] = ((a[0] - p[0]) * (b[1] - p[1]) - (b[0] - p[0]) * (a[1] - p[1])) / area2;
    }
    return l;
}

fn clip_segment(a: array<Real, 2>, b: array<Real, 2>, poly: Tri) -> Clip {
    var out = Clip(false, Real(0.0), Real(1.0));
    for (var k = 0u; k < 3u; k = k + 1u) {
        let p = poly[k];
        let q = poly[(k + 1u) % 3u];
        let fa = (q[0] - p[0]) * (a[1] - p[1]) - (q[1] - p[1]) * (a[0] - p[0]);
        let fb = (q[0] - p[0]) * (b[1] - p[1]) - (q[1] - p[1]) * (b[0] - p[0]);
        if fa < 0.0 && fb < 0.0 {
            return out;
        }
        if fa < 0.0 {
            out.s0 = max(out.s0, fa / (fa - fb));
        } else if fb < 0.0 {
            out.s1 = min(out.s1, fa / (fa - fb));
        }
    }
    out.ok = out.s1 > out.s0;
    return out;
}

// −p ∮_{∂c ∩ t} φ_t n_c ds onto fc, its reaction onto ft.
fn one_way(c: Tri, t: Tri, penalty: Real, fc: ptr<function, Tri>, ft: ptr<function, Tri>) {
    let g = array<Real, 2>((t[0][0] + t[1][0] + t[2][0]) / 3.0, (t[0][1] + t[1][1] + t[2][1]) / 3.0);
    let gauss = array<Real, 2>(GAUSS_0, GAUSS_1);
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
        let nrm = array<Real, 2>(dy / len, -dx / len);
        for (var k = 0u; k < 3u; k = k + 1u) {
            let sub = Tri(t[k], t[(k + 1u) % 3u], g);
            let cl = clip_segment(a, b, sub);
            if !cl.ok {
                continue;
            }
            for (var r = 0u; r < 2u; r = r + 1u) {
                let s = cl.s0 + (cl.s1 - cl.s0) * gauss[r];
                let x = array<Real, 2>(a[0] + s * dx, a[1] + s * dy);
                let l = barycentric(t, x);
                let phi = max(3.0 * l[(k + 2u) % 3u], 0.0);
                let q = penalty * phi * 0.5 * (cl.s1 - cl.s0) * len;
                let f = array<Real, 2>(-q * nrm[0], -q * nrm[1]);
                for (var d = 0u; d < 2u; d = d + 1u) {
                    (*fc)[i][d] = (*fc)[i][d] + (1.0 - s) * f[d];
                    (*fc)[i1][d] = (*fc)[i1][d] + s * f[d];
                    for (var m = 0u; m < 3u; m = m + 1u) {
                        (*ft)[m][d] = (*ft)[m][d] - l[m] * f[d];
                    }
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
