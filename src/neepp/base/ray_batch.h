// A speed hook of ray integrators (RayIntegrator::batch): the radiance along many camera rays at once,
// for an integrator that gains from having many paths in flight (to hide memory latency, to trace rays in
// packets). A new integrator need not know it exists: without one, its Li renders. One that has it must
// compute what Li computes, path by path, and be tested against it (tests/integrators/test_path_forms.cpp).
#pragma once
#include <span>
#include "neepp/base/interaction.h"
#include "neepp/base/stats.h"

namespace neepp {

class Scene;
class Sampler;

class RayBatch {
public:
    virtual ~RayBatch() = default;
    // Each ray with its own sampler, set up for its pixel and sample; the results into out.
    virtual void Li_batch(const Scene &scene, std::span<const Ray> rays, std::span<Sampler *const> samplers,
                          std::span<Color> out, RenderCounters &counters) const = 0;
};

}  // namespace neepp
