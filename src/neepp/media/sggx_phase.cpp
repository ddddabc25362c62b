#include "neepp/media/sggx_phase.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"

namespace neepp {

float sggx_normal_density(const SymmetricMatrix3 &s, const Vec3 &m) {
    // mᵀ S⁻¹ m = mᵀ adj(S) m / det(S): written with the adjugate, a singular S divides nothing by 0 until
    // the last step, and |det| absorbs a determinant that rounding took below 0.
    const float det = std::abs(s.determinant());
    const float quad = s.adjugate().form(m, m);
    if (!(quad > 0)) return 0.f;
    return det * std::sqrt(det) / (kPi * quad * quad);
}

float sggx_projected_area(const SymmetricMatrix3 &s, const Vec3 &w) { return safe_sqrt(s.form(w, w)); }

Vec3 sggx_sample_visible_normal(const SymmetricMatrix3 &s, const Vec3 &wi, Vec2 u) {
    // S in a frame whose third axis is wi (k, j, i = s, t, n): seen along wi the ellipsoid is a disc, and
    // the visible normals are those of its points above a cosine-distributed point of the disc. The
    // three columns below map the unit hemisphere onto the ellipsoid's visible half (a Cholesky-like
    // factor of S in that frame, the paper's appendix).
    const Frame f(wi);
    const Vec3 s_j = s * f.t, s_i = s * f.n;
    // S_kk enters only through det(S), which the frame does not change.
    const float kj = dot(f.s, s_j), ki = dot(f.s, s_i), jj = dot(f.t, s_j), ji = dot(f.t, s_i), ii = dot(f.n, s_i);
    const float j_given_i = safe_sqrt(jj * ii - ji * ji);  // the disc's extent along j, times sqrt(ii)
    if (!(ii > 0) || !(j_given_i > 0)) return Vec3(0.f);
    const float inv_sqrt_ii = 1.f / std::sqrt(ii);
    const Vec3 col_k(std::sqrt(std::abs(s.determinant())) / j_given_i, 0.f, 0.f);
    const Vec3 col_j((kj * ii - ki * ji) * inv_sqrt_ii / j_given_i, j_given_i * inv_sqrt_ii, 0.f);
    const Vec3 col_i = Vec3(ki, ji, ii) * inv_sqrt_ii;
    const Vec3 h = square_to_cosine_hemisphere(u);
    const Vec3 m = col_k * h.x + col_j * h.y + col_i * h.z;
    const float len = norm(m);
    if (!(len > 0)) return Vec3(0.f);
    return f.to_world(m / len);
}

SGGXPhase::SGGXPhase(std::shared_ptr<const Volume> S) : S_(std::move(S)) {
    if (!S_ || S_->channels() != 6)
        throw std::invalid_argument("an sggx phase function's S is a 6-channel volume (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz), not one of " +
                                    std::to_string(S_ ? S_->channels() : 0) + " channels");
    max_area_ = std::sqrt(std::max(S_->max(), 0.f));
}

float SGGXPhase::projected_area(const Vec3 &p, const Vec3 &w) const { return sggx_projected_area(S_->eval_matrix(p), w); }

float SGGXPhase::eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const {
    const SymmetricMatrix3 s = S_->eval_matrix(p);
    const float area = sggx_projected_area(s, wi);
    const Vec3 h = wi + wo;
    const float len = norm(h);
    // wo = -wi straight on has no half vector (a flake seen edge-on: no density).
    if (!(area > 0) || !(len > 0)) return 0.f;
    return sggx_normal_density(s, h / len) / (4.f * area);
}

PhaseSample SGGXPhase::sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const {
    const SymmetricMatrix3 s = S_->eval_matrix(p);
    const float area = sggx_projected_area(s, wi);
    const Vec3 m = sggx_sample_visible_normal(s, wi, u);
    if (!(area > 0) || m == Vec3(0.f)) return {};
    // Reflected about the flake: the density of wo is that of m, D(m) (m·wi) / area, over the Jacobian
    // 4 (m·wi) of the reflection.
    const float pdf = sggx_normal_density(s, m) / (4.f * area);
    if (!(pdf > 0)) return {};
    return {normalize(reflect(wi, m)), pdf, 1.f};
}

}  // namespace neepp
