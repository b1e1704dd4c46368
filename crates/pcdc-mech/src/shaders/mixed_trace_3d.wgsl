// Mixed Hex8 cells, first pass (one invocation per element): the element rotation (stored
// for the element pass) and the trace of its co-rotated strain, as
// `Mechanics::mixed_traces` on the CPU.
fn kernel(e: u32) {
    if cell_count[e] <= 1u {
        return;
    }
    let g = e * GEO;
    var mm: M3;
    for (var k = 0u; k < 9u; k = k + 1u) {
        mm[k] = geo[g + k];
    }
    let f = deformation_gradient(e, mm);
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
