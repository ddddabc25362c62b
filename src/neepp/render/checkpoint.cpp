#include "neepp/render/checkpoint.h"

#include <cstring>
#include <fmt/format.h>
#include "neepp/io/atomic_file.h"
#include "neepp/io/binary_io.h"
#include "neepp/io/checksum.h"

namespace neepp {
namespace {

constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'C', 'K', 'P'};
// Version 2: the counters gained the media counters (density and transmittance lookups). Version 3: the
// driver's part (distributed renders); a version 2 file reads as a checkpoint without one.
constexpr uint32_t kVersion = 3;
static_assert(std::is_trivially_copyable_v<RenderCounters>);

}  // namespace

std::string checkpoint_bytes(const RenderCheckpoint &c) {
    BinaryWriter w;
    w.bytes.append(kMagic, 8);
    w.put(kVersion);
    w.put_string(c.identity);
    w.put(int32_t(c.spp));
    w.put(int32_t(c.passes));
    w.put(c.render_time_s);
    w.put(c.seconds_per_spp);
    w.put(c.light_paths);
    w.put(c.counters);
    w.put_vector(c.image_sums);
    w.put_vector(c.splat_sums);
    w.put_string(c.integrator_state);
    w.put_string(c.driver);
    w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
    return std::move(w.bytes);
}

void save_checkpoint(const std::string &path, const RenderCheckpoint &c) {
    try {
        write_file_atomically(path, checkpoint_bytes(c));
    } catch (const std::exception &e) {
        throw std::runtime_error(fmt::format("checkpoint {}", e.what()));
    }
}

RenderCheckpoint load_checkpoint(const std::string &path) {
    const std::string what = fmt::format("checkpoint '{}'", path);
    const std::string bytes = read_file_bytes(path, what);
    if (bytes.size() < 8 + 4 + 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
        throw std::runtime_error(what + ": not a neepp render checkpoint");
    uint64_t stored;
    std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
    if (stored != fnv1a64(bytes.data(), bytes.size() - 8))
        throw std::runtime_error(what + ": checksum mismatch: the file is damaged");
    const std::string body = bytes.substr(0, bytes.size() - 8);
    BinaryReader r{body, 8, what};
    const uint32_t version = r.get<uint32_t>();
    if (version != kVersion && version != 2)
        throw std::runtime_error(fmt::format("{}: unsupported version {} (this build reads versions 2 to {})", what, version, kVersion));
    RenderCheckpoint c;
    c.identity = r.get_string();
    c.spp = r.get<int32_t>();
    c.passes = r.get<int32_t>();
    c.render_time_s = r.get<double>();
    c.seconds_per_spp = r.get<double>();
    c.light_paths = r.get<double>();
    c.counters = r.get<RenderCounters>();
    c.image_sums = r.get_vector<double>();
    c.splat_sums = r.get_vector<int64_t>();
    c.integrator_state = r.get_string();
    if (version >= 3) c.driver = r.get_string();
    if (r.pos != body.size() || c.spp < 1 || c.passes < 1) throw std::runtime_error(what + ": malformed");
    return c;
}

}  // namespace neepp
