// What a light sampler that learns from next event estimation's own samples offers beside the plain
// LightSampler interface (BayesLightSampler): the integrator reports each NEE sample it made, and carries
// what was learned through render checkpoints and distributed merges. The reports of a pass change
// nothing until the sampler's end_pass(), so every sample of a pass is drawn from, and weighted by, one
// frozen distribution: learning between passes keeps the pmf exact (NEEPP.md's rule for the map).
#pragma once
#include <string>
#include <vector>
#include "neepp/base/light_sampler.h"

namespace neepp {

class LightSelectionLearner {
public:
    virtual ~LightSelectionLearner() = default;
    // One NEE sample at ctx toward `light`: `estimate` is the luminance of the sample's contribution as if
    // this light had been chosen with probability 1, i.e. f·Le·cos·V / pdf_within_light, with the
    // shadow-ray component's weight for V (0 when occluded or rejected, 1/q when traced with probability
    // q): an unbiased one-sample estimate of the light's direct contribution at the shading point. Path
    // throughput and MIS weights are left out. Called concurrently from the render threads.
    virtual void record(const LightSampleContext &ctx, const Light &light, float estimate) const = 0;
    // What was learned (everything up to the last end_pass), as bytes, and its restoration; restore is
    // followed by the sampler's end_pass so the next pass reads it.
    virtual std::string save_state() const = 0;
    virtual void restore_state(const std::string &state) = 0;
    // Distributed rendering: renders continued from `base` each learned something; the state holding what
    // all of them learned.
    virtual std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const = 0;
};

}  // namespace neepp
