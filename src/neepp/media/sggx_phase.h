// Mitsuba 3's `sggx` phase function: scattering by a cloud of mirror-like microflakes whose normals follow
// the SGGX distribution (Heitz, Dupuy, Crassin and Dachsbacher, "The SGGX Microflake Distribution",
// SIGGRAPH 2015), the normals of an ellipsoid given by a symmetric positive semi-definite matrix S read from
// a 6-channel volume at the scattering point. An S with one small eigenvalue makes fibres (flakes facing
// every way across the small eigenvector), one with two small ones a surface (flakes facing along the
// large one); S = I is isotropic.
#pragma once
#include <memory>
#include "neepp/base/medium.h"
#include "neepp/math/symmetric_matrix.h"
#include "neepp/media/volume.h"

namespace neepp {

// The distribution's pieces, for one S (an S and any multiple of it are the same phase function).
// D(m) = det(S)^(3/2) / (pi (mᵀ adj(S) m)²), the density of flake normals m (not normalised over m alone:
// D(m) |m·w| integrates over m to the projected area), 0 where S is singular and m off its support.
float sggx_normal_density(const SymmetricMatrix3 &s, const Vec3 &m);
// sigma(w) = sqrt(wᵀ S w): the flakes' area seen along w (or -w).
float sggx_projected_area(const SymmetricMatrix3 &s, const Vec3 &w);
// A flake normal facing wi, drawn with density D(m) max(0, m·wi) / sigma(wi) (the visible normals, by the
// paper's appendix: a cosine-weighted point of the disc that the ellipsoid shows wi, lifted onto it). A
// zero vector where S shows wi no area, or a flat ellipsoid edge-on.
Vec3 sggx_sample_visible_normal(const SymmetricMatrix3 &s, const Vec3 &wi, Vec2 u);

// Light arriving along -wi leaves along wo, the mirror image of wi about a visible flake normal: the phase
// function is D(h) / (4 sigma(wi)) with h the half vector of wi and wo, its own sampling density (weight 1),
// as Mitsuba's. It integrates to 1 over wo; it is reciprocal only up to the projected areas:
// f(wi, wo) sigma(wi) = f(wo, wi) sigma(wo).
class SGGXPhase final : public PhaseFunction {
public:
    // S: a 6-channel volume (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz). Throws std::invalid_argument otherwise.
    explicit SGGXPhase(std::shared_ptr<const Volume> S);
    float eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override { return eval(p, wi, wo); }
    PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const override;
    // sigma(w) at p: a medium with this phase function is that much denser along w (Mitsuba's Microflake).
    float projected_area(const Vec3 &p, const Vec3 &w) const override;
    // sqrt of S's largest eigenvalue anywhere.
    float max_projected_area() const override { return max_area_; }
    const Volume &S() const { return *S_; }

private:
    std::shared_ptr<const Volume> S_;
    float max_area_;
};

}  // namespace neepp
