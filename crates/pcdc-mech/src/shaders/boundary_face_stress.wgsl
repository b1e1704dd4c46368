// Mechanical boundary: face stress (Pa, tension positive). One invocation per face; the
// face's NPF slots get the traction share t_c A / NPF, t = σ n on the face's current
// outward unit normal n and measure A (length in 2D, area in 3D), with the same
// arithmetic, in the same order, as `Boundary::compute_forces` and
// `Dim::face_measure_normal`: t_c = (σ_cc + σ_n) n_c, then + σ_cj n_j for j ≠ c in
// increasing j when SHEAR = 1. signal(SIG + c) holds σ_cc + σ_n at the start of the
// step; signal(SHEAR_SIG + c + j - 1) holds σ_cj (pairs xy, xz, yz, as `shear_pair`).
//
// Constants: D, NPF (nodes per face), NPF_REAL (the same as a Real), SLOT0 (global index
// of the block's first slot), SIG (first of the D diagonal signals), SHEAR (1 when
// shear components are prescribed), SHEAR_SIG (first of the D (D - 1) / 2 shear
// signals; unused when SHEAR = 0). Bindings: coords, disp (read), faces (face node
// lists, NPF per face, read), slots (read_write).

// Current position of node n, component c (m).
fn position(n: u32, c: u32) -> Real {
    return coords[n * D + c] + disp[n * D + c];
}

fn kernel(f: u32) {
    var x: array<Real, 9>;
    for (var k = 0u; k < NPF; k = k + 1u) {
        let node = faces[f * NPF + k];
        for (var c = 0u; c < D; c = c + 1u) {
            x[k * D + c] = position(node, c);
        }
    }
    var n: array<Real, 3>;
    let measure = face_measure_normal(x, &n);
    var t: array<Real, 3>;
    for (var c = 0u; c < D; c = c + 1u) {
        var tc = signal(SIG + c) * n[c];
        if (SHEAR == 1u) {
            for (var j = 0u; j < D; j = j + 1u) {
                if (j != c) {
                    tc = tc + signal(SHEAR_SIG + c + j - 1u) * n[j];
                }
            }
        }
        t[c] = tc;
    }
    for (var s = 0u; s < NPF; s = s + 1u) {
        let base = (SLOT0 + f * NPF + s) * D;
        for (var c = 0u; c < D; c = c + 1u) {
            slots[base + c] = t[c] * measure / NPF_REAL;
        }
    }
}
