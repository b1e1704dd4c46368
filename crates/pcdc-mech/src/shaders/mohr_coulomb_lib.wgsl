// Mohr–Coulomb with tension cut-off (manual 7.2.4): the helpers of the model body, the
// operations of mohr_coulomb.rs and principal.rs in the same order, so that f64 matches
// the CPU to rounding. Parameters (param(p, k)): 0 λ, 1 2μ (Pa), 2 α1, 3 α2 (Pa), 4 N_φ,
// 5 N_ψ, 6 2c√N_φ (Pa), 7 σ_t (Pa), 8 the Jacobi stop (1e-32), 9 f64::MIN_POSITIVE,
// 10 softening (0/1), 11 c (Pa), 12 φ, 13 ψ (degrees), 14 σ_t as given (Pa), 15 α_P of
// the h-function, then four
// tables (c, φ, ψ against κ_s; σ_t against κ_t), each its point count n, n abscissae and
// n values (n = 0: the constant).
alias McV3 = array<Real, 3>;

struct McSurf {
    n_phi: Real,
    n_psi: Real,
    kc: Real,
    st: Real,
    a1: Real,
    a2: Real,
    alpha_p: Real,
}

struct McRet {
    ok: bool,
    s: McV3,
    ep: McV3,
    eps: McV3,
    shear: Real,
    tension: Real,
}

struct McPrin {
    values: McV3,
    axes: array<McV3, 3>,
}

// Plane k at principal stresses s: 0 shear (eq. 29 corrected), 1-2 the pyramid's edges,
// 3-5 σ3, σ2, σ1 against σ_t.
fn mc_plane(f: McSurf, k: u32, s: McV3) -> Real {
    var r = s[0] - f.st;
    switch k {
        case 0u: { r = f.n_phi * s[2] - s[0] - f.kc; }
        case 1u: { r = f.n_phi * s[1] - s[0] - f.kc; }
        case 2u: { r = f.n_phi * s[2] - s[1] - f.kc; }
        case 3u: { r = s[2] - f.st; }
        case 4u: { r = s[1] - f.st; }
        default: {}
    }
    return r;
}

fn mc_grad(k: u32, n: Real) -> McV3 {
    var g = McV3(1.0, 0.0, 0.0);
    switch k {
        case 0u: { g = McV3(-1.0, 0.0, n); }
        case 1u: { g = McV3(-1.0, n, 0.0); }
        case 2u: { g = McV3(0.0, -1.0, n); }
        case 3u: { g = McV3(0.0, 0.0, 1.0); }
        case 4u: { g = McV3(0.0, 1.0, 0.0); }
        default: {}
    }
    return g;
}

fn mc_elastic(f: McSurf, m: McV3) -> McV3 {
    let t = m[0] + m[1] + m[2];
    return McV3(f.a1 * m[0] + f.a2 * (t - m[0]), f.a1 * m[1] + f.a2 * (t - m[1]), f.a1 * m[2] + f.a2 * (t - m[2]));
}

fn mc_dot(a: McV3, b: McV3) -> Real {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

fn mc_composite(f: McSurf, s: McV3) -> Real {
    let hi = max(max(s[0], s[1]), s[2]);
    let lo = min(min(s[0], s[1]), s[2]);
    return max(f.n_phi * hi - lo - f.kc, hi - f.st);
}

// Surfaces::surely_elastic: inside by a bound without the decomposition.
fn mc_surely_elastic(f: McSurf, t: Sym) -> bool {
    let p = (t[0] + t[1] + t[2]) * (1.0 / 3.0);
    let a = t[0] - p;
    let b = t[1] - p;
    let c = t[2] - p;
    let ss = a * a + b * b + c * c + 2.0 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5]);
    let r2 = ss * (2.0 / 3.0);
    let room_t = f.st - p;
    let k = f.n_phi - 1.0 + 1.7320508075688772;
    let room_s = f.kc - (f.n_phi - 1.0) * p;
    return room_t >= 0.0 && room_s >= 0.0 && r2 <= room_t * room_t && k * k * r2 <= room_s * room_s;
}

