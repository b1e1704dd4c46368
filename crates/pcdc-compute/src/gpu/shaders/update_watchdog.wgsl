// Position update u += dt v and the divergence watchdog (one invocation per node).
// A non-finite value or a displacement beyond the runaway limit records the first bad
// step in status[0] and, for that step, the smallest code node*2 + (0 non-finite,
// 1 runaway) in status[1]. Integer atomics only; no float atomics.
fn kernel(n: u32) {
    let dt = p_dt();
    var u2 = Real(0.0);
    var finite = true;
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        let vk = vel[i];
        let uk = disp[i] + dt * vk;
        disp[i] = uk;
        u2 = u2 + uk * uk;
        // NaN fails every comparison, so this also catches NaN.
        finite = finite && abs(uk) <= REAL_MAX && abs(vk) <= REAL_MAX;
    }
    var code = 0xffffffffu;
    if !finite {
        code = n * 2u;
    } else if u2 > RUNAWAY2 {
        code = n * 2u + 1u;
    }
    if code != 0xffffffffu {
        let s = p_step();
        let prev = atomicMin(&status[0], s);
        if prev >= s {
            atomicMin(&status[1], code);
        }
    }
}
