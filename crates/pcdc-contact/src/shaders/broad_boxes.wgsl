// Broad phase, step 2 (one invocation per element, only when rebuilding): the element's
// box inflated by MARGIN; the largest box extent, as the bits of an f32 rounded up
// (positive floats order like their bits), by an integer atomicMax; and a copy of the
// element's old candidate list and pair history (carried over in step 5).
fn kernel(e: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    var lo = array<Real, D>();
    var hi = array<Real, D>();
    for (var k = 0u; k < D; k = k + 1u) {
        lo[k] = REAL_MAX;
        hi[k] = -REAL_MAX;
    }
    for (var a = 0u; a < NPE; a = a + 1u) {
        let n = conn[NPE * e + a];
        for (var k = 0u; k < D; k = k + 1u) {
            let x = coords[n * D + k] + disp[n * D + k];
            lo[k] = min(lo[k], x - MARGIN);
            hi[k] = max(hi[k], x + MARGIN);
        }
    }
    var ext = Real(0.0);
    for (var k = 0u; k < D; k = k + 1u) {
        boxes[2u * D * e + k] = lo[k];
        boxes[2u * D * e + D + k] = hi[k];
        ext = max(ext, hi[k] - lo[k]);
    }
    var bits = bitcast<u32>(f32(ext));
    if Real(bitcast<f32>(bits)) < ext {
        bits = bits + 1u;
    }
    atomicMax(&cell_bits[0], bits);
    // The lists are fields of reals (exact integers).
    let n = min(u32(ncand[e]), CAP);
    ncand_old[e] = n;
    for (var k = 0u; k < n; k = k + 1u) {
        cand_old[e * CAP + k] = u32(cand[e * CAP + k]);
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            hist_old[(e * CAP + k) * NSTATE + s] = hist[(e * CAP + k) * NSTATE + s];
        }
    }
}
