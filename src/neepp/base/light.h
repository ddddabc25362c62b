// The light interface: area lights on shapes, environment maps, constant environments and point lights.
#pragma once
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include "neepp/base/interaction.h"
#include "neepp/base/light_bounds.h"
#include "neepp/math/bbox.h"

namespace neepp {

struct LightLaneRecord;
class LightSampleSteps;

// A point on a light as seen from a reference point: where, which way, how likely.
struct DirectionSample {
    Vec3 p;              // point on the light (for infinite lights: a point far away along d)
    Vec3 n;              // light surface normal at p (zero for point and infinite lights)
    Vec3 ns;             // its shading normal, whose front emits (Mitsuba's convention)
    Vec3 d;              // unit direction from the reference point toward the light
    float dist = 0;      // distance to p (infinite for environment lights)
    float pdf = 0;       // solid-angle density at the reference point (1 for delta lights)
    bool delta = false;  // sampled from a delta distribution (point light): not reachable by BSDF sampling
};

// A ray leaving a light, for light paths (light tracing, BDPT): where it starts, which way, how likely.
// Infinite lights emit from a disk of the scene's bounding sphere's radius, facing the chosen direction and
// just outside the sphere, so every point of the scene is reached by parallel rays.
struct EmissionSample {
    Ray ray;            // its origin moved off the surface, as every ray leaving one
    Vec3 p;             // the point on the light (an infinite light's: the ray's origin on its disk)
    Vec3 n;             // geometric normal at the origin (zero for point and infinite lights)
    Vec3 ns;            // shading normal there (the side that emits)
    Vec2 uv;
    Color radiance;     // Le(origin, ray.d); a point light's intensity; an infinite light's radiance along -ray.d
    float pdf_pos = 0;  // area density of the origin (1 for a point light, 1 / (pi r^2) on an infinite light's disk)
    float pdf_dir = 0;  // solid-angle density of ray.d
    bool valid() const { return pdf_pos > 0 && pdf_dir > 0 && !is_black(radiance); }
};

// The densities with which sample_emission would produce an emitted ray (BDPT's MIS weights need them
// for rays it did not sample that way).
struct EmissionDensity {
    float pos = 0, dir = 0;
};

class Light {
public:
    virtual ~Light() = default;
    // Samples a direction toward the light from ref. Returns the emitted radiance arriving at ref along
    // -d, ignoring occlusion, via `radiance` (zero when the sample is invalid, e.g. the back of an area light).
    virtual DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const = 0;
    // Solid-angle density with which sample_direction would have produced ds from ref (0 for delta lights).
    virtual float pdf_direction(const Vec3 &ref, const DirectionSample &ds) const = 0;
    // An emitted ray from two pairs of variates, u_pos for the origin and u_dir for the direction.
    virtual EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const = 0;
    // The densities of an emitted ray leaving p (geometric normal n, shading normal ns) in direction w. For
    // infinite lights w is the direction of travel (into the scene) and p, n, ns are not read: the position
    // density is the disk's.
    virtual EmissionDensity pdf_emission(const Vec3 &p, const Vec3 &n, const Vec3 &ns, const Vec3 &w) const = 0;
    // Radiance leaving a point of an area light toward direction w (world, pointing away from the light).
    virtual Color eval_surface(const SurfaceInteraction &si, const Vec3 &w) const { return Color(0.f); }
    // Radiance arriving from an infinite light along direction d (world, pointing from the scene to the sky).
    virtual Color eval_environment(const Vec3 &d) const { return Color(0.f); }
    // Total emitted power, used by the power light sampler (up to a constant common to all lights).
    virtual Color power() const = 0;
    virtual bool is_infinite() const { return false; }
    virtual bool is_delta() const { return false; }
    // Called once the scene is built: its shapes final, its bounds known (infinite lights need them for
    // power and sample points; area lights see whether their shape can be sampled in lanes).
    virtual void prepare(const BBox &scene_bounds) {}
    // Where and which way the light emits, for the light BVH; none for infinite lights (sampled apart).
    virtual std::optional<LightBounds> bounds() const { return std::nullopt; }

    // Speed hooks, for the fast forms of integrators; a light that offers neither is sampled by
    // sample_direction, slower, the same in expectation.
    // Its samples in steps (base/light_steps.h), or null.
    virtual const LightSampleSteps *steps() const { return nullptr; }
    // For lights that integrators may sample in lanes (LightSampleLanes, light_lanes.h) with the same
    // distribution as sample_direction: what the lane kernel reads. Null: sample_direction only.
    const LightLaneRecord *lane_record() const { return lane_record_; }

    uint32_t index = 0;  // position in Scene::lights, for light samplers' tables

protected:
    const LightLaneRecord *lane_record_ = nullptr;
};

using LightPtr = std::unique_ptr<Light>;

// Builds a DirectionSample for a point found by tracing a ray from ref (a BSDF-sampled hit on an area
// light, or a miss for an environment), so pdf_direction can be asked for its MIS weight.
inline DirectionSample direction_sample_from_hit(const Vec3 &ref, const SurfaceInteraction &si) {
    DirectionSample ds;
    ds.p = si.p;
    ds.n = si.n;
    ds.ns = si.sh_frame.n;
    Vec3 d = si.p - ref;
    ds.dist = norm(d);
    ds.d = ds.dist > 0 ? d / ds.dist : Vec3(0, 0, 1);
    return ds;
}
// The one direction sample toward a light at a point (point, spot, projector lights: a delta, pdf 1) from
// ref; dist2 receives the squared distance, which the light's arriving radiance divides by.
inline DirectionSample direction_sample_to_point(const Vec3 &position, const Vec3 &ref, float &dist2) {
    DirectionSample ds;
    const Vec3 d = position - ref;
    dist2 = squared_norm(d);
    ds.p = position;
    ds.dist = std::sqrt(dist2);
    ds.d = d / ds.dist;
    ds.pdf = 1.f;
    ds.delta = true;
    return ds;
}
inline DirectionSample direction_sample_from_miss(const Vec3 &d) {
    DirectionSample ds;
    ds.d = d;
    ds.dist = kInfinity;
    return ds;
}

}  // namespace neepp
