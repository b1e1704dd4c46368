// Broad phase, step 2 (one invocation per element, only when rebuilding): the element's
// box inflated by MARGIN; the largest box extent, as the bits of an f32 rounded up
// (positive floats order like their bits), by an integer atomicMax; and a copy of the
// element's old candidate list and pair history (carried over in step 5).
fn kernel(e: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    var lo = array<Real, 2>(REAL_MAX, REAL_MAX);
    var hi = array<Real, 2>(-REAL_MAX, -REAL_MAX);
    for (var a = 0u; a < 3u; a = a + 1u) {
        let n = conn[3u * e + a];
        for (var k = 0u; k < 2u; k = k + 1u) {
            let x = coords[n * D + k] + disp[n * D + k];
            lo[k] = min(lo[k], x - MARGIN);
            hi[k] = max(hi[k], x + MARGIN);
        }
    }
    boxes[4u * e] = lo[0];
    boxes[4u * e + 1u] = lo[1];
    boxes[4u * e + 2u] = hi[0];
    boxes[4u * e + 3u] = hi[1];
    let ext = max(hi[0] - lo[0], hi[1] - lo[1]);
    var bits = bitcast<u32>(f32(ext));
    if Real(bitcast<f32>(bits)) < ext {
        bits = bits + 1u;
    }
    atomicMax(&cell_bits[0], bits);
    let n = ncand[e];
    ncand_old[e] = n;
    for (var k = 0u; k < n; k = k + 1u) {
        cand_old[e * CAP + k] = cand[e * CAP + k];
        for (var s = 0u; s < NSTATE; s = s + 1u) {
            hist_old[(e * CAP + k) * NSTATE + s] = hist[(e * CAP + k) * NSTATE + s];
        }
    }
}
