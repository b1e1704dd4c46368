// Contact without a contact law (table 1): contact-m-c with the pair's smaller friction
// and penalty (shear penalty = normal penalty), no damping; the arithmetic of
// `SurfaceContact::update_pair`, in the same order. Parameters: element count, tan φ
// per element, penalty per element. State: accumulated slip δ_s (m).
let ne = u32(param(p, 0u));
let tan_phi = min(param(p, 1u + c), param(p, 1u + t));
let pen = min(param(p, 1u + ne + c), param(p, 1u + ne + t));
var r: ContactStress;
r.normal = s_try;
(*state)[0] = (*state)[0] + dslip;
// eq. 59 corrected: τ = P_t |δ_s| / h.
let kt = pen / h;
let limit = tan_phi * r.normal;
var ts = kt * abs((*state)[0]);
var sgn = Real(1.0);
if (*state)[0] < 0.0 {
    sgn = -1.0;
}
if ts > limit {
    ts = limit;
    (*state)[0] = sgn * limit / kt;
}
r.shear = -sgn * ts;
return r;
