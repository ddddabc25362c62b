// The path tracer's fast form: PathIntegrator::Li (the reference form, path.cpp) computed for a batch of
// camera paths at once. The paths advance in lockstep, one bounce at a time and stage by stage, each
// stage issuing cache prefetches that the next stage, reached after the other paths' work, finds
// complete: without it the render waits on misses (mesh data, textures, environment-map tables) as long
// as it traces. Rays go to Embree in packets, hit records are filled and rectangle lights sampled eight
// at a time. Each path draws the same random numbers in the same order as Li; tests/integrators/
// test_path_forms.cpp holds the two forms together.
#pragma once
#include <span>
#include "neepp/base/ray_batch.h"
#include "neepp/integrators/path.h"

namespace neepp {

class LightSampleLanes;

class PathBatch final : public RayBatch {
public:
    explicit PathBatch(const PathIntegrator &integrator) : pi_(integrator) {}
    void Li_batch(const Scene &scene, std::span<const Ray> rays, std::span<Sampler *const> samplers,
                  std::span<Color> out, RenderCounters &counters) const override;

private:
    struct Candidate;  // one light sample of next event estimation
    struct Path;       // one path's state between stages
    // Stages of one bounce. begin_vertex adds the emission the ray found and chooses the lights for next
    // event estimation; it and finish_vertex return false when the path ends.
    bool begin_vertex(const Scene &scene, Path &path) const;
    // Next event estimation at the vertex: begin_light and sample_light sample the light chosen at
    // begin_vertex in two steps where the light offers them (LightSampleSteps: begin, finish), and eight at
    // a time where it allows (LightSampleLanes: a rectangle of constant radiance); with resampling (ris > 1)
    // that is done for each candidate, weigh_candidates evaluates the BSDF toward each and prefetches its
    // map entry, and resample reads the entries and chooses one; begin_direct forms the shadow query
    // (false: it contributes nothing); decide_direct asks the shadow-ray policy and returns true when a ray
    // must be traced, whose outcome end_direct takes.
    void begin_light(Path &path) const;
    void sample_light(Path &path, LightSampleLanes &lanes) const;
    void weigh_candidates(Path &path) const;
    void resample(Path &path) const;
    bool begin_direct(Path &path) const;
    bool decide_direct(Path &path, RenderCounters &counters) const;
    void end_direct(Path &path, bool occluded) const;
    // Tells a learning light sampler the plain NEE sample's outcome (the shadow test's weight).
    void learn_direct(const Path &path, float visibility) const;
    // BSDF sampling and Russian roulette: the next ray, or false when the path ends.
    bool finish_vertex(Path &path) const;

    const PathIntegrator &pi_;
};

}  // namespace neepp
