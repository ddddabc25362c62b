#include "neepp/visibility/map_file.h"

#include <cstring>
#include <stdexcept>
#include <fmt/format.h>
#include "neepp/io/atomic_file.h"
#include "neepp/io/binary_io.h"
#include "neepp/scene/scene.h"

namespace neepp {

namespace {

constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'V', 'I', 'S'};
constexpr uint32_t kVersion = 1;

// Magic, version and checksum, before anything else is read: a damaged file must not be read any further,
// whatever the damage.
void check_envelope(const std::string &bytes, const std::string &what) {
    auto fail = [&](const std::string &why) { return std::runtime_error(fmt::format("{}: {}", what, why)); };
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0) throw fail("not a neepp visibility map (bad magic)");
    if (bytes.size() < 8 + 4 + 8) throw fail("file is truncated");
    uint64_t stored;
    std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
    uint64_t actual = fnv1a64(bytes.data(), bytes.size() - 8);
    BinaryReader r{bytes, 8, what};
    uint32_t version = r.get<uint32_t>();
    if (version != kVersion) throw fail(fmt::format("unsupported version {} (this build reads version {})", version, kVersion));
    if (stored != actual)
        throw fail(fmt::format("checksum mismatch (stored {:016x}, computed {:016x}): the file is damaged", stored, actual));
}

}  // namespace

uint64_t scene_fingerprint(const Scene &scene) {
    // What each shape's digest adds is mixed in as it comes.
    struct Digest final : GeometryDigest {
        uint64_t h = fnv1a64("neepp-scene-v2", 14);
        void add(const void *data, size_t bytes) override { h = fnv1a64(data, bytes, h); }
        using GeometryDigest::add;
    } digest;
    uint64_t shapes = scene.shapes().size(), lights = scene.lights().size();
    digest.add(shapes);
    for (const auto &s : scene.shapes()) s->digest(digest);
    uint64_t &h = digest.h;
    auto mix = [&](const void *d, size_t n) { h = fnv1a64(d, n, h); };
    mix(&lights, sizeof lights);
    for (const auto &l : scene.lights()) {
        uint8_t flags = uint8_t(l->is_infinite()) | uint8_t(l->is_delta() << 1);
        mix(&flags, 1);
    }
    mix(&scene.bounds().lo, sizeof(Vec3));
    mix(&scene.bounds().hi, sizeof(Vec3));
    if (scene.has_media()) {
        // Media change what the map learns (expected transmittance): their bounds on density, and which
        // media the shapes bound and the camera sits in. Media-free scenes keep the fingerprint they had.
        const auto &media = scene.media();
        auto index_of = [&](const Medium *m) {
            int32_t i = -1;
            for (size_t k = 0; k < media.size(); ++k)
                if (media[k].get() == m) i = int32_t(k);
            return i;
        };
        mix("media", 5);
        for (const auto &m : media) {
            // Along each axis: a microflake medium's extinction depends on the direction.
            const Color majorant[3] = {m->majorant(Vec3(1, 0, 0)), m->majorant(Vec3(0, 1, 0)), m->majorant(Vec3(0, 0, 1))};
            const uint8_t flags = uint8_t(m->homogeneous()) | uint8_t(m->sample_emitters << 1);
            mix(majorant, sizeof majorant);
            mix(&flags, 1);
        }
        for (const auto &s : scene.shapes()) {
            const int32_t sides[2] = {index_of(s->interior), index_of(s->exterior)};
            mix(sides, sizeof sides);
        }
        const int32_t camera = index_of(scene.camera.medium);
        mix(&camera, sizeof camera);
    }
    return h;
}

std::string encode_visibility_map(const VoxelGrid &grid, const VisibilityMap &map, uint64_t fingerprint) {
    if (map.cell_count() != grid.cell_count())
        throw std::invalid_argument("encode_visibility_map: map and grid have different cell counts");
    BinaryWriter w;
    w.bytes.append(kMagic, 8);
    w.put(kVersion);
    w.put(uint32_t(grid.resolution()));
    w.put(uint32_t(VoxelGrid::kDirectionBins));
    w.put(grid.bounds().lo);
    w.put(grid.bounds().hi);
    w.put(fingerprint);
    w.put(map.known_pairs());
    const auto &data = map.data();
    for (uint64_t i = 0; i < data.size(); ++i)
        if (data[i].traced) {
            w.put(uint32_t(i));
            w.put(data[i].visible);
            w.put(data[i].traced);
        }
    w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
    return std::move(w.bytes);
}

