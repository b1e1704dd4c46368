// Pre-existing fracture (Mohr-Coulomb joint): the arithmetic of
// `MohrCoulombJoint::traction`, in the same order. No tension; normal penalty against
// overlap; elastic-perfectly plastic shear with τ_max = c_r − σ tan φ while the faces
// touch. Parameters: P_n (Pa), P_t (Pa), c_r (Pa), tan φ. State: plastic slip vector.
var t: JointTraction;
// Always broken: damage 1 (the faces are a discontinuity).
t.damage = 1.0;
if o >= 0.0 {
    // Open: no traction; the elastic slip restarts from the current slip.
    for (var k = 0u; k < D; k = k + 1u) {
        (*state)[k] = slip[k];
    }
    return t;
}
t.normal = param(p, 0u) * o / h;
let strength = max(param(p, 2u) - t.normal * param(p, 3u), 0.0);
let kt = param(p, 1u) / h;
var trial: JointVec;
for (var k = 0u; k < D; k = k + 1u) {
    trial[k] = kt * (slip[k] - (*state)[k]);
}
let mag = sqrt(trial[0] * trial[0] + trial[1] * trial[1] + trial[2] * trial[2]);
if mag > strength {
    // Plastic sliding: return to the yield surface, move the plastic slip.
    let scale = strength / mag;
    for (var k = 0u; k < D; k = k + 1u) {
        trial[k] = trial[k] * scale;
        (*state)[k] = slip[k] - trial[k] / kt;
    }
}
t.shear = trial;
return t;
