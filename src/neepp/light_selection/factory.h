// Creates light samplers by name: uniform, power, spatial, bvh, visibility (NEE++ over the spatial
// estimate), visibility-power (NEE++ over power) and visibility-bvh (the light BVH reweighted by NEE++).
#pragma once
#include <memory>
#include <string>
#include <vector>
#include "neepp/lights/light_sampler.h"

namespace neepp {

class Scene;
class VoxelGrid;
class VisibilityMap;

struct LightSelectionInputs {
    const Scene *scene = nullptr;        // bounds for the spatial grid, reference point for light coverage
    const VoxelGrid *grid = nullptr;     // NEE++'s grid and map (required by the visibility samplers; the
    const VisibilityMap *map = nullptr;  // spatial sampler uses the grid when there is one)
    int voxels = 16;                     // resolution of the spatial sampler's own grid, without a map
};

// The names make_light_sampler accepts.
const std::vector<std::string> &light_sampler_names();
// Samplers that read the visibility map: the integrator must then keep one (NEE++'s shadow-ray component).
bool light_sampler_needs_visibility_map(const std::string &name);
// Throws std::invalid_argument for unknown names or missing inputs.
std::unique_ptr<LightSampler> make_light_sampler(const std::string &name, std::vector<const Light *> lights,
                                                 const LightSelectionInputs &inputs = {});

}  // namespace neepp
