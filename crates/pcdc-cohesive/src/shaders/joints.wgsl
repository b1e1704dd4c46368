// Face-joint forces (one invocation per joint, 2D edge joints and 3D triangle-face
// joints): the same arithmetic, in the same order, as `CohesiveJoints::joint` on the
// CPU (manual 7.4.1). Midplane of the two sides → unit normal n and measure; at each
// Gauss point the gap δ = Σ N_k (x_B,k − x_A,k) splits into the opening o = δ·n and
// the slip s = δ − o n; the model gives σ and the shear vector; side A receives
// w A N_k (σ n + τ) and side B the opposite. Writes every slot of the joint, the joint
// history, the joint damage (largest over the Gauss points) and, once broken, 1 on
// both faces in `broken_face`.
//
// joint_info, stride INFO: side A nodes (NPF), side B nodes (NPF), faces A and B,
// model kind, parameter offset. joint_data: Gauss points (N_0, N_1, N_2, weight) from
// GAUSS_AT, model parameters, h per joint from H_AT.

// Measure and unit normal of the midplane face (Dim::face_measure_normal).
fn face_normal(mid: array<Real, 9>, n: ptr<function, JointVec>) -> Real {
    if D == 2u {
        let dx = mid[2] - mid[0];
        let dy = mid[3] - mid[1];
        let len = sqrt(dx * dx + dy * dy);
        if len > 0.0 {
            (*n)[0] = dy / len;
            (*n)[1] = -dx / len;
        }
        return len;
    }
    let a0 = mid[3] - mid[0];
    let a1 = mid[4] - mid[1];
    let a2 = mid[5] - mid[2];
    let b0 = mid[6] - mid[0];
    let b1 = mid[7] - mid[1];
    let b2 = mid[8] - mid[2];
    let c0 = a1 * b2 - a2 * b1;
    let c1 = a2 * b0 - a0 * b2;
    let c2 = a0 * b1 - a1 * b0;
    let len = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
    if len > 0.0 {
        (*n)[0] = c0 / len;
        (*n)[1] = c1 / len;
        (*n)[2] = c2 / len;
    }
    return 0.5 * len;
}

fn kernel(j: u32) {
    let r = j * INFO;
    var mid: array<Real, 9>;
    var gap: array<Real, 9>;
    for (var k = 0u; k < NPF; k = k + 1u) {
        let na = joint_info[r + k] * D;
        let nb = joint_info[r + NPF + k] * D;
        for (var c = 0u; c < D; c = c + 1u) {
            let xa = coords[na + c] + disp[na + c];
            let xb = coords[nb + c] + disp[nb + c];
            mid[k * D + c] = 0.5 * (xa + xb);
            gap[k * D + c] = xb - xa;
        }
    }
    var n: JointVec;
    let area = face_normal(mid, &n);
    let kind = joint_info[r + 2u * NPF + 2u];
    let p = joint_info[r + 2u * NPF + 3u];
    let h = joint_data[H_AT + j];
    var f: array<Real, 18>;
    var damage = Real(0.0);
    for (var g = 0u; g < NGAUSS; g = g + 1u) {
        let q = GAUSS_AT + 4u * g;
        var delta: JointVec;
        for (var k = 0u; k < NPF; k = k + 1u) {
            for (var c = 0u; c < D; c = c + 1u) {
                delta[c] = delta[c] + joint_data[q + k] * gap[k * D + c];
            }
        }
        var o = Real(0.0);
        for (var c = 0u; c < D; c = c + 1u) {
            o = o + delta[c] * n[c];
        }
        var s: JointVec;
        for (var c = 0u; c < D; c = c + 1u) {
            s[c] = delta[c] - o * n[c];
        }
        let b = j * NGAUSS * NSTATE + g * NSTATE;
        var st: JointState;
        for (var k = 0u; k < NSTATE; k = k + 1u) {
            st[k] = joint_state[b + k];
        }
        let t = call_joint_model(kind, o, s, h, &st, p);
        for (var k = 0u; k < NSTATE; k = k + 1u) {
            joint_state[b + k] = st[k];
        }
        damage = max(damage, t.damage);
        var tv: JointVec;
        for (var c = 0u; c < D; c = c + 1u) {
            tv[c] = t.normal * n[c] + t.shear[c];
        }
        let w = joint_data[q + 3u];
        for (var k = 0u; k < NPF; k = k + 1u) {
            let fw = w * area * joint_data[q + k];
            for (var c = 0u; c < D; c = c + 1u) {
                let ia = k * D + c;
                let ib = (NPF + k) * D + c;
                f[ia] = f[ia] + fw * tv[c];
                f[ib] = f[ib] - fw * tv[c];
            }
        }
    }
    let s0 = (SLOT_FIRST + 2u * NPF * j) * D;
    for (var i = 0u; i < 2u * NPF * D; i = i + 1u) {
        slots[s0 + i] = f[i];
    }
    joint_damage[j] = damage;
    if damage >= 1.0 {
        broken_face[joint_info[r + 2u * NPF]] = 1.0;
        broken_face[joint_info[r + 2u * NPF + 1u]] = 1.0;
    }
}
