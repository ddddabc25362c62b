// docs/extending.md's worked examples (docs/extending/*.cpp) build, load from scene files and render what
// they should: the Oren-Nayar BSDF (Lambertian at sigma = 0 in a furnace, f cos / pdf as sampled,
// reciprocal), the downlight (its analytic irradiance, light tracing agreeing with path tracing), the
// torus (its area, the hole and the ring where they should be), ambient occlusion (1 in the open, less
// beside a wall). If an example stops compiling, loading or rendering, this fails.
#include <gtest/gtest.h>
#include <cmath>
#include "../../docs/extending/examples.h"
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/integrators/factory.h"
#include "neepp/loader/plugins.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/rng.h"
#include "neepp/scene/scene.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

class Extending : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        example::register_orennayar();
        example::register_downlight();
        example::register_torus();
        example::register_ambient_occlusion();
    }
};

// Mean of the pixels within r of the image's centre (green channel).
double centre_mean(const Image &img, double r) {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (std::hypot(x + 0.5 - img.width / 2.0, y + 0.5 - img.height / 2.0) <= r) sum += img.at(x, y, 1), ++n;
    return sum / n;
}

std::string orennayar_furnace_xml(float sigma) {
    return scene_header_xml(-1, 30, "0,0,4", "0,0,0", 32, 32) + R"(
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><float name="radius" value="1"/>
    <bsdf type="orennayar"><rgb name="reflectance" value="0.5"/><float name="sigma" value=")" + std::to_string(sigma) + R"("/></bsdf></shape>
</scene>)";
}

// A convex object under a uniform sky: every direction above a point brings radiance 1, so a Lambertian
// surface reflects its albedo, 0.5, whatever the light it is seen in.
TEST_F(Extending, OrenNayarIsLambertianAtSigmaZero) {
    const RenderedImage r = render_scene_file(write_temp_scene(orennayar_furnace_xml(0.f)), 64, 3, Options());
    EXPECT_NEAR(centre_mean(r.image, 8), 0.5, 0.01);
    // Rough facets reflect some of the light back the way it came, and lose some by masking: no more.
    const RenderedImage rough = render_scene_file(write_temp_scene(orennayar_furnace_xml(40.f)), 64, 3, Options());
    EXPECT_LT(centre_mean(rough.image, 8), 0.5);
    EXPECT_GT(centre_mean(rough.image, 8), 0.35);
}

TEST_F(Extending, OrenNayarSamplesAsItEvaluatesAndIsReciprocal) {
    auto scene = load_scene(write_temp_scene(orennayar_furnace_xml(30.f)));
    const BSDF &bsdf = *scene->shapes().at(0)->bsdf;
    SurfaceInteraction si;
    PCG32 rng(5, 1);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 wi = square_to_cosine_hemisphere(Vec2(rng.next_float(), rng.next_float()));
        const BSDFSample bs = bsdf.sample(BSDFContext{}, si, wi, rng.next_float(), Vec2(rng.next_float(), rng.next_float()));
        if (!bs.valid()) continue;
        const Color f = bsdf.eval(BSDFContext{}, si, wi, bs.wo);
        EXPECT_NEAR(bs.weight[1], f[1] / bs.pdf, 1e-4f * f[1] / bs.pdf);
        EXPECT_NEAR(bs.pdf, bsdf.pdf(BSDFContext{}, si, wi, bs.wo), 1e-5f);
        // f(wi, wo) = f(wo, wi): eval carries |cos θo|.
        EXPECT_NEAR(f[1] / bs.wo.z, bsdf.eval(BSDFContext{}, si, bs.wo, wi)[1] / wi.z, 1e-4f);
    }
}

TEST_F(Extending, OrenNayarRefusesABadSigma) {
    try {
        load_scene(write_temp_scene(orennayar_furnace_xml(120.f)));
        FAIL() << "a sigma of 120 degrees loaded";
    } catch (const SceneError &e) {
        EXPECT_NE(std::string(e.what()).find("sigma must be in [0, 90]"), std::string::npos) << e.what();
        EXPECT_GT(e.line, 0);
    }
}

