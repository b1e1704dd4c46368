// Mixed Quad4 cells, first pass (one invocation per element): the trace of the element's
// co-rotated strain, as `Mechanics::mixed_traces` and `mixed::trace_2d` on the CPU.
fn kernel(e: u32) {
    if cell_count[e] <= 1u {
        return;
    }
    let n0 = conn[3u * e] * 2u;
    let n1 = conn[3u * e + 1u] * 2u;
    let n2 = conn[3u * e + 2u] * 2u;
    let g = e * GEO;
    let d0 = disp[n1] - disp[n0];
    let d1 = disp[n2] - disp[n0];
    let d2 = disp[n1 + 1u] - disp[n0 + 1u];
    let d3 = disp[n2 + 1u] - disp[n0 + 1u];
    let h0 = d0 * geo[g] + d1 * geo[g + 2u];
    let h1 = d0 * geo[g + 1u] + d1 * geo[g + 3u];
    let h2 = d2 * geo[g] + d3 * geo[g + 2u];
    let h3 = d2 * geo[g + 1u] + d3 * geo[g + 3u];
    cell_trace[e] = trace_2d(h0, h1, h2, h3);
}
