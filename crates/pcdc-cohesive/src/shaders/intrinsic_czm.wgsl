// Intrinsic cohesive zone model (manual eq. 63-73): the arithmetic of
// `IntrinsicCzm::traction`, in the same order. Before the peak in both modes nothing
// beyond comparisons is evaluated: an undamaged joint pays no `softening`.
// Parameters: o_p/h, s_p/h, 1/o_t, 1/s_t, tan φ, T_s (Pa), c (Pa), P_overlap (Pa),
// h/o_p, h/s_p.
// State: damage D, largest opening o_u, largest slip s_u, failure mode code.
let op_h = param(p, 0u);
let sp_h = param(p, 1u);
let inv_ot = param(p, 2u);
let inv_st = param(p, 3u);
let tan_phi = param(p, 4u);
let ts = param(p, 5u);
let coh = param(p, 6u);
let p_overlap = param(p, 7u);
let inv_op_h = param(p, 8u);
let inv_sp_h = param(p, 9u);
let inv_h = 1.0 / h;
let s = slip_norm;
let op = op_h * h;
let sp = sp_h * h;
let inv_op = inv_op_h * inv_h;
let inv_sp = inv_sp_h * inv_h;
// Damage (eq. 68), irreversible.
var d = (*state)[0];
if o > op || s > sp {
    let dn = max((o - op) * inv_ot, 0.0);
    let ds = max((s - sp) * inv_st, 0.0);
    let trial = min(sqrt(dn * dn + ds * ds), 1.0);
    if trial > d {
        d = trial;
        if d >= 1.0 && (*state)[3] == 0.0 {
            // FailureMode codes: 1 tensile, 2 shear, 3 mixed.
            var mode = Real(3.0);
            if ds * ds < 0.1 * dn * dn {
                mode = Real(1.0);
            } else if dn * dn < 0.1 * ds * ds {
                mode = Real(2.0);
            }
            (*state)[3] = mode;
        }
        (*state)[0] = d;
    }
}
// A broken joint transfers nothing: its faces interact through contact alone.
if d >= 1.0 {
    var none: JointTraction;
    none.damage = d;
    return none;
}
var f = Real(1.0);
if d > 0.0 {
    f = softening(d);
}
let ou = max((*state)[1], o);
let su = max((*state)[2], s);
(*state)[1] = ou;
(*state)[2] = su;
// Normal traction (eq. 63, unloading eq. 72).
var normal: Real;
if o < 0.0 {
    normal = p_overlap * o * inv_h;
} else if ou > op && o < ou {
    normal = f * ts * o / ou;
} else if o <= op {
    let x = o * inv_op;
    normal = x * (2.0 - x) * f * ts;
} else {
    normal = f * ts;
}
// Shear strength: Mohr-Coulomb with the softened cohesion (eq. 64).
let strength = max(-normal * tan_phi + f * coh, 0.0);
// The shear traction (τ / |s|) s, τ / |s| per branch (no division before the peak).
var scale: Real;
if su > sp && s < su {
    scale = strength / su;
} else if s <= sp {
    scale = (2.0 - s * inv_sp) * strength * inv_sp;
} else {
    scale = strength / s;
}
var t: JointTraction;
t.normal = normal;
for (var k = 0u; k < D; k = k + 1u) {
    t.shear[k] = scale * slip[k];
}
t.damage = (*state)[0];
return t;