// A white diffuse floor 2 below a downlight facing down, seen from above: direct light only.
std::string downlight_xml(const std::string &integrator) {
    return R"(<scene version="3.0.0">
  <integrator type=")" + integrator + R"("><integer name="max_depth" value="2"/></integrator>
  <sensor type="orthographic">
    <transform name="to_world"><scale x="2" y="2"/><lookat origin="0,3,0" target="0,0,0" up="0,0,-1"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="downlight"><point name="position" x="0" y="2" z="0"/><vector name="axis" x="0" y="-1" z="0"/>
    <rgb name="intensity" value="10"/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf></shape>
</scene>)";
}

TEST_F(Extending, DownlightLightsTheFloorAsItsCosineSays) {
    const RenderedImage r = render_scene_file(write_temp_scene(downlight_xml("path")), 256, 1, Options());
    // Radiance at floor point (x, z): (1/π) I0 cos θ · cos θ / d², cos θ = h / d, h = 2, averaged over
    // each pixel's area (the orthographic camera sees [-2, 2]² of the floor).
    auto analytic = [](double x, double z) {
        const double d2 = x * x + z * z + 4.0, cos = 2.0 / std::sqrt(d2);
        return 10.0 / kPi * cos * cos / d2;
    };
    for (int py : {2, 8, 13})
        for (int px : {1, 7, 12}) {
            double want = 0;
            constexpr int k = 8;
            for (int i = 0; i < k; ++i)
                for (int j = 0; j < k; ++j)
                    want += analytic(-2.0 + 4.0 * (px + (i + 0.5) / k) / 16, -2.0 + 4.0 * (py + (j + 0.5) / k) / 16);
            want /= k * k;
            EXPECT_NEAR(r.image.at(px, py, 1), want, 0.02 * want) << "pixel " << px << ", " << py;
        }
}

// Light tracing reaches the floor by sample_emission and pdf_emission: it must agree with path tracing.
TEST_F(Extending, DownlightEmitsWhatItIsSampledBy) {
    std::string xml = downlight_xml("path");  // seen by a pinhole, which light paths can reach
    const size_t a = xml.find("<sensor"), b = xml.find("</sensor>") + 9;
    xml.replace(a, b - a, R"(<sensor type="perspective"><float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="0,3,1.5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>)");
    const std::string path = write_temp_scene(xml);
    const BlockMoments direct = block_moments(path, "path", Options(), 4, 16, 1);
    const BlockMoments traced = block_moments(path, "light", Options(), 4, 16, 2);
    expect_same_image(direct, traced, "downlight: light tracing vs path tracing");
}

std::string torus_xml(const std::string &integrator) {
    return scene_header_xml(3, 40, "0,0,5", "0,0,0", 33, 33) + R"(
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="torus"><float name="major_radius" value="1"/><float name="minor_radius" value="0.3"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf></shape>
</scene>)";
}

TEST_F(Extending, TorusHasItsAreaAndItsHole) {
    auto scene = load_scene(write_temp_scene(torus_xml("path")));
    const auto &torus = dynamic_cast<const TriangleMesh &>(*scene->shapes().at(0));
    double area = 0;
    for (size_t t = 0; t + 2 < torus.indices.size(); t += 3) {
        const Vec3 &a = torus.positions[torus.indices[t]];
        area += 0.5 * norm(cross(torus.positions[torus.indices[t + 1]] - a, torus.positions[torus.indices[t + 2]] - a));
    }
    EXPECT_NEAR(area, 4 * kPi * kPi * 1.0 * 0.3, 0.01 * 4 * kPi * kPi * 0.3);  // 4π² R r, less the facets' flattening
    const RenderedImage r = render_scene_file(write_temp_scene(torus_xml("path")), 16, 1, Options());
    EXPECT_NEAR(r.image.at(16, 16, 1), 1.0, 1e-4) << "the hole shows the sky";
    // The ring (at 1 of the 1.82 the half image spans) is the grey diffuse surface, darker than the sky.
    const float ring = r.image.at(16 + 9, 16, 1);
    EXPECT_GT(ring, 0.05f);
    EXPECT_LT(ring, 0.5f);
}

