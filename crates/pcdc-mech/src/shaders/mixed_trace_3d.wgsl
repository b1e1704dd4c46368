// Mixed Hex8 cells, first pass (one invocation per element): the element rotation (stored
// for the element pass) and the trace of its co-rotated strain, as
// `Mechanics::mixed_traces` on the CPU.
fn kernel(e: u32) {
    if cell_count[e] <= 1u {
        return;
    }
    var n: array<u32, 4>;
    for (var a = 0u; a < 4u; a = a + 1u) {
        n[a] = conn[4u * e + a] * 3u;
    }
    let g = e * GEO;
    var mm: M3;
    for (var k = 0u; k < 9u; k = k + 1u) {
        mm[k] = geo[g + k];
    }
    var du: M3;
    for (var i = 0u; i < 3u; i = i + 1u) {
        let o = disp[n[0] + i];
        for (var j = 0u; j < 3u; j = j + 1u) {
            du[3u * i + j] = disp[n[j + 1u] + i] - o;
        }
    }
    var f = mul3(du, mm);
    f[0] = f[0] + 1.0;
    f[4] = f[4] + 1.0;
    f[8] = f[8] + 1.0;
    var r_prev: M3;
    for (var k = 0u; k < 9u; k = k + 1u) {
        r_prev[k] = rotation[9u * e + k];
    }
    let r = polar_3d(f, r_prev);
    for (var k = 0u; k < 9u; k = k + 1u) {
        rotation[9u * e + k] = r[k];
    }
    let u = mul3_tn(r, f);
    cell_trace[e] = (u[0] - 1.0) + (u[4] - 1.0) + (u[8] - 1.0);
}