fn mc_h(f: McSurf, s: McV3) -> Real {
    let sp = f.st * f.n_phi - f.kc;
    return s[2] - f.st + f.alpha_p * (s[0] - sp);
}

// The return onto planes[0..n] together (Surfaces::solve).
fn mc_solve(f: McSurf, s: McV3, planes: array<u32, 3>, n: u32) -> McRet {
    var out: McRet;
    out.ok = false;
    var dg: array<McV3, 3>;
    for (var c = 0u; c < n; c = c + 1u) {
        dg[c] = mc_elastic(f, mc_grad(planes[c], f.n_psi));
    }
    var a: array<McV3, 3>;
    var b = McV3(0.0, 0.0, 0.0);
    for (var r = 0u; r < n; r = r + 1u) {
        let df = mc_grad(planes[r], f.n_phi);
        for (var c = 0u; c < n; c = c + 1u) {
            a[r][c] = mc_dot(df, dg[c]);
        }
        b[r] = mc_plane(f, planes[r], s);
    }
    // Gaussian elimination with partial pivoting (solve_small: the last largest pivot).
    var norm = Real(0.0);
    for (var r = 0u; r < n; r = r + 1u) {
        for (var c = 0u; c < n; c = c + 1u) {
            norm = max(norm, abs(a[r][c]));
        }
    }
    for (var c = 0u; c < n; c = c + 1u) {
        var pv = c;
        for (var i = c + 1u; i < n; i = i + 1u) {
            if abs(a[i][c]) >= abs(a[pv][c]) {
                pv = i;
            }
        }
        if abs(a[pv][c]) <= 1e-12 * norm {
            return out;
        }
        let ra = a[c];
        a[c] = a[pv];
        a[pv] = ra;
        let rb = b[c];
        b[c] = b[pv];
        b[pv] = rb;
        for (var r = c + 1u; r < n; r = r + 1u) {
            let fr = a[r][c] / a[c][c];
            for (var k = c; k < n; k = k + 1u) {
                a[r][k] = a[r][k] - fr * a[c][k];
            }
            b[r] = b[r] - fr * b[c];
        }
    }
    var x = McV3(0.0, 0.0, 0.0);
    for (var cc = n; cc > 0u; cc = cc - 1u) {
        let c = cc - 1u;
        var v = b[c];
        for (var k = c + 1u; k < n; k = k + 1u) {
            v = v - a[c][k] * x[k];
        }
        x[c] = v / a[c][c];
    }
    for (var c = 0u; c < n; c = c + 1u) {
        if x[c] < 0.0 {
            return out;
        }
    }
    out.s = s;
    out.ep = McV3(0.0, 0.0, 0.0);
    out.eps = McV3(0.0, 0.0, 0.0);
    out.shear = 0.0;
    out.tension = 0.0;
    for (var c = 0u; c < n; c = c + 1u) {
        let j = planes[c];
        let g = mc_grad(j, f.n_psi);
        for (var i = 0u; i < 3u; i = i + 1u) {
            out.s[i] = out.s[i] - x[c] * dg[c][i];
            out.ep[i] = out.ep[i] + x[c] * g[i];
            if j < 3u {
                out.eps[i] = out.eps[i] + x[c] * g[i];
            }
        }
        if j < 3u {
            out.shear = out.shear + x[c];
        } else {
            out.tension = out.tension + x[c];
        }
    }
    out.ok = true;
    return out;
}

// One candidate planes: true when admissible (then *found is it), else it may become the
// least violating (*best, *best_v).
fn mc_try(f: McSurf, s: McV3, planes: array<u32, 3>, n: u32, tol: Real, found: ptr<function, McRet>, best: ptr<function, McRet>, best_v: ptr<function, Real>) -> bool {
    let r = mc_solve(f, s, planes, n);
    if !r.ok {
        return false;
    }
    let v = mc_composite(f, r.s);
    if v <= tol {
        *found = r;
        return true;
    }
    if !(*best).ok || v < *best_v {
        *best = r;
        *best_v = v;
    }
    return false;
}

