#include "neepp/light_selection/factory.h"

#include <stdexcept>
#include "neepp/light_selection/bvh_light_sampler.h"
#include "neepp/light_selection/spatial_light_sampler.h"
#include "neepp/light_selection/visibility_bvh_light_sampler.h"
#include "neepp/light_selection/visibility_light_sampler.h"
#include "neepp/scene/scene.h"

namespace neepp {

const std::vector<std::string> &light_sampler_names() {
    static const std::vector<std::string> names = {"uniform", "power", "spatial", "spatial-oriented", "bvh",
                                                    "visibility", "visibility-power", "visibility-bvh"};
    return names;
}

bool light_sampler_needs_visibility_map(const std::string &name) {
    return name == "visibility" || name == "visibility-power" || name == "visibility-bvh";
}

std::unique_ptr<LightSampler> make_light_sampler(const std::string &name, std::vector<const Light *> lights,
                                                 const LightSelectionInputs &in) {
    if (name == "uniform") return std::make_unique<UniformLightSampler>(std::move(lights));
    if (name == "power") return std::make_unique<PowerLightSampler>(std::move(lights));
    if (name == "bvh") return std::make_unique<BVHLightSampler>(std::move(lights));
    if (name == "spatial" || name == "spatial-oriented") {
        SpatialEstimateOptions o;
        o.oriented = name == "spatial-oriented";
        if (in.grid) return std::make_unique<SpatialLightSampler>(std::move(lights), *in.grid, o);
        if (!in.scene) throw std::invalid_argument("the spatial light sampler needs a scene or a grid");
        return std::make_unique<SpatialLightSampler>(std::move(lights), VoxelGrid(in.scene->bounds(), in.voxels), o);
    }
    if (light_sampler_needs_visibility_map(name)) {
        if (!in.grid || !in.map) throw std::invalid_argument("light sampler '" + name + "' needs NEE++'s visibility map");
        const Vec3 reference = in.scene ? in.scene->bounds().center() : in.grid->bounds().center();
        if (name == "visibility-bvh")
            return std::make_unique<VisibilityBVHLightSampler>(std::move(lights), *in.grid, *in.map, reference);
        VisibilitySelectionOptions o;
        o.base = name == "visibility" ? "spatial" : "power";
        return std::make_unique<VisibilityLightSampler>(std::move(lights), *in.grid, *in.map, reference, o);
    }
    std::string list;
    for (const std::string &n : light_sampler_names()) list += (list.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown light sampler '" + name + "' (supported: " + list + ")");
}

}  // namespace neepp
