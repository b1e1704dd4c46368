// Mechanical boundary: face stress (Pa, tension positive). One invocation per face; the
// face's NPF slots get the traction share (σ_c + σ_n) n_c A / NPF on the face's current
// outward unit normal n and measure A (length in 2D, area in 3D), with the same
// arithmetic, in the same order, as `Boundary::compute_forces` and
// `Dim::face_measure_normal`. signal(SIG + c) holds σ_cc + σ_n at the start of the step.
//
// Constants: D, NPF (nodes per face), NPF_REAL (the same as a Real), SLOT0 (global index
// of the block's first slot), SIG (first of the D signals). Bindings: coords, disp
// (read), faces (face node lists, NPF per face, read), slots (read_write).

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
    var measure = Real(0.0);
    if D == 2u {
        // Edge a -> b of a counter-clockwise triangle: the outward normal is the edge
        // direction turned clockwise.
        let dx = x[2] - x[0];
        let dy = x[3] - x[1];
        let len = sqrt(dx * dx + dy * dy);
        if len > 0.0 {
            n[0] = dy / len;
            n[1] = -dx / len;
        } else {
            n[0] = Real(0.0);
            n[1] = Real(0.0);
        }
        measure = len;
    } else {
        let a0 = x[3] - x[0];
        let a1 = x[4] - x[1];
        let a2 = x[5] - x[2];
        let b0 = x[6] - x[0];
        let b1 = x[7] - x[1];
        let b2 = x[8] - x[2];
        let c0 = a1 * b2 - a2 * b1;
        let c1 = a2 * b0 - a0 * b2;
        let c2 = a0 * b1 - a1 * b0;
        let len = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
        if len > 0.0 {
            n[0] = c0 / len;
            n[1] = c1 / len;
            n[2] = c2 / len;
        } else {
            n[0] = Real(0.0);
            n[1] = Real(0.0);
            n[2] = Real(0.0);
        }
        measure = Real(0.5) * len;
    }
    for (var s = 0u; s < NPF; s = s + 1u) {
        let base = (SLOT0 + f * NPF + s) * D;
        for (var c = 0u; c < D; c = c + 1u) {
            slots[base + c] = signal(SIG + c) * n[c] * measure / NPF_REAL;
        }
    }
}
