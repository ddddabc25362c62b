#include "neepp/integrators/path_state.h"

#include <cstring>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>
#include "neepp/guiding/sd_tree.h"
#include "neepp/base/light_selection_learner.h"
#include "neepp/integrators/path.h"
#include "neepp/light_selection/factory.h"

namespace neepp {

namespace {
constexpr char kMagicGuide[8] = {'N', 'E', 'E', 'P', 'P', 'P', 'G', '1'};  // shadow, guide
constexpr char kMagicLight[8] = {'N', 'E', 'E', 'P', 'P', 'P', 'G', '2'};  // shadow, guide, light
constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'P', 'G', '3'};       // shadow, tree, light, map guide

template <typename T> void put(std::string &out, const T &v) { out.append(reinterpret_cast<const char *>(&v), sizeof v); }
template <typename T> T get(const std::string &data, size_t &offset) {
    if (offset + sizeof(T) > data.size()) throw std::runtime_error("path state: truncated");
    T v;
    std::memcpy(&v, data.data() + offset, sizeof v);
    offset += sizeof v;
    return v;
}
std::string get_bytes(const std::string &data, size_t &offset) {
    const uint64_t n = get<uint64_t>(data, offset);
    if (n > data.size() - offset) throw std::runtime_error("path state: truncated");
    std::string out = data.substr(offset, n);
    offset += n;
    return out;
}
}  // namespace

std::string PathState::encode(bool framed) const {
    if (!framed) return shadow;
    std::string out(kMagic, sizeof kMagic);
    put(out, guide_spp);
    put(out, uint64_t(shadow.size()));
    out += shadow;
    put(out, uint64_t(guide.size()));
    out += guide;
    put(out, uint64_t(light.size()));
    out += light;
    put(out, uint64_t(map_guide.size()));
    out += map_guide;
    return out;
}

PathState PathState::decode(const std::string &bytes, bool framed, bool map_guided) {
    PathState s;
    if (!framed || bytes.empty()) {
        s.shadow = bytes;
        return s;
    }
    auto starts = [&](const char (&magic)[8]) {
        return bytes.size() >= sizeof magic && std::memcmp(bytes.data(), magic, sizeof magic) == 0;
    };
    const int version = starts(kMagicGuide) ? 1 : starts(kMagicLight) ? 2 : starts(kMagic) ? 3 : 0;
    if (version == 0)
        throw std::runtime_error("path state: not a guided or learning path integrator's state (was it saved with the same "
                                 "-I guiding and light_sampler?)");
    size_t offset = sizeof kMagic;
    s.guide_spp = get<int32_t>(bytes, offset);
    s.shadow = get_bytes(bytes, offset);
    s.guide = get_bytes(bytes, offset);
    if (version >= 2) s.light = get_bytes(bytes, offset);
    if (version >= 3) s.map_guide = get_bytes(bytes, offset);
    else if (map_guided) s.map_guide = std::exchange(s.guide, std::string());
    if (offset != bytes.size()) throw std::runtime_error("path state: trailing bytes");
    return s;
}

bool PathIntegrator::framed_state() const {
    return options_.guiding != "none" || light_sampler_learns(options_.light_sampler);
}

std::string PathIntegrator::save_state() const {
    PathState s;
    s.shadow = shadow_->save_state();
    if (guide_ && guide_learns_) {
        s.guide = guide_->save();
        s.guide_spp = guide_spp_;
    }
    if (map_guide_ && guide_learns_) s.map_guide = map_guide_->save();
    if (learner_) s.light = learner_->save_state();
    return s.encode(framed_state());
}

// The shadow-ray states merged as the component merges them; the trees by SDTree::merge, the map guides
// by MapGuide::merge (the base's totals plus what each render added), the guided
// renders' sample counts by the largest (it only scales the spatial split threshold); a learning light
// sampler's states by its own merge (which needs no prepared sampler: this integrator may be a fresh one).
std::string PathIntegrator::merge_states(const std::string &base, const std::vector<std::string> &learned) const {
    if (!framed_state()) return shadow_->merge_states(base, learned);
    if (learned.empty()) return base;
    const PathState b = PathState::decode(base, true, options_.guides_by_map());
    std::vector<std::string> shadows, lights, map_guides;
    std::vector<SDTree> trees;
    PathState merged;
    for (const std::string &l : learned) {
        PathState s = PathState::decode(l, true, options_.guides_by_map());
        shadows.push_back(std::move(s.shadow));
        lights.push_back(std::move(s.light));
        if (!s.map_guide.empty()) map_guides.push_back(std::move(s.map_guide));
        if (!s.guide.empty()) trees.push_back(SDTree::decode(s.guide));
        merged.guide_spp = std::max(merged.guide_spp, s.guide_spp);
    }
    merged.shadow = shadow_->merge_states(b.shadow, shadows);
    std::vector<const SDTree *> pointers;
    for (const SDTree &t : trees) pointers.push_back(&t);
    merged.guide = pointers.empty() ? b.guide : SDTree::merge(pointers).save();
    merged.map_guide = map_guides.empty() ? b.map_guide : MapGuide::merge(b.map_guide, map_guides);
    merged.light = merge_light_selection_states(options_.light_sampler, b.light, lights);
    return merged.encode(true);
}

}  // namespace neepp
