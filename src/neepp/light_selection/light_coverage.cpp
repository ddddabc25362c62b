#include "neepp/light_selection/light_coverage.h"

#include <map>
#include "neepp/sampling/rng.h"

namespace neepp {

std::vector<std::vector<CellWeight>> light_coverage(const VoxelGrid &grid, const std::vector<const Light *> &lights,
                                                    const Vec3 &reference, int samples_per_light) {
    std::vector<std::vector<CellWeight>> coverage(lights.size());
    for (size_t l = 0; l < lights.size(); ++l) {
        std::map<uint32_t, uint32_t> counts;  // ordered: the list (and everything built on it) is deterministic
        uint32_t total = 0;
        PCG32 rng(0xc0ffee ^ l, l);
        // A stratified grid of sample points: m × m of them.
        int m = 1;
        while ((m + 1) * (m + 1) <= samples_per_light) ++m;
        for (int i = 0; i < m * m; ++i) {
            Vec2 u((float(i % m) + rng.next_float()) / float(m), (float(i / m) + rng.next_float()) / float(m));
            Color Le;
            DirectionSample ds = lights[l]->sample_direction(reference, u, Le);
            // Area samples facing away from the reference still mark where the light is.
            const uint32_t cell = ds.dist >= kInfinity ? grid.cell_of_direction(ds.d) : grid.voxel_of(ds.p);
            ++counts[cell];
            ++total;
        }
        for (auto [cell, n] : counts) coverage[l].push_back({cell, float(n) / float(total)});
    }
    return coverage;
}

}  // namespace neepp
