// Resampled importance sampling (RIS: Talbot, Cline & Egbert 2005; the single-frame, single-reservoir
// case of ReSTIR DI) of next event estimation's light samples, with NEE++'s visibility map in the target.
//
// M candidates x_1..x_M are drawn independently from the usual source: a light by the light sampler (pmf),
// a point on it by the light's own sampling or a ContextLightSampler (solid-angle density; the one point of
// a delta light has mass 1), so p(x) = pmf × pdf, in the measure plain NEE's estimate f(x)/p(x) uses. Each
// gets the target
//     p̂(x) = luminance(f_bsdf(x)·|cos| · Le(x)) × max(√Ṽ(shading voxel, cell of x), floor)
// and the weight w_i = p̂(x_i) / p(x_i). One y = x_s is chosen with probability w_s / Σw and weighted by
// W = Σw / (M p̂(y)); the estimate is g(y)·W, g = f_bsdf·|cos|·Le·V (V: one shadow ray).
// Why unbiased: given the candidates, E[g(y)·W] = Σ_s (w_s/Σw)·g(x_s)·Σw/(M p̂(x_s)) = (1/M) Σ_{p̂(x_s)>0}
// g(x_s)/p(x_s), the mean of M plain NEE estimates over the candidates with p̂ > 0. So the expectation is
// plain NEE's, provided g = 0 wherever p̂ = 0: the floor keeps p̂ > 0 wherever f·Le > 0, so a map that
// calls a visible pair occluded costs variance (a weight at most 1/floor times a right map's), never bias.
// Candidates with p̂ = 0 (the light's back, a light below the surface) are counted in M all the same,
// as the mean above needs: each is a plain NEE estimate of 0.
// Why √Ṽ and not Ṽ: as M grows, y follows p̂ / ∫p̂, and for a pair through which a fraction ν of rays
// gets, the estimate's second moment is ∫p̂ · ∫ f·ν/h for p̂ = f·h; Cauchy-Schwarz puts its least at
// h ∝ √ν (as for within_light=visibility). It also halves, in log terms, what a wrong estimate costs.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include "neepp/base/light.h"
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

// The map's share of the target: max(√Ṽ, floor) between a shading point's voxel and a light sample's cell.
// Without a map (or before it is seeded) every pair counts as visible: RIS by unoccluded contribution.
class ResamplingVisibility {
public:
    ResamplingVisibility() = default;
    // grid and map may be null; when given they must outlive this object (the map's values are read as
    // they are when asked: a pass reads its frozen snapshot).
    ResamplingVisibility(const VoxelGrid *grid, const VisibilityMap *map, float floor)
        : grid_(grid), map_(map && grid && map->pair_count() ? map : nullptr), floor_(floor) {}

    bool uses_map() const { return map_ != nullptr; }
    uint32_t shading_cell(const Vec3 &p) const { return map_ ? grid_->voxel_of(p) : 0; }
    uint32_t light_cell(const DirectionSample &ds) const {
        return map_ ? grid_->cell_of_end(ds.p, ds.d, ds.dist >= kInfinity) : 0;
    }
    // A cache prefetch of the pair's entry, for a batch that reads it a stage later.
    void prefetch(uint32_t a, uint32_t b) const {
        if (map_) map_->prefetch(VisibilityMap::pair_index(a, b));
    }
    float operator()(uint32_t a, uint32_t b) const {
        return map_ ? std::max(std::sqrt(map_->estimate_or_visible(a, b)), floor_) : 1.f;
    }

private:
    const VoxelGrid *grid_ = nullptr;
    const VisibilityMap *map_ = nullptr;
    float floor_ = 1.f;
};

// One of n weights chosen by one uniform number u: index i with probability w_i / Σw (w_i >= 0 and
// finite). Returns -1 when Σw is 0 or not finite; sum receives Σw.
int choose_proportional(const float *weights, int n, float u, float &sum);

}  // namespace neepp
