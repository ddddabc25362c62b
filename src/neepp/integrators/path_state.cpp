#include "neepp/integrators/path_state.h"

#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>
#include "neepp/guiding/sd_tree.h"
#include "neepp/integrators/path.h"

namespace neepp {

namespace {
constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'P', 'G', '1'};

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

std::string PathState::encode(bool guiding) const {
    if (!guiding) return shadow;
    std::string out(kMagic, sizeof kMagic);
    put(out, guide_spp);
    put(out, uint64_t(shadow.size()));
    out += shadow;
    put(out, uint64_t(guide.size()));
    out += guide;
    return out;
}

PathState PathState::decode(const std::string &bytes, bool guiding) {
    PathState s;
    if (!guiding || bytes.empty()) {
        s.shadow = bytes;
        return s;
    }
    if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        throw std::runtime_error("path state: not a guided path integrator's state (was it saved with -I guiding=sdtree?)");
    size_t offset = sizeof kMagic;
    s.guide_spp = get<int32_t>(bytes, offset);
    s.shadow = get_bytes(bytes, offset);
    s.guide = get_bytes(bytes, offset);
    if (offset != bytes.size()) throw std::runtime_error("path state: trailing bytes");
    return s;
}

std::string PathIntegrator::save_state() const {
    PathState s;
    s.shadow = shadow_->save_state();
    if (guide_ && guide_learns_) {
        s.guide = guide_->save();
        s.guide_spp = guide_spp_;
    }
    return s.encode(options_.guiding);
}

// The shadow-ray states merged as the component merges them; the trees by SDTree::merge, the guided
// renders' sample counts by the largest (it only scales the spatial split threshold).
std::string PathIntegrator::merge_states(const std::string &base, const std::vector<std::string> &learned) const {
    if (!options_.guiding) return shadow_->merge_states(base, learned);
    if (learned.empty()) return base;
    const PathState b = PathState::decode(base, true);
    std::vector<std::string> shadows;
    std::vector<SDTree> trees;
    PathState merged;
    for (const std::string &l : learned) {
        PathState s = PathState::decode(l, true);
        shadows.push_back(std::move(s.shadow));
        if (!s.guide.empty()) trees.push_back(SDTree::decode(s.guide));
        merged.guide_spp = std::max(merged.guide_spp, s.guide_spp);
    }
    merged.shadow = shadow_->merge_states(b.shadow, shadows);
    std::vector<const SDTree *> pointers;
    for (const SDTree &t : trees) pointers.push_back(&t);
    merged.guide = pointers.empty() ? b.guide : SDTree::merge(pointers).save();
    return merged.encode(true);
}

}  // namespace neepp
