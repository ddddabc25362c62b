// Spatial and directional bounds of the light a light emits, for the light BVH (Conty Estevez & Kulla,
// "Importance Sampling of Many Lights with Adaptive Tree Splitting", 2018): a box holding the emitters, a
// cone holding their normals (theta_o) and how far beyond a normal they emit (theta_e, pi/2 for a
// cosine emitter), and their power. importance() is a conservative bound shape: it is zero only where no
// light inside the bounds can illuminate the point, so a sampler that uses it stays unbiased.
#pragma once
#include "neepp/math/bbox.h"
#include "neepp/math/vec.h"

namespace neepp {

// The set of unit directions within angle acos(cos_theta) of w. cos_theta = -1 is the whole sphere.
struct DirectionCone {
    Vec3 w{0, 0, 1};
    float cos_theta = 1.f;
    static DirectionCone entire_sphere() { return {Vec3(0, 0, 1), -1.f}; }
    bool is_entire_sphere() const { return cos_theta <= -1.f; }
};
// The smallest cone (of this construction) holding both cones.
DirectionCone cone_union(const DirectionCone &a, const DirectionCone &b);

struct LightBounds {
    BBox bounds;
    DirectionCone normals;     // normals of the emitting surfaces
    float cos_theta_e = 0.f;   // emission extends this far past any normal (cos(pi/2) = 0: cosine emitters)
    float phi = 0.f;           // power (luminance), the importance's scale
    bool two_sided = false;

    // Importance of these lights at point p with surface normal n (n = 0: no receiver-side factor):
    // phi · cos(theta') · cos(theta_i') / d², with theta' and theta_i' the smallest angles any point of
    // the bounds can make with the emission cone and with the receiver's normal.
    float importance(const Vec3 &p, const Vec3 &n) const;
};

LightBounds bounds_union(const LightBounds &a, const LightBounds &b);

// LightBounds with what importance() derives from them precomputed, for the BVH's inner loop.
struct CompactLightBounds {
    Vec3 center, w;
    float r2 = 0, cos_o = 1, sin_o = 0, cos_e = 0, phi = 0;
    bool two_sided = false;
    CompactLightBounds() = default;
    explicit CompactLightBounds(const LightBounds &b);
    float importance(const Vec3 &p, const Vec3 &n) const;
};

}  // namespace neepp
