#include "neepp/light_selection/factory.h"

#include <algorithm>
#include <stdexcept>
#include "neepp/light_selection/bayes_light_sampler.h"
#include "neepp/light_selection/bvh_light_sampler.h"
#include "neepp/light_selection/spatial_light_sampler.h"
#include "neepp/light_selection/visibility_bvh_light_sampler.h"
#include "neepp/light_selection/visibility_light_sampler.h"
#include "neepp/scene/scene.h"

namespace neepp {

const std::vector<std::string> &light_sampler_names() {
    static const std::vector<std::string> names = {"uniform", "power", "spatial", "spatial-oriented", "bvh",
                                                    "visibility", "visibility-power", "visibility-bvh",
                                                    "bayes", "bayes-va"};
    return names;
}

void check_light_sampler_name(const std::string &name) {
    const auto &names = light_sampler_names();
    if (std::find(names.begin(), names.end(), name) != names.end()) return;
    std::string list;
    for (const std::string &n : names) list += (list.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown light sampler '" + name + "' (supported: " + list + ")");
}

bool light_sampler_needs_visibility_map(const std::string &name, size_t light_count) {
    return light_count > 1 && (name == "visibility" || name == "visibility-power" || name == "visibility-bvh");
}

bool light_sampler_learns(const std::string &name) { return name == "bayes" || name == "bayes-va"; }

std::string merge_light_selection_states(const std::string &name, const std::string &base,
                                         const std::vector<std::string> &learned) {
    if (!light_sampler_learns(name)) return base;
    return BayesLightSampler::merge_encoded(base, learned);
}

std::unique_ptr<LightSampler> make_light_sampler(const std::string &name, std::vector<const Light *> lights,
                                                 const LightSelectionInputs &in) {
    check_light_sampler_name(name);
    if (name == "power" || lights.size() <= 1) return std::make_unique<PowerLightSampler>(std::move(lights));
    if (name == "uniform") return std::make_unique<UniformLightSampler>(std::move(lights));
    if (name == "bvh") return std::make_unique<BVHLightSampler>(std::move(lights));
    if (name == "spatial" || name == "spatial-oriented") {
        SpatialEstimateOptions o;
        o.oriented = name == "spatial-oriented";
        if (in.grid) return std::make_unique<SpatialLightSampler>(std::move(lights), *in.grid, o);
        if (!in.scene) throw std::invalid_argument("the spatial light sampler needs a scene or a grid");
        return std::make_unique<SpatialLightSampler>(std::move(lights), VoxelGrid(in.scene->bounds(), in.voxels), o);
    }
    if (name == "bayes" || name == "bayes-va") {
        BayesSelectionOptions o;
        o.second_moment = name == "bayes-va";
        if (in.grid) return std::make_unique<BayesLightSampler>(std::move(lights), *in.grid, o);
        if (!in.scene) throw std::invalid_argument("the Bayesian light sampler needs a scene or a grid");
        return std::make_unique<BayesLightSampler>(std::move(lights), VoxelGrid(in.scene->bounds(), in.voxels), o);
    }
    if (light_sampler_needs_visibility_map(name, lights.size())) {
        if (!in.grid || !in.map) throw std::invalid_argument("light sampler '" + name + "' needs NEE++'s visibility map");
        const Vec3 reference = in.scene ? in.scene->bounds().center() : in.grid->bounds().center();
        if (name == "visibility-bvh")
            return std::make_unique<VisibilityBVHLightSampler>(std::move(lights), *in.grid, *in.map, reference);
        VisibilitySelectionOptions o;
        o.base = name == "visibility" ? "spatial" : "power";
        return std::make_unique<VisibilityLightSampler>(std::move(lights), *in.grid, *in.map, reference, o);
    }
    throw std::logic_error("light sampler '" + name + "' is listed but not built");
}

}  // namespace neepp
