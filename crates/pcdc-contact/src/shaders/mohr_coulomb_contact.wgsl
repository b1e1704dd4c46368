// The built-in law contact-m-c: the arithmetic of `MohrCoulombContact::update`, in the
// same order. Parameters: friction on (≠ 0), tan φ, shear penalty P_t (Pa), damping on
// (≠ 0), transition stress T (Pa), exponent b (an integer on the GPU).
// State: accumulated slip δ_s (m); with damping also the largest trial stress and the
// stress held there (Pa). Without damping the host removes the lines between the
// DAMPING markers (the history then holds δ_s only, NSTATE = 1).
var r: ContactStress;
r.normal = s_try;
// DAMPING BEGIN
if param(p, 3u) != 0.0 {
    if s_try >= (*state)[1] {
        (*state)[1] = s_try;
        (*state)[2] = min(s_try, param(p, 4u));
        r.normal = (*state)[2];
    } else {
        let q = s_try / (*state)[1];
        var w = Real(1.0);
        let nb = u32(param(p, 5u));
        for (var k = 0u; k < nb; k = k + 1u) {
            w = w * q;
        }
        r.normal = (*state)[2] * w;
    }
}
// DAMPING END
r.shear = 0.0;
if param(p, 0u) != 0.0 {
    (*state)[0] = (*state)[0] + dslip;
    // eq. 59 corrected: τ = P_t |δ_s| / h.
    let kt = param(p, 2u) / h;
    let limit = param(p, 1u) * r.normal;
    var t = kt * abs((*state)[0]);
    var sgn = Real(1.0);
    if (*state)[0] < 0.0 {
        sgn = -1.0;
    }
    if t > limit {
        t = limit;
        (*state)[0] = sgn * limit / kt;
    }
    r.shear = -sgn * t;
}
return r;
