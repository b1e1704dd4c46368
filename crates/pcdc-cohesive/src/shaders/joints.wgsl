// Face-joint forces (one invocation per joint, 2D edge joints and 3D triangle-face
// joints): the same arithmetic, in the same order, as `CohesiveJoints::joint` on the
// CPU (manual 7.4.1). Midplane of the two sides → unit normal n and measure; at each
// Gauss point the gap δ = Σ N_k (x_B,k − x_A,k) splits into the opening o = δ·n and
// the slip s = δ − o n; the model gives σ and the shear vector; side A receives
// A Σ_g w N_k (σ n + τ) (summed over the points, then scaled by the area) and side B the
// opposite. Writes every slot of the joint, the joint
// history, the joint damage (largest over the Gauss points) and, once broken, 1 on
// both faces in `broken_face`; and for every joint its opening δ̄·n, sliding δ̄ − (δ̄·n) n
// and normal n, δ̄ the mean of the node-pair gaps (the gap at the face centroid). A
// joint already broken at the start of the step writes these, zero slots and nothing
// else.
//
// joint_info, stride INFO: side A nodes (NPF), side B nodes (NPF), faces A and B,
// model kind, parameter offset. joint_data: Gauss points (N_0, N_1, N_2, weight) from
// GAUSS_AT, model parameters, h per joint from H_AT.

fn kernel(j: u32) {
    let r = j * INFO;
    let s0 = (SLOT_FIRST + 2u * NPF * j) * D;
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
    var n: array<Real, 3>;
    // Measure and unit normal of the midplane face.
    let area = face_measure_normal(mid, &n);
    // Published kinematics: the gap at the face centroid split along the normal.
    var gbar: JointVec;
    for (var k = 0u; k < NPF; k = k + 1u) {
        for (var c = 0u; c < D; c = c + 1u) {
            gbar[c] = gbar[c] + gap[k * D + c];
        }
    }
    var ob = Real(0.0);
    for (var c = 0u; c < D; c = c + 1u) {
        gbar[c] = gbar[c] / Real(NPF);
        ob = ob + gbar[c] * n[c];
    }
    joint_opening[j] = ob;
    for (var c = 0u; c < D; c = c + 1u) {
        joint_sliding[j * D + c] = gbar[c] - ob * n[c];
        joint_normal[j * D + c] = n[c];
    }
    // A broken joint (largest damage 1, faces flagged) transfers no force: contact alone
    // acts between its faces.
    if joint_damage[j] >= 1.0 {
        for (var i = 0u; i < 2u * NPF * D; i = i + 1u) {
            slots[s0 + i] = Real(0.0);
        }
        // As on the CPU, a joint whose damage reached 1 in any way (its law, or the null
        // model breaking it from the host) flags its faces.
        broken_face[joint_info[r + 2u * NPF]] = 1.0;
        broken_face[joint_info[r + 2u * NPF + 1u]] = 1.0;
        return;
    }
    let kind = joint_info[r + 2u * NPF + 2u];
    let p = joint_info[r + 2u * NPF + 3u];
    let h = joint_data[H_AT + j];/*coupling_values*/
    // Side A's force per unit area, summed over the Gauss points; scaled by the area
    // at the end, side B's the opposite.
    var fa: array<Real, 9>;
    var damage = Real(0.0);
    // 2D: the kinematics in the joint's frame (n, t = (-n_y, n_x)), once per joint:
    // each node pair's normal and tangential gap.
    let t0 = -n[1];
    let t1 = n[0];
    var gn: array<Real, 2>;
    var gt: array<Real, 2>;
    if D == 2u {
        for (var k = 0u; k < 2u; k = k + 1u) {
            gn[k] = gap[2u * k] * n[0] + gap[2u * k + 1u] * n[1];
            gt[k] = gap[2u * k] * t0 + gap[2u * k + 1u] * t1;
        }
    }
    for (var g = 0u; g < NGAUSS; g = g + 1u) {
        let q = GAUSS_AT + 4u * g;
        var o = Real(0.0);
        var s: JointVec;
        var sn = Real(0.0);
        if D == 2u {
            o = joint_data[q] * gn[0] + joint_data[q + 1u] * gn[1];
            let st = joint_data[q] * gt[0] + joint_data[q + 1u] * gt[1];
            s[0] = st * t0;
            s[1] = st * t1;
            sn = abs(st);
        } else {
            var delta: JointVec;
            for (var k = 0u; k < NPF; k = k + 1u) {
                for (var c = 0u; c < D; c = c + 1u) {
                    delta[c] = delta[c] + joint_data[q + k] * gap[k * D + c];
                }
            }
            for (var c = 0u; c < D; c = c + 1u) {
                o = o + delta[c] * n[c];
            }
            var s2 = Real(0.0);
            for (var c = 0u; c < D; c = c + 1u) {
                s[c] = delta[c] - o * n[c];
                s2 = s2 + s[c] * s[c];
            }
            sn = sqrt(s2);
        }
        let b = j * NGAUSS * NSTATE + g * NSTATE;
        var st: JointState;
        for (var k = 0u; k < NSTATE; k = k + 1u) {
            st[k] = joint_state[b + k];
        }
        let t = call_joint_model(kind, o, s, sn, h, &st, /*coupling*/p);
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
            let wk = w * joint_data[q + k];
            for (var c = 0u; c < D; c = c + 1u) {
                fa[k * D + c] = fa[k * D + c] + wk * tv[c];
            }
        }
    }
    for (var i = 0u; i < NPF * D; i = i + 1u) {
        let fi = area * fa[i];
        slots[s0 + i] = fi;
        slots[s0 + NPF * D + i] = -fi;
    }
    joint_damage[j] = damage;
    if damage >= 1.0 {
        broken_face[joint_info[r + 2u * NPF]] = 1.0;
        broken_face[joint_info[r + 2u * NPF + 1u]] = 1.0;
    }
}
