// Mohr–Coulomb with tension cut-off (manual 7.2.4; MohrCoulomb::update): elastic trial
// (eq. 25-28), principal decomposition, active-set return (eq. 29 corrected, 30-33),
// history: 0 shear now, 1 shear past, 2 tension now, 3 tension past, 4 κ_s, 5 κ_t.
let l = param(p, 0u);
let two_mu = param(p, 1u);
let tr = dstrain[0] + dstrain[1] + dstrain[2];
var s = stress;
s[0] = s[0] + (l * tr + two_mu * dstrain[0]);
s[1] = s[1] + (l * tr + two_mu * dstrain[1]);
s[2] = s[2] + (l * tr + two_mu * dstrain[2]);
s[3] = s[3] + two_mu * dstrain[3];
s[4] = s[4] + two_mu * dstrain[4];
s[5] = s[5] + two_mu * dstrain[5];
(*state)[0] = 0.0;
(*state)[2] = 0.0;
let f = mc_surfaces(p, (*state)[4], (*state)[5]);
if mc_surely_elastic(f, s) {
    return s;
}
// Plane strain in closed form, else Jacobi.
let flat = s[4] == 0.0 && s[5] == 0.0;
var values: McV3;
var pr: McPrin;
var p2: McPrin2;
if flat {
    p2 = mc_principal_2d(s);
    values = p2.values;
} else {
    pr = mc_principal(s, param(p, 8u));
    values = pr.values;
}
let r = mc_return(f, values, param(p, 9u));
if !r.ok {
    return s;
}
if r.shear > 0.0 {
    (*state)[0] = 1.0;
    (*state)[1] = 1.0;
    let m = (r.eps[0] + r.eps[1] + r.eps[2]) * (1.0 / 3.0);
    let ea = r.eps[0] - m;
    let eb = r.eps[1] - m;
    let ec = r.eps[2] - m;
    (*state)[4] = (*state)[4] + sqrt(0.5 * (ea * ea + eb * eb + ec * ec));
}
if r.tension > 0.0 {
    (*state)[2] = 1.0;
    (*state)[3] = 1.0;
    (*state)[5] = (*state)[5] + r.tension;
}
if flat {
    return mc_compose_2d(r.s, p2);
}
return mc_compose(r.s, pr.axes);
