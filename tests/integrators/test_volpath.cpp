// The volumetric path tracer against analytic answers: an absorbing slab's transmittance per channel, the
// single scattering of a slab lit from above (which fixes how max_depth counts collisions and null
// crossings, and Henyey-Greenstein's sign), and a medium furnace (an albedo-1 medium in a uniform sky
// looks like the sky), through every shadow-ray policy and light choice, NEE on and off.
#include <gtest/gtest.h>
#include <cmath>
#include <fmt/core.h>
#include <filesystem>
#include <fstream>
#include "common/seeded_map.h"
#include "common/volume_grid_writer.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// An orthographic camera at z = 5 looking down -z over [-1, 1]^2, a slab z in [-h/2, h/2] of null faces
// around the medium (`medium` is its XML body), and `lights`.
std::string slab_xml(float h, const std::string &medium, const std::string &lights, int max_depth) {
    return fmt::format(R"(<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="{max_depth}"/></integrator>
  <sensor type="orthographic"><transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film></sensor>
  {lights}
  <shape type="cube"><transform name="to_world"><scale x="50" y="50" z="{half}"/></transform>
    <bsdf type="null"/><medium type="homogeneous" name="interior">{medium}</medium></shape>
</scene>)",
                       fmt::arg("max_depth", max_depth), fmt::arg("half", h / 2), fmt::arg("medium", medium),
                       fmt::arg("lights", lights));
}

// |image mean - expected| per channel within 5 standard errors (plus a little for float rounding).
void expect_mean(const Image &img, const Color &expected, const std::string &what) {
    for (int c = 0; c < 3; ++c) {
        const MeanStderr st = pixel_statistics(img, c);
        EXPECT_NEAR(st.mean, expected[c], 5 * st.stderr_ + 2e-4 * expected[c] + 1e-6) << what << " channel " << c;
    }
}

}  // namespace

TEST(VolPath, AbsorbingSlabTransmitsExactlyPerChannel) {
    const float h = 0.8f;
    const Color sigma_t(0.5f, 1.5f, 2.f);
    const std::string path = write_temp_scene(slab_xml(
        h, R"(<rgb name="sigma_t" value="0.25, 0.75, 1"/><float name="scale" value="2"/><float name="albedo" value="0"/>)",
        R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)", -1));
    // 1: the sky is seen through the slab's null faces, which are no bounce.
    for (int max_depth : {-1, 1}) {
        Options o;
        o.set("max_depth", std::to_string(max_depth));
        const auto out = render_scene_file(path, 512, 3, o, "volpath");
        expect_mean(out.image, vexp(-sigma_t * h), "max_depth " + std::to_string(max_depth));
    }
}

// A heterogeneous medium: its density varies along z only (a grid of 2 x 2 x 8 texels stretched over the
// slab), so every ray down through it sees exp(-scale ∫ sigma_t dz), which the trilinear interpolant gives
// exactly: each texel's value over its own height, the half texels at the faces at the face texel's value.
// The camera's rays sample it by delta tracking with null collisions (albedo 0: a real one ends the path).
// And a heterogeneous medium with one constant value renders the homogeneous slab's transmittance.
TEST(VolPath, HeterogeneousSlabTransmitsItsIntegral) {
    const float h = 0.8f, scale = 1.5f;
    const float column[8] = {0.2f, 1.f, 0.5f, 2.f, 0.f, 1.5f, 0.7f, 0.3f};
    VolumeGridFile g;
    g.size[0] = 2, g.size[1] = 2, g.size[2] = 8, g.channels = 3;
    for (int z = 0; z < 8; ++z)
        for (int k = 0; k < 4; ++k)
            for (int c = 0; c < 3; ++c) g.values.push_back(column[z] * (c == 0 ? 1.f : c == 1 ? 0.5f : 2.f));
    const std::string dir = std::filesystem::path(write_temp_scene("", "density.vol")).parent_path().string();
    {
        std::ofstream(dir + "/density.vol", std::ios::binary) << volume_grid_bytes(g);
    }
    double integral = 0;  // of the interpolant over [0, 1] in z: half texels at each face, lines between centres
    for (int z = 0; z < 8; ++z) integral += column[z] / 8.0;
    const std::string medium = fmt::format(
        R"(<volume name="sigma_t" type="gridvolume"><string name="filename" value="{dir}/density.vol"/>
             <transform name="to_world"><scale x="200" y="200" z="{h}"/><translate x="-100" y="-100" z="{lo}"/></transform></volume>
           <float name="scale" value="{scale}"/><float name="albedo" value="0"/>)",
        fmt::arg("dir", dir), fmt::arg("h", h), fmt::arg("lo", -h / 2), fmt::arg("scale", scale));
    std::string xml = slab_xml(h, medium, R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)", -1);
    const std::string homogeneous = R"(type="homogeneous")", heterogeneous = R"(type="heterogeneous")";
    xml.replace(xml.find(homogeneous), homogeneous.size(), heterogeneous);
    const auto out = render_scene_file(write_temp_scene(xml), 1024, 3, Options(), "volpath");
    const double tau = scale * integral * h;
    expect_mean(out.image, Color(float(std::exp(-tau)), float(std::exp(-0.5 * tau)), float(std::exp(-2 * tau))), "grid");

    // A constant volume is defined over the unit cube placed by its to_world (Mitsuba's): here the slab.
    std::string flat = slab_xml(h, R"(<volume name="sigma_t" type="constvolume"><rgb name="value" value="0.25, 0.75, 1"/>
                                        <transform name="to_world"><scale x="100" y="100" z="0.8"/><translate x="-50" y="-50" z="-0.4"/></transform></volume>
                                      <float name="scale" value="2"/><float name="albedo" value="0"/>)",
                                R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)", -1);
    flat.replace(flat.find(homogeneous), homogeneous.size(), heterogeneous);
    const auto out_flat = render_scene_file(write_temp_scene(flat), 1024, 3, Options(), "volpath");
    expect_mean(out_flat.image, vexp(-Color(0.5f, 1.5f, 2.f) * h), "constant");
}

