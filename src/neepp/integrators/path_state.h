// What the path integrator carries between passes for checkpoints and distributed rounds: the shadow-ray
// component's state, and with guiding=sdtree the SD-tree and the samples per pixel it has seen. Without
// guiding the state is the shadow-ray component's alone, as it always was.
#pragma once
#include <cstdint>
#include <string>

namespace neepp {

struct PathState {
    std::string shadow;
    std::string guide;   // SDTree::save(); empty: none yet
    int32_t guide_spp = 0;

    std::string encode(bool guiding) const;
    // Throws std::runtime_error if a guided state is malformed; an empty state is an empty one.
    static PathState decode(const std::string &bytes, bool guiding);
};

}  // namespace neepp
