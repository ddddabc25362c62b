// What the path integrator carries between passes for checkpoints and distributed rounds: the shadow-ray
// component's state, with guiding=sdtree the SD-tree and the samples per pixel it has seen (guiding=map: the
// map guide's totals), and with a light
// sampler that learns (light_selection_learner.h) what it learned. Without either the state is the
// shadow-ray component's alone, as it always was.
#pragma once
#include <cstdint>
#include <string>

namespace neepp {

struct PathState {
    std::string shadow;
    std::string guide;      // SDTree::save(); empty: none yet
    int32_t guide_spp = 0;
    std::string light;      // the learning light sampler's; empty: none
    std::string map_guide;  // MapGuide::save(); empty: none

    // framed: guiding or a learning light sampler, whose parts need a frame around the shadow state.
    std::string encode(bool framed) const;
    // Throws std::runtime_error if a framed state is malformed; an empty state is an empty one. Reads the
    // frames of the states saved before the light part (G1) and the map guide's own part (G2, which held a
    // guiding=map state's guide in `guide`: decode(..., map_guided) moves it) existed too.
    static PathState decode(const std::string &bytes, bool framed, bool map_guided = false);
};

}  // namespace neepp
