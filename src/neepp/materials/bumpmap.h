// Mitsuba's `bumpmap`: perturbs the shading frame by the gradient of a height texture (times `scale`)
// and evaluates the nested BSDF in the perturbed frame.
#pragma once
#include "neepp/materials/perturbed_frame.h"

namespace neepp {

class BumpMapBSDF final : public PerturbedFrameBSDF {
public:
    BumpMapBSDF(TexturePtr height, float scale, BSDFPtr nested, bool flip_invalid_normals = true,
                bool use_shadowing_function = true)
        : PerturbedFrameBSDF(std::move(height), std::move(nested), flip_invalid_normals, use_shadowing_function),
          scale_(scale) {}
    Frame perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const override;

private:
    float scale_;
};

}  // namespace neepp