TEST_F(Extending, TorusRefusesARadiusItCannotHave) {
    std::string xml = torus_xml("path");
    xml.replace(xml.find("value=\"0.3\""), 11, "value=\"2\"");
    EXPECT_THROW(load_scene(write_temp_scene(xml)), SceneError);
}

std::string ao_xml(bool wall) {
    std::string xml = R"(<scene version="3.0.0">
  <integrator type="ao"><float name="distance" value="1"/></integrator>
  <sensor type="orthographic">
    <transform name="to_world"><scale x="2" y="2"/><lookat origin="0,3,0" target="0,0,0" up="0,0,-1"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform></shape>
  <emitter type="constant"/>  <!-- ao ignores lights, but the loader refuses a scene without any -->
)";
    if (wall)  // a wall along the image's middle column, 1 high
        xml += R"(  <shape type="cube"><transform name="to_world"><scale x="0.05" y="0.5" z="3"/><translate y="0.5"/></transform></shape>
)";
    return xml + "</scene>\n";
}

TEST_F(Extending, AmbientOcclusionIsOneInTheOpenAndLessBesideAWall) {
    auto open = load_scene(write_temp_scene(ao_xml(false)));
    EXPECT_EQ(open->settings.integrator, "ao");  // the scene file selects the registered integrator
    const RenderedImage r = render_scene_file(write_temp_scene(ao_xml(false)), 8, 1, Options(), "ao");
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) ASSERT_EQ(r.image.at(x, y, 1), 1.f) << "nothing occludes the open floor";
    const RenderedImage w = render_scene_file(write_temp_scene(ao_xml(true)), 64, 1,
                                              Options(std::map<std::string, std::string>{{"distance", "1"}}), "ao");
    // Beside the wall (a pixel from it) about a third of the cosine-weighted hemisphere is blocked; far
    // from it, at 1.9 away, nothing within the distance is.
    EXPECT_LT(w.image.at(9, 8, 1), 0.8f);
    EXPECT_GT(w.image.at(0, 8, 1), 0.97f);
    EXPECT_EQ(make_integrator("ao", Options())->describe()["name"], "ao");
    EXPECT_THROW(register_integrator("path", [](const Options &) { return std::unique_ptr<Integrator>(); }),
                 std::invalid_argument);
    EXPECT_THROW(register_bsdf("diffuse", [](const PluginProperties &) { return BSDFPtr(); }), std::invalid_argument);
}

// A plugin's mistakes are reported as the loader's own are: at the element, with the file and the line.
TEST_F(Extending, PluginErrorsNameTheElement) {
    register_texture("broken_texture", [](const PluginProperties &) -> TexturePtr { throw std::invalid_argument("no"); });
    register_shape("broken_mesh", [](const PluginProperties &) {
        MeshData m;
        m.positions = {Vec3(0.f), Vec3(1, 0, 0), Vec3(0, 1, 0)};
        m.indices = {0, 1, 7};
        return m;
    });
    auto expect_error = [](const std::string &body, const std::string &says) {
        try {
            load_scene(write_temp_scene(scene_header_xml(2, 40, "0,0,4", "0,0,0", 8, 8) + body +
                                        "\n  <emitter type=\"constant\"/>\n</scene>"));
            ADD_FAILURE() << "loaded: " << body;
        } catch (const SceneError &e) {
            EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
            EXPECT_GT(e.line, 0) << e.what();
        }
    };
    expect_error(R"(<shape type="sphere"><bsdf type="diffuse"><texture name="reflectance" type="broken_texture"/></bsdf></shape>)", "no");
    expect_error(R"(<shape type="broken_mesh"/>)", "index 7 is past its 3 positions");
    // An unknown type's message lists the registered ones beside the loader's.
    expect_error(R"(<shape type="klein_bottle"/>)", "torus (registered)");
}

}  // namespace
