// Grid volumes whose file is broken or does not fit its use (a medium's sigma_t or albedo, a blendphase's
// weight): each is an error at the <volume>'s line that names the use, the .vol file and the problem, so
// nothing renders from it; data beyond what the header gives (which Mitsuba reads without a word) loads as
// Mitsuba loads it, with a warning; a medium whose densities overflow a float when scaled is refused.
#include <gtest/gtest.h>

#include "common/temp_dir.h"
#include "common/volume_grid_writer.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// 2 x 2 x 2 points of `channels` channels, all 0.5.
VolumeGridFile grid(int channels = 1) {
    VolumeGridFile g;
    g.channels = channels;
    g.values.assign(8 * size_t(channels), 0.5f);
    return g;
}

// A scene with a heterogeneous medium whose `use` ("sigma_t", "albedo" or "weight", a blendphase's) is the
// grid file `vol`; the <volume> is on line 5.
std::string scene(const TempDir &dir, const std::string &use, const std::string &vol, const std::string &extra = "",
                  const std::string &medium_extra = "") {
    const std::string volume = "<volume name=\"" + use + "\" type=\"gridvolume\"><string name=\"filename\" value=\"" + vol +
                               "\"/>" + extra + "</volume>";
    const std::string body = use == "weight" ? "<phase type=\"blendphase\"><phase type=\"isotropic\"/><phase type=\"hg\"/>\n" +
                                                   volume + "</phase>"
                                             : "\n" + volume;
    return dir.write("scene.xml", R"(<scene version="3.0.0">
<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="constant"/>
<shape type="cube"><bsdf type="null"/><medium type="heterogeneous" name="interior">)" + medium_extra + body + R"(
</medium></shape>
</scene>
)");
}