// Light travelling down -z onto the slab, seen from above: with max_depth 2 only light scattered once,
// back toward the camera, arrives: L = sigma_s p(backward) E (1 - e^{-2 sigma_t h}) / (2 sigma_t).
TEST(VolPath, SingleScatteringOfALitSlab) {
    const float h = 0.6f, g = 0.4f, E = 3.f;
    const Color sigma_t(0.8f, 2.f, 4.f), albedo(0.9f, 0.5f, 0.7f);
    const std::string medium = fmt::format(
        R"(<rgb name="sigma_t" value="0.2, 0.5, 1"/><float name="scale" value="4"/><rgb name="albedo" value="0.9, 0.5, 0.7"/>
           <phase type="hg"><float name="g" value="{}"/></phase>)", g);
    const std::string light = fmt::format(
        R"(<emitter type="directional"><vector name="direction" value="0,0,-1"/><rgb name="irradiance" value="{}"/></emitter>)", E);
    const std::string path = write_temp_scene(slab_xml(h, medium, light, 2));
    const float backward = (1 - g * g) / (4 * kPi * std::pow(1 + g, 3.f));
    Color expected;
    for (int c = 0; c < 3; ++c)
        expected[c] = albedo[c] * sigma_t[c] * backward * E * (1 - std::exp(-2 * sigma_t[c] * h)) / (2 * sigma_t[c]);
    const auto out = render_scene_file(path, 512, 5, Options(), "volpath");
    expect_mean(out.image, expected, "single scattering");
    // A collision is a bounce: with max_depth 1 nothing scattered arrives.
    Options one;
    one.set("max_depth", "1");
    const auto none = render_scene_file(path, 64, 5, one, "volpath");
    expect_mean(none.image, Color(0.f), "max_depth 1");
}

// The same slab with the phase functions that have no parameter to show their sign: each one's backward
// value (cos_theta = -1 to the direction of travel, wo = wi) is what the camera sees. A tabphase's first
// value is the backward one; a blendphase reads its weight at the scattering point, here a grid that is 0
// (the first alone) over x < 0.5, three quarters of the image, and 1 (the second alone) beyond.
TEST(VolPath, SingleScatteringShowsEachPhaseFunctionsBackwardValue) {
    const float h = 0.6f, E = 3.f;
    const Color sigma_t(0.8f, 2.f, 4.f), albedo(0.9f, 0.5f, 0.7f);
    VolumeGridFile split;
    split.size[0] = 2, split.size[1] = 1, split.size[2] = 1;
    split.values = {0.f, 1.f};
    const std::string dir = std::filesystem::path(write_temp_scene("", "split.vol")).parent_path().string();
    {
        std::ofstream(dir + "/split.vol", std::ios::binary) << volume_grid_bytes(split);
    }
    const float g = 0.4f, hg_backward = (1 - g * g) / (4 * kPi * std::pow(1 + g, 3.f)), rayleigh_backward = 3.f / (8.f * kPi);
    const std::vector<std::pair<std::string, float>> phases = {
        {R"(<phase type="rayleigh"/>)", rayleigh_backward},
        // 1 at cos_theta = -1, 0.5 at 0, 0.25 at 1: mass 1.125 over the cosine, 1/(2 pi) per unit of azimuth.
        {R"(<phase type="tabphase"><string name="values" value="1, 0.5, 0.25"/></phase>)", 1.f / 1.125f * kInv2Pi},
        {fmt::format(R"(<phase type="blendphase"><phase type="hg"><float name="g" value="{g}"/></phase><phase type="rayleigh"/>
             <volume name="weight" type="gridvolume"><string name="filename" value="{dir}/split.vol"/><string name="filter_type" value="nearest"/>
               <transform name="to_world"><scale x="2"/><translate x="-0.5"/></transform></volume></phase>)",
                     fmt::arg("g", g), fmt::arg("dir", dir)),
         0.75f * hg_backward + 0.25f * rayleigh_backward},
    };
    const std::string light = fmt::format(
        R"(<emitter type="directional"><vector name="direction" value="0,0,-1"/><rgb name="irradiance" value="{}"/></emitter>)", E);
    for (const auto &[phase, backward] : phases) {
        const std::string medium =
            R"(<rgb name="sigma_t" value="0.2, 0.5, 1"/><float name="scale" value="4"/><rgb name="albedo" value="0.9, 0.5, 0.7"/>)" + phase;
        Color expected;
        for (int c = 0; c < 3; ++c)
            expected[c] = albedo[c] * sigma_t[c] * backward * E * (1 - std::exp(-2 * sigma_t[c] * h)) / (2 * sigma_t[c]);
        const auto out = render_scene_file(write_temp_scene(slab_xml(h, medium, light, 2)), 512, 5, Options(), "volpath");
        expect_mean(out.image, expected, phase);
    }
}

