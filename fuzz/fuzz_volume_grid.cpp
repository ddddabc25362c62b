// The .vol reader and the SDF grid built from what it reads, on arbitrary bytes: a SceneError (or the
// grid's std::invalid_argument) is the expected answer to a bad file; anything else (a crash, a sanitizer
// report, a hang, a leak, memory out of proportion to the input) is a bug. The first byte chooses how the
// rest is read: bit 0 clear, as the whole file; set, as three sizes (one byte each) and the float values
// behind a header the harness writes, so that mutations reach the grid's checks and its intersection
// instead of stopping at the header's. A grid that loads is then met by rays through every voxel (at
// most 64), whose hits have their normals computed, in both `normals` modes.
#include <exception>
#include "common/volume_grid_writer.h"
#include "fuzz_input.h"
#include "neepp/io/volume_grid_reader.h"
#include "neepp/shapes/sdf_grid.h"

namespace {

// Rays into each voxel from the grid's corners and from a face, as a render's would come.
void trace_through(const neepp::SdfGrid &grid) {
    using neepp::Vec3;
    for (size_t v = 0; v < grid.voxel_count() && v < 64; ++v) {
        const Vec3 target = grid.surface_bounds(v).center();
        for (const Vec3 &o : {Vec3(-1.f), Vec3(2.f, -1.f, 0.5f), Vec3(0.5f, 0.5f, 3.f), target * 0.5f}) {
            float t;
            const Vec3 d = target - o;
            if (!grid.intersect(v, o, d, 0.f, 1e30f, t)) continue;
            const Vec3 p = o + d * t;
            (void)grid.gradient(p);
            (void)grid.shading_normal(p);
        }
    }
}

// A grid of nx x ny x nz points behind a valid header: what the harness writes for a first byte with bit 0 set.
std::string with_header(const std::string &rest) {
    neepp::testing::VolumeGridFile g;
    for (int a = 0; a < 3; ++a) g.size[a] = a < int(rest.size()) ? uint8_t(rest[a]) : 0;
    std::string file = neepp::testing::volume_grid_bytes(g);
    if (rest.size() > 3) file += rest.substr(3);
    return file;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        const std::string sphere = neepp::testing::volume_grid_bytes(neepp::testing::sphere_sdf_grid(5));
        neepp::fuzz::write_seed(dir, "sphere.vol", std::string(1, char(0)) + sphere);
        neepp::fuzz::write_seed(dir, "sphere_values.bin", std::string(1, char(1)) + "\5\5\5" + sphere.substr(48));
        neepp::testing::VolumeGridFile plane;
        plane.size[0] = 3, plane.size[1] = 2, plane.size[2] = 2;
        for (int i = 0; i < 12; ++i) plane.values.push_back(float(i % 3) - 0.7f);
        neepp::fuzz::write_seed(dir, "plane.vol", std::string(1, char(0)) + neepp::testing::volume_grid_bytes(plane));
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size == 0) return 0;
    std::string file(reinterpret_cast<const char *>(data + 1), size - 1);
    if (data[0] & 1) file = with_header(file);
    try {
        neepp::VolumeGrid g = neepp::read_volume_grid(
            neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(file.data()), file.size(), "grid.vol"));
        if (g.channels != 1) return 0;
        for (auto normals : {neepp::SdfGrid::Normals::Smooth, neepp::SdfGrid::Normals::Analytic})
            trace_through(neepp::SdfGrid(g.size[0], g.size[1], g.size[2], g.values, normals));
    } catch (const std::exception &) {
    }
    return 0;
}
