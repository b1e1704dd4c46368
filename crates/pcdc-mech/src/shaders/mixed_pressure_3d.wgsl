// Mixed Hex8 cells, third pass (one invocation per element): the element's forces take
// the cell's mean pressure instead of its own, as `Mechanics::mixed_pressure_forces` on
// the CPU, with the rotation the element pass stored.
fn mean_stress(k: u32) -> Real {
    return (stress[6u * k] + stress[6u * k + 1u] + stress[6u * k + 2u]) / 3.0;
}

fn kernel(e: u32) {
    if cell_count[e] <= 1u || element_null[e] != 0.0 {
        return;
    }
    let cf = cell_first[e];
    var pbar = Real(0.0);
    for (var k = cf; k < cf + cell_count[e]; k = k + 1u) {
        pbar = pbar + cell_weight[k] * mean_stress(k);
    }
    let g = e * GEO;
    let dp = (pbar - mean_stress(e)) * geo[g + 9u];
    let s = (SLOT_FIRST + 4u * e) * 3u;
    var f0 = array<Real, 3>(0.0, 0.0, 0.0);
    for (var a = 0u; a < 3u; a = a + 1u) {
        for (var i = 0u; i < 3u; i = i + 1u) {
            let fa = -dp * (rotation[9u * e + 3u * i] * geo[g + 3u * a]
                + rotation[9u * e + 3u * i + 1u] * geo[g + 3u * a + 1u]
                + rotation[9u * e + 3u * i + 2u] * geo[g + 3u * a + 2u]);
            slots[s + 3u * (a + 1u) + i] = slots[s + 3u * (a + 1u) + i] + fa;
            f0[i] = f0[i] - fa;
        }
    }
    for (var i = 0u; i < 3u; i = i + 1u) {
        slots[s + i] = slots[s + i] + f0[i];
    }
}
