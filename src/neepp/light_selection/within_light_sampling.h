// How next event estimation samples a point on the light it chose: by the light's own sampling
// (Light::sample_direction, which knows only the shading point's position), by a sampler that also
// knows the shading point's voxel and orientation (NEE++'s visibility map carried inside a light:
// VisibilityEnvironmentSampler), or, for rectangle and sphere lights, in the solid angle they subtend
// rather than by area (solid_angle_sampling.h). An integrator asks for_light(light) once it has chosen a light, and
// then samples and asks densities through what it got, if anything.
#pragma once
#include <memory>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "neepp/base/light_sampler.h"
#include "neepp/base/light_steps.h"

namespace neepp {

class Scene;
class VoxelGrid;
class VisibilityMap;

// Points of one light, sampled for a shading context. The density must be exactly reproducible from
// (ctx, ds) alone, as MIS asks it for BSDF-sampled rays that reach the light.
class ContextLightSampler {
public:
    virtual ~ContextLightSampler() = default;
    // As Light::sample_direction, from the shading point ctx.p, knowing its normal; in steps as Light's
    // (prefetch, begin, finish), for batched integrators: finish(ctx, begin(ctx, u)) is sample(ctx, u).
    DirectionSample sample(const LightSampleContext &ctx, Vec2 u, Color &radiance) const {
        return finish(ctx, begin(ctx, u), radiance);
    }
    virtual void prefetch(const LightSampleContext &ctx, Vec2 u) const {}
    virtual LightSampleStart begin(const LightSampleContext &ctx, Vec2 u) const { return {u}; }
    virtual DirectionSample finish(const LightSampleContext &ctx, const LightSampleStart &start, Color &radiance) const = 0;
    virtual float pdf(const LightSampleContext &ctx, const DirectionSample &ds) const = 0;
    // Speed hook for batched integrators: where this sampler would draw by the light's own sampling at
    // ctx (finish calls Light::sample_direction), the light's lane record (Light::lane_record), so that
    // the sample is taken in lanes as the light's own are; else null.
    virtual const LightLaneRecord *own_lane_record(const LightSampleContext &ctx) const { return nullptr; }
    virtual void end_pass() {}  // between passes, single-threaded: the map has learned
    virtual nlohmann::json statistics() const { return nlohmann::json::object(); }
};

class WithinLightSampling {
public:
    // "own": every light samples itself. "visibility": environment maps sample per shading voxel and
    // orientation by the visibility map (grid and map must then be given, and outlive this object).
    static const std::vector<std::string> &names();
    // How area lights are sampled: "area" (their own sampling, uniform in area) or "solid-angle"
    // (rectangles and spheres in the solid angle they subtend; other shapes by area all the same).
    static const std::vector<std::string> &area_light_names();
    WithinLightSampling() = default;
    WithinLightSampling(const std::string &name, const Scene &scene, const VoxelGrid *grid, const VisibilityMap *map,
                        const std::string &area_lights = "area");

    // The sampler for points of `light`; null: the light's own sampling.
    const ContextLightSampler *for_light(const Light &light) const {
        return light.index < by_index_.size() ? by_index_[light.index] : nullptr;
    }
    bool any() const { return !owned_.empty(); }
    void end_pass();
    nlohmann::json statistics() const;

private:
    std::string name_ = "own", area_lights_ = "area";
    std::vector<std::unique_ptr<ContextLightSampler>> owned_;
    const ContextLightSampler *environment_ = nullptr;  // the visibility map's, for statistics
    int solid_angle_lights_ = 0;
    std::vector<const ContextLightSampler *> by_index_;  // by Light::index
};

}  // namespace neepp
