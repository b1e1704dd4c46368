// Broad phase, step 1 (one invocation per node): raise this step's rebuild flag when a
// node has moved more than half the skin since the last build (or the reference is
// unset: NaN). The flags alternate with the step's parity, so node 0 can lower the
// other step's flag here and no separate reset kernel is needed.
fn kernel(n: u32) {
    let p = p_step() & 1u;
    if n == 0u {
        atomicStore(&flag[1u - p], 0u);
    }
    var d2 = Real(0.0);
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        let dk = (coords[i] + disp[i]) - reference[i];
        d2 = d2 + dk * dk;
    }
    // NaN fails the comparison: a NaN reference also forces a build.
    if !(d2 <= LIMIT2) {
        atomicMax(&flag[p], 1u);
    }
}