// Surfaces::return_map: ok = false when s is not outside the surface.
fn mc_return(f: McSurf, s: McV3, min_pos: Real) -> McRet {
    var found: McRet;
    found.ok = false;
    let scale = max(max(max(abs(s[0]), abs(s[2])), f.kc), f.st);
    if mc_composite(f, s) <= 0.0 {
        return found;
    }
    let tol = 1e-12 * max(scale, min_pos);
    // Active set from the h-function's plane, adding the most violated plane.
    var planes = array<u32, 3>(0u, 0u, 0u);
    if mc_h(f, s) > 0.0 {
        planes[0] = 3u;
    }
    for (var n = 1u; n <= 3u; n = n + 1u) {
        let r = mc_solve(f, s, planes, n);
        if !r.ok {
            break;
        }
        if mc_composite(f, r.s) <= tol {
            return r;
        }
        if n == 3u {
            break;
        }
        var worst = tol;
        var at = 6u;
        for (var k = 0u; k < 6u; k = k + 1u) {
            var used = false;
            for (var j = 0u; j < n; j = j + 1u) {
                used = used || planes[j] == k;
            }
            let fk = mc_plane(f, k, r.s);
            if !used && fk > worst {
                worst = fk;
                at = k;
            }
        }
        if at == 6u {
            break;
        }
        planes[n] = at;
    }
    // Otherwise the likely sets first, then every set (Surfaces::return_map:
    // FIRST_SHEAR, FIRST_TENSION, SETS as bit masks).
    var first = array<u32, 5>(1u, 3u, 5u, 9u, 8u);
    if mc_h(f, s) > 0.0 {
        first = array<u32, 5>(8u, 24u, 9u, 1u, 56u);
    }
    var sets = array<u32, 41>(1u, 2u, 4u, 8u, 16u, 32u, 3u, 5u, 6u, 9u, 10u, 12u, 17u, 18u, 20u, 24u, 33u, 34u, 36u, 40u, 48u, 7u, 11u, 13u, 14u, 19u, 21u, 22u, 25u, 26u, 28u, 35u, 37u, 38u, 41u, 42u, 44u, 49u, 50u, 52u, 56u);
    var best: McRet;
    best.ok = false;
    var best_v = Real(0.0);
    for (var i = 0u; i < 46u; i = i + 1u) {
        var mask = 0u;
        if i < 5u {
            mask = first[i];
        } else {
            mask = sets[i - 5u];
            var tried = false;
            for (var k = 0u; k < 5u; k = k + 1u) {
                tried = tried || first[k] == mask;
            }
            if tried {
                continue;
            }
        }
        planes = array<u32, 3>(0u, 0u, 0u);
        var n = 0u;
        for (var k = 0u; k < 6u; k = k + 1u) {
            if (mask & (1u << k)) != 0u {
                planes[n] = k;
                n = n + 1u;
            }
        }
        if mc_try(f, s, planes, n, tol, &found, &best, &best_v) {
            return found;
        }
    }
    return best;
}

// One Jacobi rotation zeroing a[p][q] (principal.rs: rotate; t = sgn(d) 2a_pq/(ρ + |d|),
// c = √((ρ + |d|)/2ρ)).
fn mc_rotate(a: ptr<function, array<McV3, 3>>, v: ptr<function, array<McV3, 3>>, p: u32, q: u32) {
    let apq = (*a)[p][q];
    if apq == 0.0 {
        return;
    }
    let d = (*a)[q][q] - (*a)[p][p];
    let rho = sqrt(d * d + 4.0 * apq * apq);
    let e = rho + abs(d);
    if e <= 0.0 {
        return;
    }
    var t = -2.0 * apq / e;
    if d >= 0.0 {
        t = 2.0 * apq / e;
    }
    let c = sqrt(e / (2.0 * rho));
    let s = t * c;
    let r = 3u - p - q;
    let app = (*a)[p][p];
    let aqq = (*a)[q][q];
    let apr = (*a)[p][r];
    let aqr = (*a)[q][r];
    (*a)[p][p] = app - t * apq;
    (*a)[q][q] = aqq + t * apq;
    (*a)[p][q] = 0.0;
    (*a)[q][p] = 0.0;
    (*a)[p][r] = c * apr - s * aqr;
    (*a)[r][p] = (*a)[p][r];
    (*a)[q][r] = s * apr + c * aqr;
    (*a)[r][q] = (*a)[q][r];
    for (var i = 0u; i < 3u; i = i + 1u) {
        let vp = (*v)[i][p];
        let vq = (*v)[i][q];
        (*v)[i][p] = c * vp - s * vq;
        (*v)[i][q] = s * vp + c * vq;
    }
}

