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

// H = [u₁ − u₀, u₂ − u₀] D_m⁻¹ of triangle e (row-major), as the element pass computes it
// (`Mechanics::displacement_gradient_2d` on the CPU).
fn disp_gradient_2d(e: u32) -> array<Real, 4> {
    let n0 = conn[3u * e] * 2u;
    let n1 = conn[3u * e + 1u] * 2u;
    let n2 = conn[3u * e + 2u] * 2u;
    let g = e * GEO;
    let d0 = disp[n1] - disp[n0];
    let d1 = disp[n2] - disp[n0];
    let d2 = disp[n1 + 1u] - disp[n0 + 1u];
    let d3 = disp[n2 + 1u] - disp[n0 + 1u];
    return array<Real, 4>(
        d0 * geo[g] + d1 * geo[g + 2u],
        d0 * geo[g + 1u] + d1 * geo[g + 3u],
        d2 * geo[g] + d3 * geo[g + 2u],
        d2 * geo[g + 1u] + d3 * geo[g + 3u],
    );
}
