// Which cells of the NEE++ grid a light covers, and how much of it lies in each: the "list of voxels a
// light is linked to" of the paper. Found by drawing the light's own samples (Light::sample_direction),
// so a cell weighs what it weighs among the end points of the shadow rays NEE traces toward that light:
// area for area lights, luminance for environment maps (whose cells are the grid's direction bins).
#pragma once
#include <vector>
#include "neepp/base/light.h"
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

struct CellWeight {
    uint32_t cell;
    float weight;  // fractions summing to 1 over a light's cells
};

// One list per light, indexed like `lights`. `reference` is where samples are drawn from (it only
// matters for lights whose sampling depends on it: their visible part is what counts from there).
std::vector<std::vector<CellWeight>> light_coverage(const VoxelGrid &grid, const std::vector<const Light *> &lights,
                                                    const Vec3 &reference, int samples_per_light = 4096);

// Ṽ(a, l): the visibility map's estimate between voxel a and light l, i.e. the coverage-weighted mean of
// Ṽ(a, b) over the cells b that l covers. Pairs the map has never seen, and a's own voxel (whose
// visibility the map cannot resolve), count as visible. Lights are addressed by Light::index.
class LightVisibility {
public:
    // map must outlive this object (it keeps learning between passes; values follow it).
    LightVisibility(const VoxelGrid &grid, const VisibilityMap &map, const std::vector<const Light *> &lights,
                    const Vec3 &reference);
    float operator()(uint32_t voxel, const Light &light) const;
    uint64_t covered_cells() const;

private:
    const VisibilityMap &map_;
    std::vector<std::vector<CellWeight>> coverage_;  // by Light::index
};

}  // namespace neepp
