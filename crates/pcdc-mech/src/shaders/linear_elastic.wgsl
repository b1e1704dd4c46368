// Isotropic linear elasticity, incremental: σ += λ tr(Δε) I + 2μ Δε (manual eq. 20-24).
// Parameters: λ, μ (Pa).
let l = param(p, 0u);
let mu = param(p, 1u);
let tr = dstrain[0] + dstrain[1] + dstrain[2];
var s = stress;
s[0] = s[0] + (l * tr + 2.0 * mu * dstrain[0]);
s[1] = s[1] + (l * tr + 2.0 * mu * dstrain[1]);
s[2] = s[2] + (l * tr + 2.0 * mu * dstrain[2]);
s[3] = s[3] + 2.0 * mu * dstrain[3];
s[4] = s[4] + 2.0 * mu * dstrain[4];
s[5] = s[5] + 2.0 * mu * dstrain[5];
return s;
