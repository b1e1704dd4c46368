// Munjiza's potential contact force between two tetrahedra: the arithmetic of
// `potential3d.rs` (`tet_pair_force`), in the same order. Faces of one tetrahedron are
// clipped (Sutherland-Hodgman) by the sub-tetrahedra of the other and the clipped
// polygons integrated with the three-point edge-midpoint rule.
alias V3 = array<Real, 3>;
alias Tet = array<V3, 4>;
alias L4 = array<Real, 4>;

struct PairForce {
    c: Tet,
    t: Tet,
}

// Barycentric coordinates as affine functions: λ_i(x) = g_i · (x − p0) (+ 1 for i = 0).
struct Bary {
    ok: bool,
    p0: V3,
    g: Tet,
}

// Capacity of a clipped polygon (as the CPU's `CAP`).
const PCAP: u32 = 12u;

// A convex polygon with the target's barycentric coordinates at its vertices.
struct Poly {
    n: u32,
    x: array<V3, PCAP>,
    l: array<L4, PCAP>,
}

// Clipping buffers (per invocation): 0 the face, 1-2 the face inside the whole target,
// 3-4 the part in one sub-tetrahedron.
var<private> polys: array<Poly, 5>;

fn sub3(a: V3, b: V3) -> V3 {
    return V3(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

fn cross3(a: V3, b: V3) -> V3 {
    return V3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

fn dot3(a: V3, b: V3) -> Real {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

fn bary_new(t: Tet) -> Bary {
    var b: Bary;
    let e1 = sub3(t[1], t[0]);
    let e2 = sub3(t[2], t[0]);
    let e3 = sub3(t[3], t[0]);
    let c23 = cross3(e2, e3);
    let c31 = cross3(e3, e1);
    let c12 = cross3(e1, e2);
    let det = dot3(e1, c23);
    // Degenerate or not finite (NaN fails the comparison).
    if det == 0.0 || !(abs(det) <= REAL_MAX) {
        b.ok = false;
        return b;
    }
    let inv = 1.0 / det;
    for (var d = 0u; d < 3u; d = d + 1u) {
        b.g[1][d] = c23[d] * inv;
        b.g[2][d] = c31[d] * inv;
        b.g[3][d] = c12[d] * inv;
    }
    for (var d = 0u; d < 3u; d = d + 1u) {
        b.g[0][d] = -(b.g[1][d] + b.g[2][d] + b.g[3][d]);
    }
    b.p0 = t[0];
    b.ok = true;
    return b;
}

fn bary_eval(b: Bary, x: V3) -> L4 {
    let d = sub3(x, b.p0);
    let l1 = dot3(b.g[1], d);
    let l2 = dot3(b.g[2], d);
    let l3 = dot3(b.g[3], d);
    return L4(1.0 - l1 - l2 - l3, l1, l2, l3);
}

// The clipping function of plane (j, k): λ_j − λ_k (λ_j for k = 4).
fn plane(l: L4, j: u32, k: u32) -> Real {
    if k < 4u {
        return l[j] - l[k];
    }
    return l[j];
}

fn push_vertex(dst: u32, x: V3, l: L4) {
    let n = polys[dst].n;
    if n < PCAP {
        polys[dst].x[n] = x;
        polys[dst].l[n] = l;
        polys[dst].n = n + 1u;
    }
}

// Sutherland-Hodgman: polys[dst] = the part of polys[src] where plane (j, k) ≥ 0.
fn clip_poly(src: u32, dst: u32, j: u32, k: u32) {
    polys[dst].n = 0u;
    let ns = polys[src].n;
    if ns == 0u {
        return;
    }
    var prev = ns - 1u;
    var fp = plane(polys[src].l[prev], j, k);
    for (var i = 0u; i < ns; i = i + 1u) {
        let fi = plane(polys[src].l[i], j, k);
        if (fi >= 0.0) != (fp >= 0.0) {
            let s = fp / (fp - fi);
            let a = polys[src].x[prev];
            let b = polys[src].x[i];
            let la = polys[src].l[prev];
            let lb = polys[src].l[i];
            var x: V3;
            for (var d = 0u; d < 3u; d = d + 1u) {
                x[d] = a[d] + s * (b[d] - a[d]);
            }
            var l: L4;
            for (var d = 0u; d < 4u; d = d + 1u) {
                l[d] = la[d] + s * (lb[d] - la[d]);
            }
            push_vertex(dst, x, l);
        }
        if fi >= 0.0 {
            push_vertex(dst, polys[src].x[i], polys[src].l[i]);
        }
        prev = i;
        fp = fi;
    }
}

// Clips polys[start] by the planes (j, k) for j ≠ skip (j = 0..3; k fixed, 4 meaning
// λ_j ≥ 0), alternately into buffers buf and buf + 1; a plane that leaves every vertex
// inside costs no copy. Returns the buffer holding the result (`start` when no plane
// cut); a result with fewer than three vertices is empty (the CPU's `clip_chain`).
fn clip_chain(start: u32, skip: u32, k: u32, buf: u32) -> u32 {
    var cur = start;
    for (var j = 0u; j < 4u; j = j + 1u) {
        if j == skip {
            continue;
        }
        var any_in = false;
        var all_in = true;
        for (var v = 0u; v < polys[cur].n; v = v + 1u) {
            let inside = plane(polys[cur].l[v], j, k) >= 0.0;
            any_in = any_in || inside;
            all_in = all_in && inside;
        }
        if all_in {
            continue;
        }
        var dst = buf;
        if cur == buf {
            dst = buf + 1u;
        }
        if !any_in {
            polys[dst].n = 0u;
            return dst;
        }
        clip_poly(cur, dst, j, k);
        cur = dst;
        if polys[dst].n < 3u {
            return cur;
        }
    }
    return cur;
}

// −p ∮_{∂c ∩ t} φ_t n_c dA onto fc, its reaction onto ft (the CPU's `one_way`).
fn one_way(c: Tet, bc: Bary, bt: Bary, penalty: Real, fc: ptr<function, Tet>, ft: ptr<function, Tet>) {
    for (var i = 0u; i < 4u; i = i + 1u) {
        // Face opposite vertex i.
        let v = array<V3, 3>(c[(i + 1u) % 4u], c[(i + 2u) % 4u], c[(i + 3u) % 4u]);
        let lv = array<L4, 3>(bary_eval(bt, v[0]), bary_eval(bt, v[1]), bary_eval(bt, v[2]));
        // Entirely outside one face plane of the target: nothing to integrate.
        var outside = false;
        for (var j = 0u; j < 4u; j = j + 1u) {
            outside = outside || (lv[0][j] <= 0.0 && lv[1][j] <= 0.0 && lv[2][j] <= 0.0);
        }
        if outside {
            continue;
        }
        let nrm = cross3(sub3(v[1], v[0]), sub3(v[2], v[0]));
        let len = sqrt(dot3(nrm, nrm));
        if len == 0.0 || !(len <= REAL_MAX) {
            continue;
        }
        // Outward: away from the opposite vertex.
        var sgn = Real(1.0);
        if dot3(nrm, sub3(v[0], c[i])) < 0.0 {
            sgn = -1.0;
        }
        var n: V3;
        for (var d = 0u; d < 3u; d = d + 1u) {
            n[d] = sgn * nrm[d] / len;
        }
        // The face inside the whole target first (λ_j ≥ 0 for all j) ...
        polys[0].n = 3u;
        for (var a = 0u; a < 3u; a = a + 1u) {
            polys[0].x[a] = v[a];
            polys[0].l[a] = lv[a];
        }
        let whole = clip_chain(0u, 4u, 4u, 1u);
        if polys[whole].n < 3u {
            continue;
        }
        // Per-node load sums along n over this face: Σ λ_c q and Σ λ_t q.
        var sc = L4(0.0, 0.0, 0.0, 0.0);
        var st = L4(0.0, 0.0, 0.0, 0.0);
        // ... then in each sub-tetrahedron k (λ_j − λ_k ≥ 0, j ≠ k), where φ_t = 4 λ_k.
        for (var k = 0u; k < 4u; k = k + 1u) {
            let p = clip_chain(whole, k, k, 3u);
            let np = polys[p].n;
            if np < 3u {
                continue;
            }
            // Fan triangles (q_0, q_m, q_m+1), three edge-midpoint points each.
            for (var m = 1u; m + 1u < np; m = m + 1u) {
                let x0 = polys[p].x[0];
                let x1 = polys[p].x[m];
                let x2 = polys[p].x[m + 1u];
                let ar = cross3(sub3(x1, x0), sub3(x2, x0));
                let area = 0.5 * sqrt(dot3(ar, ar));
                if area == 0.0 {
                    continue;
                }
                let l0 = polys[p].l[0];
                let l1 = polys[p].l[m];
                let l2 = polys[p].l[m + 1u];
                let w = penalty * area / 3.0;
                let xs = array<V3, 3>(x0, x1, x2);
                let ls = array<L4, 3>(l0, l1, l2);
                for (var e = 0u; e < 3u; e = e + 1u) {
                    let xa = xs[e];
                    let xb = xs[(e + 1u) % 3u];
                    let la = ls[e];
                    let lb = ls[(e + 1u) % 3u];
                    let phi = max(2.0 * (la[k] + lb[k]), 0.0);
                    let q = w * phi;
                    var mid: V3;
                    for (var d = 0u; d < 3u; d = d + 1u) {
                        mid[d] = 0.5 * (xa[d] + xb[d]);
                    }
                    let lc = bary_eval(bc, mid);
                    for (var a = 0u; a < 4u; a = a + 1u) {
                        sc[a] = sc[a] + lc[a] * q;
                        st[a] = st[a] + 0.5 * (la[a] + lb[a]) * q;
                    }
                }
            }
        }
        // The load −q n on the contactor's face, +q n on the target.
        for (var a = 0u; a < 4u; a = a + 1u) {
            for (var d = 0u; d < 3u; d = d + 1u) {
                (*fc)[a][d] = (*fc)[a][d] - sc[a] * n[d];
                (*ft)[a][d] = (*ft)[a][d] + st[a] * n[d];
            }
        }
    }
}

fn tet_pair_force(c: Tet, t: Tet, penalty: Real) -> PairForce {
    var out: PairForce;
    // Cheap rejection on bounding boxes.
    for (var k = 0u; k < 3u; k = k + 1u) {
        let cmin = min(min(min(c[0][k], c[1][k]), c[2][k]), c[3][k]);
        let cmax = max(max(max(c[0][k], c[1][k]), c[2][k]), c[3][k]);
        let tmin = min(min(min(t[0][k], t[1][k]), t[2][k]), t[3][k]);
        let tmax = max(max(max(t[0][k], t[1][k]), t[2][k]), t[3][k]);
        if cmax <= tmin || tmax <= cmin {
            return out;
        }
    }
    let bc = bary_new(c);
    let bt = bary_new(t);
    if !bc.ok || !bt.ok {
        return out;
    }
    // Separating face planes: all of one tetrahedron outside a face of the other.
    var lc_of_t: array<L4, 4>;
    var lt_of_c: array<L4, 4>;
    for (var a = 0u; a < 4u; a = a + 1u) {
        lc_of_t[a] = bary_eval(bc, t[a]);
        lt_of_c[a] = bary_eval(bt, c[a]);
    }
    for (var j = 0u; j < 4u; j = j + 1u) {
        var all_c = true;
        var all_t = true;
        for (var a = 0u; a < 4u; a = a + 1u) {
            all_c = all_c && lc_of_t[a][j] <= 0.0;
            all_t = all_t && lt_of_c[a][j] <= 0.0;
        }
        if all_c || all_t {
            return out;
        }
    }
    var fc: Tet;
    var ft: Tet;
    one_way(c, bc, bt, penalty, &fc, &ft);
    one_way(t, bt, bc, penalty, &ft, &fc);
    out.c = fc;
    out.t = ft;
    return out;
}
