// Mixed Quad4 cells, third pass (one invocation per element): the element's forces take
// the cell's mean in-plane pressure instead of its own, as
// `Mechanics::mixed_pressure_forces` on the CPU.
fn in_plane_mean(k: u32) -> Real {
    return 0.5 * (stress[3u * k] + stress[3u * k + 1u]);
}

fn kernel(e: u32) {
    if cell_count[e] <= 1u || element_null[e] != 0.0 {
        return;
    }
    let cf = cell_first[e];
    var pbar = Real(0.0);
    for (var k = cf; k < cf + cell_count[e]; k = k + 1u) {
        pbar = pbar + cell_weight[k] * in_plane_mean(k);
    }
    let g = e * GEO;
    let dp = (pbar - in_plane_mean(e)) * geo[g + 4u];
    let h = disp_gradient_2d(e);
    let h0 = h[0];
    let h1 = h[1];
    let h2 = h[2];
    let h3 = h[3];
    // The rotation as the element pass finds it.
    let pc = 2.0 + (h0 + h3);
    let ps = h2 - h1;
    let pr = sqrt(pc * pc + ps * ps);
    var co = Real(1.0);
    var si = Real(0.0);
    if pr > 0.0 {
        if pc >= 0.0 {
            let q = 1.0 / (pr * (pc + pr));
            let inv_r = (pc + pr) * q;
            co = pc * inv_r;
            si = ps * inv_r;
        } else {
            let inv_r = 1.0 / pr;
            co = pc * inv_r;
            si = ps * inv_r;
        }
    }
    let s = (SLOT_FIRST + 3u * e) * 2u;
    var f0x = Real(0.0);
    var f0y = Real(0.0);
    for (var a = 0u; a < 2u; a = a + 1u) {
        let gx = geo[g + 2u * a];
        let gy = geo[g + 2u * a + 1u];
        let fx = -dp * (co * gx - si * gy);
        let fy = -dp * (si * gx + co * gy);
        slots[s + 2u * (a + 1u)] = slots[s + 2u * (a + 1u)] + fx;
        slots[s + 2u * (a + 1u) + 1u] = slots[s + 2u * (a + 1u) + 1u] + fy;
        f0x = f0x - fx;
        f0y = f0y - fy;
    }
    slots[s] = slots[s] + f0x;
    slots[s + 1u] = slots[s + 1u] + f0y;
}
