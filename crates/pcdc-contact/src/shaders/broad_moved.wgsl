// Broad phase, step 1 (one invocation per node): raise the rebuild flag when a node has
// moved more than half the skin since the last build (or the reference is unset: NaN).
fn kernel(n: u32) {
    var d2 = Real(0.0);
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        let dk = (coords[i] + disp[i]) - reference[i];
        d2 = d2 + dk * dk;
    }
    // NaN fails the comparison: a NaN reference also forces a build.
    if !(d2 <= LIMIT2) {
        atomicMax(&flag[0], 1u);
    }
}
