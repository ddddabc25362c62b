// Mitsuba 3's procedural `checkerboard` texture.
#pragma once
#include "neepp/base/texture.h"
#include "neepp/textures/bitmap_texture.h"  // UvTransform

namespace neepp {

// Matches Mitsuba 3.9 (src/textures/checkerboard.cpp). With (u', v') = to_uv(uv) and
// mask_x = frac(u') > 0.5, mask_y = frac(v') > 0.5 (frac(t) = t - floor(t)):
//  * eval gives color0 where mask_x == mask_y (so the cell at the uv origin is color0), else color1;
//  * eval_1 gives color0->eval_1 where mask_x != mask_y, else color1->eval_1. This is the opposite
//    assignment to eval; it is Mitsuba's (inconsistent) rule, kept so scalar uses (bump maps, opacity,
//    roughness) match it;
//  * mean is (color0.mean + color1.mean) / 2. eval_1_grad is zero (Mitsuba does not implement it).
class CheckerboardTexture final : public Texture {
public:
    // Mitsuba's defaults: color0 = 0.4, color1 = 0.2, identity to_uv.
    CheckerboardTexture(TexturePtr color0 = constant_texture(0.4f), TexturePtr color1 = constant_texture(0.2f),
                        const Transform &to_uv = {});

    Color eval(const SurfaceInteraction &si) const override;
    float eval_1(const SurfaceInteraction &si) const override;
    Color mean() const override;

private:
    bool same_parity(const SurfaceInteraction &si) const;  // mask_x == mask_y

    TexturePtr color0_, color1_;
    UvTransform to_uv_;
    // Read once: asked at every call, a chain of checkerboards that each use the previous one twice would
    // cost 2^depth calls.
    Color mean_;
};

}  // namespace neepp
