// Textures: spatially varying RGB or scalar parameters of BSDFs, looked up by surface uv.
#pragma once
#include <memory>
#include "neepp/base/interaction.h"

namespace neepp {

class Texture {
public:
    virtual ~Texture() = default;
    virtual Color eval(const SurfaceInteraction &si) const = 0;
    // Scalar value (for roughness, opacity, bump height): the mean of the RGB channels.
    virtual float eval_1(const SurfaceInteraction &si) const {
        Color c = eval(si);
        return (c.x + c.y + c.z) * (1.f / 3.f);
    }
    // Derivative of eval_1 with respect to (u, v), for bump mapping.
    virtual Vec2 eval_1_grad(const SurfaceInteraction &) const { return {0, 0}; }
    // Average value over the texture's domain (for light power estimates and plastic's sampling weights).
    virtual Color mean() const = 0;
    virtual bool is_constant() const { return false; }
    // Speed hook, optional: cache prefetch of what eval(si) will read (see BSDF::prefetch).
    virtual void prefetch(const SurfaceInteraction &) const {}
};

// Prefetches each texture that is set (textures of a BSDF may be null when unused).
template <class... T>
void prefetch_textures(const SurfaceInteraction &si, const T &...textures) {
    ((textures ? textures->prefetch(si) : void()), ...);
}

class ConstantTexture final : public Texture {
public:
    explicit ConstantTexture(Color v) : value_(v) {}
    Color eval(const SurfaceInteraction &) const override { return value_; }
    Color mean() const override { return value_; }
    bool is_constant() const override { return true; }

private:
    Color value_;
};

using TexturePtr = std::shared_ptr<const Texture>;

// A scalar texture's value, 0 where it is not set (a BSDF's optional parameters, such as principled's).
inline float eval_or_zero(const TexturePtr &t, const SurfaceInteraction &si) { return t ? t->eval_1(si) : 0.f; }

inline TexturePtr constant_texture(Color c) { return std::make_shared<ConstantTexture>(c); }
inline TexturePtr constant_texture(float v) { return std::make_shared<ConstantTexture>(Color(v)); }

}  // namespace neepp
