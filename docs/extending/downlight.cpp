// A light: a point that emits in one hemisphere with intensity I(ω) = I0 cos θ about its axis, as a tiny
// patch of a Lambertian emitter does (a recessed ceiling light). A delta light: next event estimation
// connects to its one point, and BSDF sampling never finds it.
#include <algorithm>
#include "neepp/loader/plugins.h"
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"

namespace example {
using namespace neepp;

class DownLight final : public Light {
public:
    DownLight(Vec3 position, Vec3 axis, Color intensity) : position_(position), axis_(normalize(axis)), intensity_(intensity) {}

    // The one direction toward the light from ref, and the radiance-equivalent I(ω) / r² arriving along it.
    DirectionSample sample_direction(const Vec3 &ref, Vec2, Color &radiance) const override {
        float dist2 = 0;
        const DirectionSample ds = direction_sample_to_point(position_, ref, dist2);
        radiance = intensity_ * (std::max(0.f, dot(-ds.d, axis_)) / dist2);
        return ds;
    }
    float pdf_direction(const Vec3 &, const DirectionSample &) const override { return 0.f; }  // a delta

    // Light paths (light tracing, BDPT): rays from the point, their directions by the cosine about the axis.
    EmissionSample sample_emission(Vec2, Vec2 u_dir) const override {
        EmissionSample es;
        const Vec3 local = square_to_cosine_hemisphere(u_dir);
        const Vec3 d = Frame(axis_).to_world(local);
        es.ray = Ray{position_, d, 0.f, kInfinity};
        es.p = position_;
        es.radiance = intensity_ * cos_theta(local);
        es.pdf_pos = 1.f;
        es.pdf_dir = square_to_cosine_hemisphere_pdf(local);
        return es;
    }
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const override {
        return {1.f, std::max(0.f, dot(w, axis_)) * kInvPi};
    }
    // ∫ I0 cos θ dω over the hemisphere.
    Color power() const override { return intensity_ * kPi; }
    bool is_delta() const override { return true; }
    // For the light BVH: a point whose emission is a hemisphere about the axis.
    std::optional<LightBounds> bounds() const override {
        LightBounds b;
        b.bounds.expand(position_);
        b.normals = DirectionCone{axis_, 1.f};  // one normal: the axis
        b.cos_theta_e = 0.f;  // emits up to 90° from its axis
        b.phi = luminance(power());
        return b;
    }

private:
    Vec3 position_, axis_;
    Color intensity_;
};

// <emitter type="downlight"><point name="position" x="0" y="2" z="0"/><vector name="axis" x="0" y="-1" z="0"/>
//     <rgb name="intensity" value="10"/></emitter>
void register_downlight() {
    register_emitter("downlight", [](const PluginProperties &props) -> LightPtr {
        const Vec3 axis = props.node.get_vector("axis", Vec3(0, -1, 0));
        if (!(norm(axis) > 0)) throw props.error("the axis must not be zero");
        return std::make_unique<DownLight>(props.node.get_vector("position", Vec3(0.f)), axis,
                                           props.node.get_unbounded_rgb("intensity", Color(1.f)));
    });
}

}  // namespace example
