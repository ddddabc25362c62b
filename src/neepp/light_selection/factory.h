// Creates light samplers by name: uniform, power, spatial, bvh, visibility (NEE++ over the spatial
// estimate), visibility-power (NEE++ over power), visibility-bvh (the light BVH reweighted by NEE++), and
// bayes / bayes-va (the light BVH's cut learned from NEE's own samples, Vévoda et al. 2018).
#pragma once
#include <memory>
#include <string>
#include <vector>
#include "neepp/base/light_sampler.h"

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

// The names make_light_sampler accepts; check_light_sampler_name throws std::invalid_argument, listing
// them, for any other.
const std::vector<std::string> &light_sampler_names();
void check_light_sampler_name(const std::string &name);
// Whether sampler `name` over light_count lights reads the visibility map, so the integrator must keep
// one (NEE++'s shadow-ray component). Without a count: whether it may, for some scene.
bool light_sampler_needs_visibility_map(const std::string &name, size_t light_count = 2);
// Whether sampler `name` learns from NEE's own samples (LightSampler::learner()), so the integrator carries
// its state through checkpoints; and that state's merge for distributed renders, which needs no sampler.
bool light_sampler_learns(const std::string &name);
std::string merge_light_selection_states(const std::string &name, const std::string &base,
                                         const std::vector<std::string> &learned);
// Throws std::invalid_argument for unknown names or missing inputs. With a single light every sampler's
// pmf is 1, so every name gives the cheapest, power (whose statistics then say so).
std::unique_ptr<LightSampler> make_light_sampler(const std::string &name, std::vector<const Light *> lights,
                                                 const LightSelectionInputs &inputs = {});

}  // namespace neepp
