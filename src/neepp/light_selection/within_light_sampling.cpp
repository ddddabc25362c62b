#include "neepp/light_selection/within_light_sampling.h"

#include <stdexcept>
#include "neepp/light_selection/visibility_environment.h"
#include "neepp/scene/scene.h"

namespace neepp {

const std::vector<std::string> &WithinLightSampling::names() {
    static const std::vector<std::string> n = {"own", "visibility"};
    return n;
}

WithinLightSampling::WithinLightSampling(const std::string &name, const Scene &scene, const VoxelGrid *grid,
                                         const VisibilityMap *map)
    : name_(name) {
    if (name == "own") return;
    if (name != "visibility") throw std::invalid_argument("within_light must be 'own' or 'visibility', not '" + name + "'");
    if (!grid || !map) throw std::invalid_argument("within_light=visibility needs NEE++'s visibility map");
    by_index_.assign(scene.lights().size(), nullptr);
    for (const Light *light : scene.light_pointers())
        if (const auto *env = dynamic_cast<const EnvironmentMapLight *>(light)) {
            owned_.push_back(std::make_unique<VisibilityEnvironmentSampler>(*env, *grid, *map));
            by_index_[light->index] = owned_.back().get();
        }
}

void WithinLightSampling::end_pass() {
    for (auto &s : owned_) s->end_pass();
}

nlohmann::json WithinLightSampling::statistics() const {
    nlohmann::json j = {{"within_light", name_}};
    if (!owned_.empty()) j["environment"] = owned_.front()->statistics();
    return j;
}

}  // namespace neepp
