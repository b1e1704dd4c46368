// Mixed Quad4 cells, first pass (one invocation per element): the trace of the element's
// co-rotated strain, as `Mechanics::mixed_traces` and `mixed::trace_2d` on the CPU.
fn kernel(e: u32) {
    if cell_count[e] <= 1u {
        return;
    }
    let h = disp_gradient_2d(e);
    cell_trace[e] = trace_2d(h[0], h[1], h[2], h[3]);
}
