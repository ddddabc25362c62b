#include "neepp/light_selection/within_light_sampling.h"

#include <stdexcept>
#include "neepp/light_selection/solid_angle_sampling.h"
#include "neepp/light_selection/visibility_environment.h"
#include "neepp/scene/scene.h"

namespace neepp {

const std::vector<std::string> &WithinLightSampling::names() {
    static const std::vector<std::string> n = {"own", "visibility"};
    return n;
}

const std::vector<std::string> &WithinLightSampling::area_light_names() {
    static const std::vector<std::string> n = {"area", "solid-angle"};
    return n;
}

WithinLightSampling::WithinLightSampling(const std::string &name, const Scene &scene, const VoxelGrid *grid,
                                         const VisibilityMap *map, const std::string &area_lights)
    : name_(name), area_lights_(area_lights) {
    if (name != "own" && name != "visibility")
        throw std::invalid_argument("within_light must be 'own' or 'visibility', not '" + name + "'");
    if (area_lights != "area" && area_lights != "solid-angle")
        throw std::invalid_argument("area_light_sampling must be 'area' or 'solid-angle', not '" + area_lights + "'");
    if (name == "visibility" && (!grid || !map))
        throw std::invalid_argument("within_light=visibility needs NEE++'s visibility map");
    by_index_.assign(scene.lights().size(), nullptr);
    for (const Light *light : scene.light_pointers()) {
        std::unique_ptr<ContextLightSampler> sampler;
        const auto *env = dynamic_cast<const EnvironmentMapLight *>(light);
        if (name == "visibility" && env) {
            sampler = std::make_unique<VisibilityEnvironmentSampler>(*env, *grid, *map);
            environment_ = sampler.get();
        } else if (area_lights == "solid-angle") {
            sampler = make_solid_angle_sampler(*light);
            if (sampler) ++solid_angle_lights_;
        }
        if (!sampler) continue;
        owned_.push_back(std::move(sampler));
        by_index_[light->index] = owned_.back().get();
    }
    if (owned_.empty()) by_index_.clear();  // for_light's answer without a lookup
}

void WithinLightSampling::end_pass() {
    for (auto &s : owned_) s->end_pass();
}

nlohmann::json WithinLightSampling::statistics() const {
    nlohmann::json j = {{"within_light", name_}, {"area_light_sampling", area_lights_}};
    if (environment_) j["environment"] = environment_->statistics();
    if (area_lights_ == "solid-angle") j["solid_angle_lights"] = solid_angle_lights_;
    return j;
}

}  // namespace neepp
