// Burgers creep (manual 7.2.5, eq. 43-48 corrected, tensor form of FLAC; Burgers::step):
// coupling[0] the creep step index, coupling[1] Δt_c (s). Parameters: K, G_M, G_K (Pa),
// η_K, η_M (Pa·s). History: 0-5 e^K, 6-11 S^O, 12-17 strain at the step's start, 18 step
// index, 19 Δt_c last used, 20 ready.
let bulk = param(p, 0u);
let gm = param(p, 1u);
let gk = param(p, 2u);
let ek = param(p, 3u);
let em = param(p, 4u);
let index = coupling[0];
let dt = coupling[1];
let mean0 = (stress[0] + stress[1] + stress[2]) * (1.0 / 3.0);
var dev = stress;
dev[0] = stress[0] - mean0;
dev[1] = stress[1] - mean0;
dev[2] = stress[2] - mean0;
var fresh = false;
if (*state)[20] == 0.0 {
    fresh = true;
} else if index != (*state)[18] {
    // Commit the finished creep step.
    let dtp = (*state)[19];
    let ap = 1.0 + gk * dtp / (2.0 * ek);
    let bp = 1.0 - gk * dtp / (2.0 * ek);
    let c = dtp / (4.0 * ek);
    for (var k = 0u; k < 6u; k = k + 1u) {
        let s0 = (*state)[6u + k];
        (*state)[k] = (bp * (*state)[k] + c * (dev[k] + s0)) / ap;
    }
    fresh = true;
}
if fresh {
    for (var k = 0u; k < 6u; k = k + 1u) {
        (*state)[6u + k] = dev[k];
        (*state)[12u + k] = strain[k] - dstrain[k];
    }
    (*state)[18] = index;
    (*state)[20] = 1.0;
}
let a = 1.0 + gk * dt / (2.0 * ek);
let b = 1.0 - gk * dt / (2.0 * ek);
let x = 1.0 / (2.0 * gm) + dt / (4.0 * em) + dt / (4.0 * a * ek);
let y = 1.0 / (2.0 * gm) - dt / (4.0 * em) - dt / (4.0 * a * ek);
var e = Sym(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
for (var k = 0u; k < 6u; k = k + 1u) {
    e[k] = strain[k] - (*state)[12u + k];
}
let em0 = (e[0] + e[1] + e[2]) * (1.0 / 3.0);
e[0] = e[0] - em0;
e[1] = e[1] - em0;
e[2] = e[2] - em0;
let mean = mean0 + bulk * (dstrain[0] + dstrain[1] + dstrain[2]);
var s = stress;
for (var k = 0u; k < 6u; k = k + 1u) {
    let sk = (e[k] + y * (*state)[6u + k] - (b / a - 1.0) * (*state)[k]) / x;
    s[k] = sk + select(0.0, mean, k < 3u);
}
(*state)[19] = dt;
return s;
