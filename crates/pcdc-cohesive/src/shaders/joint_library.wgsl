// Library of the joint kernel, callable from joint model bodies. Each function performs
// the operations of its CPU twin in pcdc_cohesive (model.rs) in the same order.

// e^x with + − × ÷ and an integer conversion only (`pcdc_cohesive::portable_exp`):
// clamp to [−708, 709], x = k ln 2 + r (two-part ln 2), degree-13 Taylor polynomial of
// e^r in Horner form, times 2^k built exactly by binary powering.
fn portable_exp(x_in: Real) -> Real {
    let x = clamp(x_in, -708.0, 709.0);
    let t = x * INV_LN2;
    let k = i32(t + select(Real(-0.5), Real(0.5), t >= 0.0));
    let kf = Real(k);
    let r = (x - kf * LN2_HI) - kf * LN2_LO;
    var c = array<Real, 14>(EXP_C0, EXP_C1, EXP_C2, EXP_C3, EXP_C4, EXP_C5, EXP_C6,
        EXP_C7, EXP_C8, EXP_C9, EXP_C10, EXP_C11, EXP_C12, EXP_C13);
    var poly = c[13];
    for (var i = 12; i >= 0; i = i - 1) {
        poly = c[i] + r * poly;
    }
    var base = Real(2.0);
    if k < 0 {
        base = Real(0.5);
    }
    var n = u32(abs(k));
    var scale = Real(1.0);
    while n > 0u {
        if (n & 1u) == 1u {
            scale = scale * base;
        }
        base = base * base;
        n = n >> 1u;
    }
    return poly * scale;
}

// Softening function f(D) of eq. 69 (`pcdc_cohesive::softening`): f(0) = 1, f(1) = 0.
fn softening(d: Real) -> Real {
    if d <= 0.0 {
        return 1.0;
    }
    if d >= 1.0 {
        return 0.0;
    }
    let z = SOFTENING_Z0 * portable_exp(d * SOFTENING_X / SOFTENING_Y);
    let q = 1.0 - d;
    let q2 = q * q;
    let q6 = q2 * q2 * q2;
    return (1.0 - z) * (SOFTENING_A * q + SOFTENING_B * q6);
}
