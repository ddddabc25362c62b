// Mitsuba's `normalmap`: an RGB texture gives the shading normal in the tangent space of the hit's
// shading frame, each channel mapping [0, 1] to [-1, 1] ((0.5, 0.5, 1) leaves the surface unchanged), and
// the nested BSDF is evaluated in the frame around it. The texture is read as it is given: a bitmap
// holding normals wants `raw` set, or its sRGB decoding bends them (as in Mitsuba).
#pragma once
#include "neepp/materials/perturbed_frame.h"

namespace neepp {

class NormalMapBSDF final : public PerturbedFrameBSDF {
public:
    NormalMapBSDF(TexturePtr normals, BSDFPtr nested, bool flip_invalid_normals = true,
                  bool use_shadowing_function = true)
        : PerturbedFrameBSDF(std::move(normals), std::move(nested), flip_invalid_normals, use_shadowing_function) {}
    Frame perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const override;
};

}  // namespace neepp