void save_visibility_map(const std::string &path, const VoxelGrid &grid, const VisibilityMap &map, uint64_t fingerprint) {
    const std::string bytes = encode_visibility_map(grid, map, fingerprint);
    try {
        write_file_atomically(path, bytes);
    } catch (const std::exception &e) {
        throw std::runtime_error(fmt::format("visibility map {}", e.what()));
    }
}

VisibilityMap load_visibility_map(const std::string &path, const VoxelGrid &grid, uint64_t fingerprint) {
    const std::string what = fmt::format("visibility map '{}'", path);
    return decode_visibility_map(read_file_bytes(path, what), what, grid, fingerprint);
}

std::pair<VoxelGrid, VisibilityMap> load_visibility_map(const std::string &path, uint64_t fingerprint) {
    const std::string what = fmt::format("visibility map '{}'", path);
    return decode_visibility_map(read_file_bytes(path, what), what, fingerprint);
}

VisibilityMap decode_visibility_map(const std::string &bytes, const std::string &what, const VoxelGrid &grid,
                                    uint64_t fingerprint) {
    auto fail = [&](const std::string &why) { return std::runtime_error(fmt::format("{}: {}", what, why)); };
    check_envelope(bytes, what);
    BinaryReader r{bytes, 8 + 4, what};
    uint32_t n = r.get<uint32_t>(), bins = r.get<uint32_t>();
    Vec3 lo = r.get<Vec3>(), hi = r.get<Vec3>();
    uint64_t fp = r.get<uint64_t>(), entries = r.get<uint64_t>();
    if (fp != fingerprint)
        throw fail(fmt::format("belongs to another scene (scene fingerprint {:016x}, this scene {:016x})", fp, fingerprint));
    if (int(n) != grid.resolution() || bins != uint32_t(VoxelGrid::kDirectionBins))
        throw fail(fmt::format("was built for a {}^3 grid with {} direction bins, this render uses {}^3 with {}", n, bins,
                               grid.resolution(), VoxelGrid::kDirectionBins));
    if (!(lo == grid.bounds().lo) || !(hi == grid.bounds().hi)) throw fail("was built for other grid bounds");
    VisibilityMap map(grid.cell_count());
    if (bytes.size() - 8 - r.pos != entries * 8) throw fail("entry count does not match the file size");
    int64_t last = -1;
    for (uint64_t e = 0; e < entries; ++e) {
        uint32_t pair = r.get<uint32_t>();
        PairCounts c;
        c.visible = r.get<uint16_t>();
        c.traced = r.get<uint16_t>();
        if (int64_t(pair) <= last || pair >= map.pair_count() || c.visible > c.traced || c.traced == 0)
            throw fail(fmt::format("entry {} is malformed", e));
        last = pair;
        map.set(uint64_t(pair), c);
    }
    return map;
}

std::pair<VoxelGrid, VisibilityMap> decode_visibility_map(const std::string &bytes, const std::string &what,
                                                          uint64_t fingerprint) {
    // The header's grid (after magic and version: resolution, bins, bounds); the full decode checks the rest.
    check_envelope(bytes, what);
    BinaryReader r{bytes, 8 + 4, what};
    const uint32_t n = r.get<uint32_t>();
    r.get<uint32_t>();
    const Vec3 lo = r.get<Vec3>(), hi = r.get<Vec3>();
    if (n < 1 || n > uint32_t(VoxelGrid::kMaxResolution) || !(BBox{lo, hi}.valid()))
        throw std::runtime_error(fmt::format("{}: malformed grid", what));
    VoxelGrid grid = VoxelGrid::with_exact_bounds(BBox{lo, hi}, int(n));
    VisibilityMap map = decode_visibility_map(bytes, what, grid, fingerprint);
    return {grid, std::move(map)};
}

}  // namespace neepp
