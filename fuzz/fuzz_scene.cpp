// The scene loader on arbitrary XML: parsing (pugixml, then Mitsuba's elements: defaults, -D
// substitution, includes, refs, transforms), every plugin's parameters, and building the scene (meshes,
// textures, lights, the BVH). The input is written beside a small OBJ, PLY, .serialized, .vol, curve file and
// PNG, so that files it names can be found. The first line, when it starts with "-D ", holds name=value parameter overrides
// (as the CLI's -D), to fuzz their substitution too.
#include <exception>
#include <map>
#include <sstream>
#include "common/serialized_writer.h"
#include "common/volume_grid_writer.h"
#include "fuzz_input.h"
#include "neepp/io/image.h"
#include "neepp/loader/scene_loader.h"

namespace {

void write_companions() {
    static const char kObj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n";
    static const char kPly[] =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(kObj), sizeof(kObj) - 1, "mesh.obj");
    neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(kPly), sizeof(kPly) - 1, "mesh.ply");
    // Two curves, long enough for either basis.
    static const char kCurves[] = "0 0 0 0.1\n0.3 0.5 0 0.1\n0.6 0 0 0.1\n1 0.5 0 0\n\n0 1 0 0.2\n1 1 0 0.2\n2 1 1 0.2\n3 1 0 0.2\n";
    neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(kCurves), sizeof(kCurves) - 1, "curves.txt");
    neepp::testing::SerializedTestMesh tri;
    tri.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    tri.indices = {0, 1, 2};
    const std::string serialized = neepp::testing::serialized({tri, tri});
    neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(serialized.data()), serialized.size(), "mesh.serialized");
    const std::string grid = neepp::testing::volume_grid_bytes(neepp::testing::sphere_sdf_grid(5));
    neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(grid.data()), grid.size(), "grid.vol");
    neepp::write_png_srgb((neepp::fuzz::scratch_dir() / "texture.png").string(), neepp::Image(2, 2, 3));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        neepp::fuzz::write_seed(
            dir, "companions.xml",
            "-D res=8 albedo=0.5\n<scene version='3.0.0'><default name='spp' value='4'/>"
            "<sensor type='perspective'><float name='fov' value='45'/><transform name='to_world'><lookat origin='0,0,3' "
            "target='0,0,0' up='0,1,0'/></transform><film type='hdrfilm'><integer name='width' value='$res'/>"
            "<integer name='height' value='$res'/><rfilter type='gaussian'/></film><sampler type='independent'>"
            "<integer name='sample_count' value='$spp'/></sampler></sensor>"
            "<bsdf type='diffuse' id='tex'><texture type='bitmap' name='reflectance'><string name='filename' "
            "value='texture.png'/></texture></bsdf>"
            "<shape type='obj'><string name='filename' value='mesh.obj'/><ref id='tex'/></shape>"
            "<shape type='ply'><string name='filename' value='mesh.ply'/><bsdf type='roughconductor'/>"
            "<emitter type='area'><rgb name='radiance' value='$albedo'/></emitter></shape>"
            "<shape type='sphere'><bsdf type='twosided'><bsdf type='roughplastic'/></bsdf></shape>"
            "<emitter type='point'><point name='position' x='0' y='1' z='0'/></emitter></scene>\n");
        neepp::fuzz::write_seed(
            dir, "instances.xml",
            "<scene version='3.0.0'><sensor type='perspective'><film type='hdrfilm'><integer name='width' value='8'/>"
            "<integer name='height' value='8'/></film></sensor>"
            "<shape type='shapegroup' id='group'><shape type='serialized'><string name='filename' value='mesh.serialized'/>"
            "<integer name='shape_index' value='1'/><bsdf type='diffuse'/></shape><shape type='sphere'/>"
            "<shape type='sdfgrid'><string name='filename' value='grid.vol'/><string name='normals' value='analytic'/>"
            "</shape></shape>"
            "<shape type='instance'><ref id='group'/></shape>"
            "<shape type='instance'><ref id='group'/><transform name='to_world'><translate x='2'/></transform></shape>"
            "<emitter type='constant'/></scene>\n");
        neepp::fuzz::write_seed(
            dir, "curves.xml",
            "<scene version='3.0.0'><sensor type='perspective'><film type='hdrfilm'><integer name='width' value='8'/>"
            "<integer name='height' value='8'/></film></sensor>"
            "<shape type='linearcurve'><string name='filename' value='curves.txt'/><transform name='to_world'>"
            "<scale x='2'/></transform><bsdf type='diffuse'/></shape>"
            "<shape type='shapegroup' id='hair'><shape type='bsplinecurve'><string name='filename' value='curves.txt'/>"
            "</shape></shape><shape type='instance'><ref id='hair'/><transform name='to_world'><scale value='0.5'/>"
            "</transform></shape><emitter type='constant'/></scene>\n");
    });
    write_companions();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    std::string text(reinterpret_cast<const char *>(data), size);
    std::map<std::string, std::string> defines;
    if (text.rfind("-D ", 0) == 0) {
        const size_t end = text.find('\n');
        std::istringstream line(text.substr(3, end == std::string::npos ? std::string::npos : end - 3));
        for (std::string kv; line >> kv;)
            if (size_t eq = kv.find('='); eq != std::string::npos && eq > 0) defines[kv.substr(0, eq)] = kv.substr(eq + 1);
        text = end == std::string::npos ? "" : text.substr(end + 1);
    }
    try {
        neepp::load_scene(neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(text.data()), text.size(), "scene.xml"),
                          defines);
    } catch (const std::exception &) {
    }
    return 0;
}
