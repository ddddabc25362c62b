#include "neepp/light_selection/light_coverage.h"

#include <map>
#include <stdexcept>
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
            const uint32_t cell = grid.cell_of_end(ds.p, ds.d, ds.dist >= kInfinity);
            ++counts[cell];
            ++total;
        }
        for (auto [cell, n] : counts) coverage[l].push_back({cell, float(n) / float(total)});
    }
    return coverage;
}

LightVisibility::LightVisibility(const VoxelGrid &grid, const VisibilityMap &map, const std::vector<const Light *> &lights,
                                 const Vec3 &reference)
    : map_(map) {
    if (map.cell_count() != grid.cell_count()) throw std::invalid_argument("light visibility: map and grid disagree");
    auto by_position = light_coverage(grid, lights, reference);
    for (size_t i = 0; i < lights.size(); ++i) {
        if (lights[i]->index >= coverage_.size()) coverage_.resize(lights[i]->index + 1);
        coverage_[lights[i]->index] = std::move(by_position[i]);
    }
}

float LightVisibility::operator()(uint32_t voxel, const Light &light) const {
    if (light.index >= coverage_.size()) return 1.f;
    double v = 0;
    for (const CellWeight &cw : coverage_[light.index]) {
        v += double(cw.weight) * double(map_.estimate_or_visible(voxel, cw.cell));
    }
    return float(v);
}

uint64_t LightVisibility::covered_cells() const {
    uint64_t n = 0;
    for (auto &c : coverage_) n += c.size();
    return n;
}

}  // namespace neepp