std::string load_error(const std::string &path) {
    try {
        load_scene(path);
    } catch (const SceneError &e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(GridVolumeErrors, EachBrokenFileIsRefusedNamingTheLineTheUseTheFileAndTheProblem) {
    TempDir dir;
    const std::string whole = volume_grid_bytes(grid());
    VolumeGridFile v2 = grid(), float16 = grid(), two = grid(2), six = grid(6), nan = grid(), inf = grid(3), negative = grid(),
                   zero_size = grid();
    v2.version = 2;
    float16.data_type = 2;
    nan.values[5] = std::nanf("");         // point (1, 0, 1)
    inf.values[3 * 6 + 1] = INFINITY;      // point (0, 1, 1), channel 1
    negative.values[2] = -0.25f;           // point (0, 1, 0)
    zero_size.size[0] = 0;
    struct Case {
        std::string file, bytes, use, problem;
    };
    const std::vector<Case> cases = {
        {"missing.vol", "", "sigma_t", "cannot open the volume grid file"},
        {"text.vol", "density 0.5\n", "sigma_t", "does not start with 'VOL'"},
        {"header.vol", whole.substr(0, 20), "sigma_t", "the header ends early"},
        {"truncated.vol", whole.substr(0, whole.size() - 3), "sigma_t", "truncated volume grid file: the header gives 2 x 2 x 2 points of 1 channel, more values than"},
        {"v2.vol", volume_grid_bytes(v2), "sigma_t", "version 2 (only version 3 is supported)"},
        {"float16.vol", volume_grid_bytes(float16), "albedo", "data type 2 (only type 1, float32"},
        {"zero.vol", volume_grid_bytes(zero_size), "sigma_t", "size 0 x 2 x 2 is invalid"},
        {"two.vol", volume_grid_bytes(two), "sigma_t", "the grid has 2 channels; a gridvolume's value is grey (1 channel) or RGB (3)"},
        {"six.vol", volume_grid_bytes(six), "albedo", "the grid has 6 channels; a gridvolume's value is grey (1 channel) or RGB (3) as a medium's albedo (6 channels hold a symmetric matrix"},
        {"two_weight.vol", volume_grid_bytes(two), "weight", "the grid has 2 channels"},
        {"nan.vol", volume_grid_bytes(nan), "sigma_t", "grid point (1, 0, 1) is nan: not a finite number"},
        {"inf.vol", volume_grid_bytes(inf), "sigma_t", "grid point (0, 1, 1), channel 1, is inf: not a finite number"},
        {"negative.vol", volume_grid_bytes(negative), "sigma_t", "grid point (0, 1, 0) is -0.250000"},
        {"negative_albedo.vol", volume_grid_bytes(negative), "albedo", "are not negative"},
    };
    for (const Case &c : cases) {
        const std::string vol = c.file == "missing.vol" ? (dir.dir / c.file).string() : dir.write(c.file, c.bytes);
        const std::string xml = scene(dir, c.use, vol);
        const std::string msg = load_error(xml);
        // scene.xml:5: <volume type="gridvolume">: as "sigma_t": /…/file.vol: problem
        EXPECT_NE(msg.find(xml + ":5: <volume type=\"gridvolume\">: as \"" + c.use + "\": " + vol + ": "), std::string::npos)
            << c.file << ": " << msg;
        EXPECT_NE(msg.find(c.problem), std::string::npos) << c.file << ": " << msg;
        // neepp check lists it, as one error at that line.
        const std::vector<SceneProblem> problems = check_scene(xml);
        ASSERT_FALSE(problems.empty()) << c.file;
        EXPECT_TRUE(problems[0].error) << c.file;
        EXPECT_EQ(problems[0].line, 5) << c.file;
    }
}

// max_value bounds the data (a heterogeneous medium's majorant comes from it): one below it is refused.
TEST(GridVolumeErrors, MaxValueBelowTheDataIsRefused) {
    TempDir dir;
    const std::string vol = dir.write("half.vol", volume_grid_bytes(grid()));
    const std::string msg = load_error(scene(dir, "sigma_t", vol, R"(<float name="max_value" value="0.25"/>)"));
    EXPECT_NE(msg.find("half.vol: max_value 0.250000 is below the grid's largest value 0.500000"), std::string::npos) << msg;
    EXPECT_EQ(load_error(scene(dir, "sigma_t", vol, R"(<float name="max_value" value="2"/>)")), "");
}

// Each value is a float; the medium's scale times the largest need not be: an infinite majorant is refused.
TEST(GridVolumeErrors, DensitiesThatOverflowWhenScaledAreRefused) {
    TempDir dir;
    VolumeGridFile big = grid();
    big.values[0] = 1e30f;
    const std::string vol = dir.write("big.vol", volume_grid_bytes(big));
    const std::string msg = load_error(scene(dir, "sigma_t", vol, "", R"(<float name="scale" value="1e10"/>)"));
    EXPECT_NE(msg.find("sigma_t times scale is not a finite number"), std::string::npos) << msg;
    EXPECT_EQ(load_error(scene(dir, "sigma_t", vol)), "");
}

// Mitsuba reads the values the header gives and ignores the rest; neepp does, and warns at the volume's line.
TEST(GridVolumeErrors, DataBeyondTheHeaderLoadsWithAWarning) {
    TempDir dir;
    VolumeGridFile rgb_as_grey = grid(3);
    rgb_as_grey.channels = 1;
    const std::string vol = dir.write("rgb_as_grey.vol", volume_grid_bytes(rgb_as_grey));
    const std::string xml = scene(dir, "sigma_t", vol);
    EXPECT_EQ(load_error(xml), "");
    const std::vector<SceneProblem> problems = check_scene(xml);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_FALSE(problems[0].error);
    EXPECT_EQ(problems[0].line, 5);
    EXPECT_NE(problems[0].problem.find(vol + ": 64 bytes after the 2 x 2 x 2 points of 1 channel that the header gives are ignored"),
              std::string::npos)
        << problems[0].problem;
    EXPECT_NE(problems[0].problem.find("exactly 3 times as many values"), std::string::npos) << problems[0].problem;
}

// An sggx's S is a 6-channel grid: one of other channel counts, or of matrices that are not positive
// semi-definite, is refused at the volume's line naming the file; in a homogeneous medium S must be the same
// at every grid point (else the extinction would vary through it).
TEST(GridVolumeErrors, SggxSIsAGridOfSymmetricMatrices) {
    TempDir dir;
    auto sggx_scene = [&](const std::string &vol, const std::string &medium = "heterogeneous") {
        return dir.write("scene.xml", R"(<scene version="3.0.0">
<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="constant"/>
<shape type="cube"><bsdf type="null"/><medium type=")" + medium + R"(" name="interior"><phase type="sggx">
<volume name="S" type="gridvolume"><string name="filename" value=")" + vol + R"("/></volume>
</phase></medium></shape>
</scene>
)");
    };
    VolumeGridFile identity = grid(6);
    for (size_t i = 0; i < identity.values.size(); ++i) identity.values[i] = i % 6 < 3 ? 1.f : 0.f;
    EXPECT_EQ(load_error(sggx_scene(dir.write("identity.vol", volume_grid_bytes(identity)))), "");
    EXPECT_EQ(load_error(sggx_scene(dir.write("identity.vol", volume_grid_bytes(identity)), "homogeneous")), "");
    VolumeGridFile varying = identity, indefinite = identity;
    varying.values[6 * 7 + 2] = 0.01f;      // point (1, 1, 1): a fibre
    indefinite.values[6 * 3 + 4] = -1.5f;   // point (1, 1, 0): S_xz beyond its diagonal
    struct Case {
        std::string file, bytes, medium, problem;
    };
    const std::vector<Case> cases = {
        {"grey.vol", volume_grid_bytes(grid(1)), "heterogeneous", "the grid has 1 channel; an sggx's S is a symmetric matrix, 6 channels"},
        {"rgb.vol", volume_grid_bytes(grid(3)), "heterogeneous", "the grid has 3 channels; an sggx's S is a symmetric matrix"},
        {"indefinite.vol", volume_grid_bytes(indefinite), "heterogeneous", "at grid point (1, 1, 0) has an eigenvalue of -"},
    };
    for (const Case &c : cases) {
        const std::string vol = dir.write(c.file, c.bytes), xml = sggx_scene(vol, c.medium);
        const std::string msg = load_error(xml);
        EXPECT_NE(msg.find(xml + ":5: <volume type=\"gridvolume\">: as \"S\": " + vol + ": "), std::string::npos) << c.file << ": " << msg;
        EXPECT_NE(msg.find(c.problem), std::string::npos) << c.file << ": " << msg;
    }
    const std::string vol = dir.write("varying.vol", volume_grid_bytes(varying));
    EXPECT_EQ(load_error(sggx_scene(vol)), "");
    const std::string msg = load_error(sggx_scene(vol, "homogeneous"));
    EXPECT_NE(msg.find(":4: <medium type=\"homogeneous\">: a homogeneous medium's sggx S is the same everywhere"), std::string::npos) << msg;
}
