// tr(U) − 2 of a 2D displacement gradient H without cancellation (`mixed::trace_2d`).
fn trace_2d(h0: Real, h1: Real, h2: Real, h3: Real) -> Real {
    let t = h0 + h3;
    let c = 2.0 + t;
    let s = h2 - h1;
    let r = sqrt(c * c + s * s);
    return (t * (c + 2.0) + s * s) / (r + 2.0);
}

// The cell's volume-weighted mean of the element traces.
fn cell_mean(e: u32) -> Real {
    let cf = cell_first[e];
    var mean = Real(0.0);
    for (var k = cf; k < cf + cell_count[e]; k = k + 1u) {
        mean = mean + cell_weight[k] * cell_trace[k];
    }
    return mean;
}
