#include "neepp/textures/checkerboard_texture.h"

#include <cmath>

namespace neepp {

CheckerboardTexture::CheckerboardTexture(TexturePtr color0, TexturePtr color1, const Transform &to_uv)
    : color0_(std::move(color0)), color1_(std::move(color1)), to_uv_(to_uv),
      mean_((color0_->mean() + color1_->mean()) * 0.5f) {}

bool CheckerboardTexture::same_parity(const SurfaceInteraction &si) const {
    const Vec2 uv = to_uv_.apply(si.uv);
    const bool mx = uv.x - std::floor(uv.x) > 0.5f, my = uv.y - std::floor(uv.y) > 0.5f;
    return mx == my;
}

Color CheckerboardTexture::eval(const SurfaceInteraction &si) const {
    return same_parity(si) ? color0_->eval(si) : color1_->eval(si);
}

float CheckerboardTexture::eval_1(const SurfaceInteraction &si) const {
    return same_parity(si) ? color1_->eval_1(si) : color0_->eval_1(si);
}

Color CheckerboardTexture::mean() const { return mean_; }

}  // namespace neepp