// An albedo-1 medium neither adds nor removes light: in a uniform sky every pixel is the sky, whatever
// the estimator (NEE or not, every shadow-ray policy, a light choice that reads the map).
TEST(VolPath, MediumFurnaceIsTheSky) {
    const std::string path = write_temp_scene(R"(<scene version="3.0.0">
  <integrator type="volpath"/>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/><rfilter type="box"/></film></sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><float name="radius" value="1.2"/><bsdf type="null"/>
    <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="0.5, 1, 0.25"/><float name="scale" value="3"/>
      <float name="albedo" value="1"/><phase type="hg"><float name="g" value="0.5"/></phase></medium></shape>
</scene>)");
    const std::vector<std::map<std::string, std::string>> variants = {
        {}, {{"nee", "false"}}, {{"shadow_rays", "neepp"}}, {{"shadow_rays", "neepp-adaptive"}},
        {{"shadow_rays", "neepp-cv"}}, {{"light_sampler", "visibility"}}};
    for (const auto &v : variants) {
        std::string what;
        for (const auto &[k, val] : v) what += k + "=" + val + " ";
        // The variants with a NEE++ map start from the one the first seeded (common/seeded_map.h).
        const Options o(with_map_file(v, map_file_beside(path), "volpath"));
        const auto out = render_scene_file(path, 256, 11, o, "volpath");
        expect_mean(out.image, Color(1.f), what);
    }
}

TEST(VolPath, LightPathsRefuseMediaNamingVolpath) {
    const std::string path = write_temp_scene(slab_xml(
        0.5f, R"(<float name="albedo" value="0.5"/>)", R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)", -1));
    const std::vector<std::pair<std::string, OptionMap>> refused = {
        {"bdpt", {}}, {"light", {}}, {"pssmlt", {{"bidirectional", "true"}}}};
    for (const auto &[name, options] : refused) {
        try {
            render_scene_file(path, 1, 1, Options(options), name);
            ADD_FAILURE() << name << " rendered a scene with media";
        } catch (const std::exception &e) {
            EXPECT_NE(std::string(e.what()).find("volpath"), std::string::npos) << e.what();
        }
    }
}

// PSSMLT over the path tracer runs its chains over volpath in a scene with media: a chromatic fog ball on a
// floor under a lamp, the image volpath renders, with NEE++'s roulette inside the chain too.
TEST(VolPath, PssmltChainsOverVolpathAgreeWithIt) {
    const std::string path = write_temp_scene(R"(<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,1.2,4" target="0,0.4,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film></sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.5"/></transform>
    <emitter type="area"><rgb name="radiance" value="12"/></emitter></shape>
  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0.7" z="0"/><bsdf type="null"/>
    <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="0.25, 0.5, 1"/><float name="scale" value="4"/>
      <rgb name="albedo" value="0.9, 0.7, 0.8"/></medium></shape>
</scene>)");
    const BlockMoments ref = block_moments(path, "volpath", Options(), 6, 64, 100);
    const OptionMap chains = {{"bidirectional", "false"}, {"chains", "32"}, {"bootstrap", "20000"}};
    expect_same_image(ref, block_moments(path, "pssmlt", Options(chains), 6, 64, 200), "pssmlt over volpath");
    OptionMap roulette = chains;
    roulette.emplace("shadow_rays", "neepp");
    expect_same_image(ref, block_moments(path, "pssmlt", Options(roulette), 6, 64, 300), "pssmlt over volpath, NEE++ roulette");
}