// principal.rs: principal (cyclic Jacobi, values ascending, axes carried).
fn mc_principal(t: Sym, jtol: Real) -> McPrin {
    var a = array<McV3, 3>(McV3(t[0], t[3], t[5]), McV3(t[3], t[1], t[4]), McV3(t[5], t[4], t[2]));
    var v = array<McV3, 3>(McV3(1.0, 0.0, 0.0), McV3(0.0, 1.0, 0.0), McV3(0.0, 0.0, 1.0));
    var sweeps = 12u;
    if t[4] == 0.0 && t[5] == 0.0 {
        mc_rotate(&a, &v, 0u, 1u);
        sweeps = 0u;
    }
    for (var sweep = 0u; sweep < sweeps; sweep = sweep + 1u) {
        let off = a[0][1] * a[0][1] + a[1][2] * a[1][2] + a[0][2] * a[0][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= jtol * diag || off == 0.0 {
            break;
        }
        mc_rotate(&a, &v, 0u, 1u);
        mc_rotate(&a, &v, 1u, 2u);
        mc_rotate(&a, &v, 0u, 2u);
    }
    var idx = array<u32, 3>(0u, 1u, 2u);
    let d = McV3(a[0][0], a[1][1], a[2][2]);
    if d[idx[1]] < d[idx[0]] {
        idx = array<u32, 3>(idx[1], idx[0], idx[2]);
    }
    if d[idx[2]] < d[idx[1]] {
        idx = array<u32, 3>(idx[0], idx[2], idx[1]);
    }
    if d[idx[1]] < d[idx[0]] {
        idx = array<u32, 3>(idx[1], idx[0], idx[2]);
    }
    var out: McPrin;
    for (var i = 0u; i < 3u; i = i + 1u) {
        let k = idx[i];
        out.values[i] = d[k];
        out.axes[i] = McV3(v[0][k], v[1][k], v[2][k]);
    }
    return out;
}

// principal.rs: plane (closed form for yz = xz = 0).
struct McPrin2 {
    values: McV3,
    cs: array<Real, 2>,
    slots: array<u32, 3>,
}

fn mc_principal_2d(t: Sym) -> McPrin2 {
    let c = 0.5 * (t[0] + t[1]);
    let d = 0.5 * (t[0] - t[1]);
    let r = sqrt(d * d + t[3] * t[3]);
    var out: McPrin2;
    out.cs = array<Real, 2>(-1.0, 0.0);
    if r > 0.0 {
        let inv = 1.0 / r;
        out.cs = array<Real, 2>(d * inv, t[3] * inv);
    }
    let lo = c - r;
    let hi = c + r;
    let zz = t[2];
    if zz <= lo {
        out.values = McV3(zz, lo, hi);
        out.slots = array<u32, 3>(1u, 2u, 0u);
    } else if zz >= hi {
        out.values = McV3(lo, hi, zz);
        out.slots = array<u32, 3>(0u, 1u, 2u);
    } else {
        out.values = McV3(lo, zz, hi);
        out.slots = array<u32, 3>(0u, 2u, 1u);
    }
    return out;
}

// principal.rs: compose_plane.
fn mc_compose_2d(values: McV3, p: McPrin2) -> Sym {
    let a = values[p.slots[0]];
    let b = values[p.slots[1]];
    let c = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    return Sym(c + r * p.cs[0], c - r * p.cs[0], values[p.slots[2]], r * p.cs[1], 0.0, 0.0);
}

// principal.rs: compose.
fn mc_compose(values: McV3, axes: array<McV3, 3>) -> Sym {
    var t = Sym(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (var i = 0u; i < 3u; i = i + 1u) {
        let s = values[i];
        let n = axes[i];
        t[0] = t[0] + s * n[0] * n[0];
        t[1] = t[1] + s * n[1] * n[1];
        t[2] = t[2] + s * n[2] * n[2];
        t[3] = t[3] + s * n[0] * n[1];
        t[4] = t[4] + s * n[1] * n[2];
        t[5] = t[5] + s * n[0] * n[2];
    }
    return t;
}

// sin x for x in [0, π/2] by its Taylor series to x^21 (error below 3e-16): drivers may
// lack f64 sin. Only the softening tables need it.
fn mc_sin(x: Real) -> Real {
    let x2 = x * x;
    var r = Real(1.9572941063391263e-20); // 1/21!
    r = r * x2 - 8.220635246624331e-18; // 1/19!
    r = r * x2 + 2.8114572543455206e-15;
    r = r * x2 - 7.647163731819816e-13;
    r = r * x2 + 1.6059043836821613e-10;
    r = r * x2 - 2.505210838544172e-8;
    r = r * x2 + 2.7557319223985893e-6;
    r = r * x2 - 1.984126984126984e-4;
    r = r * x2 + 8.333333333333333e-3;
    r = r * x2 - 1.6666666666666666e-1;
    r = r * x2 + 1.0;
    return r * x;
}

// Table k (0 c, 1 φ, 2 ψ, 3 σ_t) at x, or `fallback` without points: linear between
// points, constant beyond (pcdc_compute::Table::eval).
fn mc_table(p: u32, k: u32, x: Real, fallback: Real) -> Real {
    var at = 16u;
    for (var j = 0u; j < k; j = j + 1u) {
        at = at + 1u + 2u * u32(param(p, at));
    }
    let n = u32(param(p, at));
    if n == 0u {
        return fallback;
    }
    let t0 = at + 1u;
    let v0 = at + 1u + n;
    if x <= param(p, t0) {
        return param(p, v0);
    }
    if x >= param(p, t0 + n - 1u) {
        return param(p, v0 + n - 1u);
    }
    var i = 1u;
    while param(p, t0 + i) <= x {
        i = i + 1u;
    }
    let ta = param(p, t0 + i - 1u);
    let tb = param(p, t0 + i);
    let va = param(p, v0 + i - 1u);
    let vb = param(p, v0 + i);
    return va + (vb - va) * (x - ta) / (tb - ta);
}

// The surfaces at the element's plastic strains (MohrCoulomb::surfaces_at).
fn mc_surfaces(p: u32, ks: Real, kt: Real) -> McSurf {
    var f = McSurf(param(p, 4u), param(p, 5u), param(p, 6u), param(p, 7u), param(p, 2u), param(p, 3u), param(p, 15u));
    if param(p, 10u) == 0.0 {
        return f;
    }
    let c = mc_table(p, 0u, ks, param(p, 11u));
    let phi = mc_table(p, 1u, ks, param(p, 12u));
    let psi = min(mc_table(p, 2u, ks, param(p, 13u)), phi);
    let st = mc_table(p, 3u, kt, param(p, 14u));
    let sphi = mc_sin(phi * 0.017453292519943295);
    let spsi = mc_sin(psi * 0.017453292519943295);
    f.n_phi = (1.0 + sphi) / (1.0 - sphi);
    f.n_psi = (1.0 + spsi) / (1.0 - spsi);
    f.kc = 2.0 * c * sqrt(f.n_phi);
    f.alpha_p = sqrt(1.0 + f.n_phi * f.n_phi) + f.n_phi;
    f.st = st;
    if phi > 0.0 {
        f.st = min(st, c * sqrt(1.0 - sphi * sphi) / sphi);
    }
    return f;
}
