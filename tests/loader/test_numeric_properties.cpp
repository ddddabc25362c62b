// Every numeric property of every plugin the loader knows, given a value that is not finite (nan, inf,
// -inf), one that overflows a 32-bit float (1e39), an integer that fits no int, and a negative one: a
// clear error naming the file, the property's line, the property and the value as written; or, where
// Mitsuba 3 accepts the value (a negative translation, a bump map's negative scale), a scene that loads.
// The table is walked along the loader's own plugin list, so a plugin added there without an entry here
// fails this test until someone says what its numbers may be.
#include <gtest/gtest.h>
#include <algorithm>
#include <map>
#include "common/serialized_writer.h"
#include "common/temp_dir.h"
#include "common/volume_grid_writer.h"
#include "neepp/io/image.h"
#include "neepp/loader/supported_plugins.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// What a negative value of a property is.
enum class Negative {
    Refused,   // it cannot mean anything (a radiance, an IOR, a count): an error
    Accepted,  // Mitsuba 3 accepts it and neepp renders it as Mitsuba does: the scene loads
};

struct Property {
    std::string name;
    std::string element;  // float, integer, rgb, spectrum, point, vector, transform
    Negative negative = Negative::Refused;
    std::string negative_value = "-1";  // the negative value tried
    std::string beside;                 // XML the property needs beside it (alpha_v for alpha_u)
};

// A plugin's scene body, "@" where the property goes, and its numeric properties.
struct PluginCase {
    std::string body;
    std::vector<Property> properties;
    std::string required;  // what the plugin needs in place of "@" to load at all (blendbsdf's weight)
};

const char *kCamera = R"(<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>)";
const char *kLight = R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)";
const char *kFilm = R"(<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>)";

// Small files the plugins read, written once.
const TempDir &aux_files() {
    static TempDir dir;
    static bool written = false;
    if (!written) {
        dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        dir.write("tri.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        dir.write("colour.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                "property float r\nproperty float g\nproperty float b\nelement face 1\n"
                                "property list uchar int vertex_indices\nend_header\n0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 0 0 1\n3 0 1 2\n");
        SerializedTestMesh m;
        m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        m.indices = {0, 1, 2};
        dir.write("mesh.serialized", serialized({m}));
        dir.write("line.txt", "-1 0 0 0.25\n1 0 0 0.25\n");
        dir.write("spline.txt", "-1 0 0 0.25\n-0.5 0 0 0.25\n0.5 0 0 0.25\n1 0 0 0.25\n");
        dir.write("grid.vol", volume_grid_bytes(sphere_sdf_grid(4)));
        VolumeGridFile density;
        density.values.assign(8, 0.5f);
        dir.write("density.vol", volume_grid_bytes(density));
        VolumeGridFile identity;  // 2 x 2 x 2 matrices S = I (sggx's S)
        identity.channels = 6;
        for (int i = 0; i < 8 * 6; ++i) identity.values.push_back(i % 6 < 3 ? 1.f : 0.f);
        dir.write("sggx.vol", volume_grid_bytes(identity));
        Image img(2, 2, 3);
        std::fill(img.data.begin(), img.data.end(), 0.5f);
        write_exr((dir.dir / "image.exr").string(), img);
        written = true;
    }
    return dir;
}

std::string aux(const std::string &name) { return (aux_files().dir / name).string(); }

std::string shape(const std::string &type, const std::string &inside = "@") {
    return "<shape type=\"" + type + "\">" + inside + "</shape>";
}
std::string file_shape(const std::string &type, const std::string &file) {
    return shape(type, "<string name=\"filename\" value=\"" + aux(file) + "\"/>@");
}
std::string bsdf(const std::string &type, const std::string &inside = "") {
    return shape("sphere", "<bsdf type=\"" + type + "\">@" + inside + "</bsdf>");
}
std::string texture(const std::string &type, const std::string &inside = "") {
    return shape("sphere", "<bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"" + type + "\">" + inside +
                               "@</texture></bsdf>");
}
std::string emitter(const std::string &type, const std::string &inside = "") {
    return "<emitter type=\"" + type + "\">" + inside + "@</emitter>";
}
// A plugin inside the sensor: the scene gets no camera of its own.
std::string sensor(const std::string &type, const std::string &inside = "@") {
    return "<sensor type=\"" + type + "\">" + inside + "</sensor>";
}
std::string integrator(const std::string &type) { return "<integrator type=\"" + type + "\">@</integrator>"; }

Property accepted(const std::string &name, const std::string &element) { return {name, element, Negative::Accepted}; }
Property refused(const std::string &name, const std::string &element) { return {name, element, Negative::Refused}; }

const std::vector<Property> kDepths = {{"max_depth", "integer", Negative::Refused, "-2"}, refused("rr_depth", "integer")};

std::vector<Property> with(std::vector<Property> a, const std::vector<Property> &b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// kind -> type -> case. A plugin with no numeric property has an empty list, said here on purpose.
std::map<std::string, std::map<std::string, PluginCase>> plugin_cases() {
    const Property to_world = accepted("to_world", "transform"), to_uv = accepted("to_uv", "transform");
    const std::vector<Property> iors = {refused("int_ior", "float"), refused("ext_ior", "float")};
    const std::vector<Property> specular = {refused("specular_reflectance", "rgb"), refused("specular_transmittance", "rgb")};
    const std::vector<Property> roughness = {refused("alpha", "float"),
                                             {"alpha_u", "float", Negative::Refused, "-1", R"(<float name="alpha_v" value="0.1"/>)"}};
    const std::vector<Property> principled_lobes = {
        refused("base_color", "rgb"), refused("roughness", "float"), refused("anisotropic", "float"),
        refused("spec_trans", "float"), refused("spec_tint", "float"), refused("sheen", "float"),
        refused("sheen_tint", "float"), refused("flatness", "float"), refused("eta", "float")};
    const std::string diffuse = R"(<bsdf type="diffuse"/>)";
    const std::vector<Property> sampler = {refused("sample_count", "integer"), refused("seed", "integer")};
    const std::string group = R"(<shape type="shapegroup" id="g"><shape type="sphere"/></shape>)";
    const std::vector<Property> projective = {refused("sppc", "integer"), refused("sppp", "integer"), refused("sppi", "integer"),
                                              refused("guiding_rounds", "integer")};
    return {
        {"shape",
         {{"obj", {file_shape("obj", "tri.obj"), {to_world}}},
          {"ply", {file_shape("ply", "tri.ply"), {to_world}}},
          {"serialized", {file_shape("serialized", "mesh.serialized"), {to_world, refused("shape_index", "integer")}}},
          {"rectangle", {shape("rectangle"), {to_world}}},
          {"cube", {shape("cube"), {to_world}}},
          {"disk", {shape("disk"), {to_world}}},
          {"sphere", {shape("sphere"), {to_world, accepted("center", "point"), refused("radius", "float")}}},
          {"cylinder", {shape("cylinder"), {to_world, accepted("p0", "point"), accepted("p1", "point"), refused("radius", "float")}}},
          {"sdfgrid", {file_shape("sdfgrid", "grid.vol"), {to_world}}},
          {"linearcurve", {file_shape("linearcurve", "line.txt"), {to_world}}},
          {"bsplinecurve", {file_shape("bsplinecurve", "spline.txt"), {to_world}}},
          // A group's shapes are built for the instances: their numbers are checked all the same.
          {"shapegroup", {R"(<shape type="shapegroup" id="g"><shape type="sphere">@</shape></shape>)",
                          {to_world, refused("radius", "float")}}},
          {"instance", {group + R"(<shape type="instance"><ref id="g"/>@</shape>)", {to_world}}}}},
        {"bsdf",
         {{"diffuse", {bsdf("diffuse"), {refused("reflectance", "rgb"), refused("reflectance", "float"), refused("reflectance", "spectrum")}}},
          {"twosided", {bsdf("twosided", diffuse), {}}},
          {"mask", {bsdf("mask", diffuse), {refused("opacity", "float")}}},
          // Mitsuba 3 scales the height by any factor, a negative one inverting the bumps.
          {"bumpmap", {bsdf("bumpmap", R"(<texture type="checkerboard"/>)" + diffuse), {accepted("scale", "float")}}},
          {"conductor", {bsdf("conductor"), {refused("eta", "rgb"), refused("k", "rgb"), refused("specular_reflectance", "rgb")}}},
          {"roughconductor", {bsdf("roughconductor"), with(roughness, {refused("eta", "spectrum"), refused("k", "float"),
                                                                       refused("specular_reflectance", "rgb")})}},
          {"plastic", {bsdf("plastic"), with(iors, {refused("diffuse_reflectance", "rgb"), refused("specular_reflectance", "rgb")})}},
          {"roughplastic", {bsdf("roughplastic"), with(iors, {refused("alpha", "float"), refused("diffuse_reflectance", "rgb"),
                                                              refused("specular_reflectance", "float")})}},
          {"dielectric", {bsdf("dielectric"), with(iors, specular)}},
          {"thindielectric", {bsdf("thindielectric"), with(iors, specular)}},
          {"roughdielectric", {bsdf("roughdielectric"), with(with(iors, specular), roughness)}},
          {"principled", {bsdf("principled"), with(principled_lobes, {
              refused("metallic", "float"), refused("clearcoat", "float"), refused("clearcoat_gloss", "float"),
              refused("specular", "float"), refused("main_specular_sampling_rate", "float"),
              refused("clearcoat_sampling_rate", "float"), refused("diffuse_reflectance_sampling_rate", "float")})}},
          {"principledthin", {bsdf("principledthin"), with(principled_lobes, {
              refused("diff_trans", "float"), refused("specular_reflectance_sampling_rate", "float"),
              refused("specular_transmittance_sampling_rate", "float"), refused("diffuse_reflectance_sampling_rate", "float"),
              refused("diffuse_transmittance_sampling_rate", "float")})}},
          {"null", {bsdf("null"), {}}},
          {"normalmap", {bsdf("normalmap", R"(<texture name="normalmap" type="rawconstant"><vector name="value" value="0.5 0.5 1"/></texture>)" + diffuse), {}}},
          {"blendbsdf", {bsdf("blendbsdf", diffuse + diffuse), {refused("weight", "float")}, R"(<float name="weight" value="0.5"/>)"}},
          {"hair", {bsdf("hair"), with(iors, {refused("longitudinal_roughness", "float"), refused("azimuthal_roughness", "float"),
                                              accepted("scale_tilt", "float"), refused("eumelanin", "float"),
                                              refused("pheomelanin", "float"), refused("scale", "float")})}},
          {"pplastic", {bsdf("pplastic"), with(with(iors, roughness), {refused("diffuse_reflectance", "rgb"),
                                                                       refused("specular_reflectance", "rgb")})}},
          // An angle: any sign means something.
          {"polarizer", {bsdf("polarizer"), {accepted("theta", "float"), refused("transmittance", "rgb")}}}}},
        {"texture",
         {{"bitmap", {texture("bitmap", "<string name=\"filename\" value=\"" + aux("image.exr") + "\"/>"), {to_uv}}},
          {"checkerboard", {texture("checkerboard"), {refused("color0", "rgb"), refused("color1", "float"), to_uv}}},
          // The value as written, a normal map's raw numbers included: any sign.
          {"rawconstant", {texture("rawconstant"), {accepted("value", "float")}, R"(<float name="value" value="0.5"/>)"}},
          {"mesh_attribute", {"<shape type=\"ply\"><string name=\"filename\" value=\"" + aux("colour.ply") +
                                  "\"/><bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"mesh_attribute\">"
                                  "<string name=\"name\" value=\"vertex_color\"/>@</texture></bsdf></shape>",
                              {accepted("scale", "float")}}}}},
        {"emitter",
         {{"area", {shape("sphere", "<emitter type=\"area\">@</emitter>"),
                    {refused("radiance", "rgb"), refused("radiance", "float"), refused("radiance", "spectrum")}}},
          {"envmap", {emitter("envmap", "<string name=\"filename\" value=\"" + aux("image.exr") + "\"/>"),
                      {refused("scale", "float"), to_world}}},
          {"constant", {emitter("constant"), {refused("radiance", "rgb"), refused("radiance", "spectrum")}}},
          {"point", {emitter("point"), {refused("intensity", "rgb"), accepted("position", "point")}}},
          {"spot", {emitter("spot"), {refused("intensity", "rgb"), refused("cutoff_angle", "float"),
                                      refused("beam_width", "float"), to_world}}},
          {"directional", {emitter("directional"), {refused("irradiance", "rgb"), accepted("direction", "vector")}}},
          {"projector", {emitter("projector"), {refused("irradiance", "rgb"), refused("scale", "float"),
                                                refused("fov", "float"), to_world}}}}},
        {"sensor",
         {{"perspective", {sensor("perspective", std::string("@") + kFilm),
                           {refused("fov", "float"), refused("near_clip", "float"), refused("far_clip", "float"), to_world}}},
          {"orthographic", {sensor("orthographic", std::string("@") + kFilm),
                            {refused("near_clip", "float"), refused("far_clip", "float"), to_world}}},
          {"thinlens", {sensor("thinlens", std::string(R"(<float name="aperture_radius" value="0.1"/>@)") + kFilm),
                        {refused("fov", "float"), refused("focus_distance", "float"), to_world}}}}},
        {"medium",
         {{"homogeneous", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior">@</medium></shape>)",
                           {refused("sigma_t", "rgb"), refused("sigma_t", "float"), refused("albedo", "rgb"),
                            refused("albedo", "spectrum"), refused("scale", "float")}}},
          {"heterogeneous", {R"(<shape type="sphere"><bsdf type="null"/><medium type="heterogeneous" name="interior">@</medium></shape>)",
                             {refused("sigma_t", "float"), refused("albedo", "rgb"), refused("scale", "float")}}}}},
        {"volume",
         {{"constvolume", {R"(<shape type="sphere"><bsdf type="null"/><medium type="heterogeneous" name="interior"><volume name="sigma_t" type="constvolume">@</volume></medium></shape>)",
                           {refused("value", "rgb"), refused("value", "float")}}},
          {"gridvolume", {R"(<shape type="sphere"><bsdf type="null"/><medium type="heterogeneous" name="interior"><volume name="sigma_t" type="gridvolume"><string name="filename" value=")" +
                              aux("density.vol") + R"("/>@</volume></medium></shape>)",
                          {refused("max_value", "float"), accepted("to_world", "transform")}}}}},
        {"phase",
         {{"isotropic", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"><phase type="isotropic">@</phase></medium></shape>)",
                         {}}},
          {"hg", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"><phase type="hg">@</phase></medium></shape>)",
                  {{"g", "float", Negative::Accepted, "-0.5"}}}},
          {"rayleigh", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"><phase type="rayleigh">@</phase></medium></shape>)",
                        {}}},
          // Mitsuba clips the weight to [0, 1] where it reads it, so any finite number is accepted.
          {"blendphase", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"><phase type="blendphase"><phase type="isotropic"/><phase type="hg"/>@</phase></medium></shape>)",
                          {accepted("weight", "float")}, R"(<float name="weight" value="0.5"/>)"}},
          // Its numbers are in a string; each is checked as a <float> would be, and a density is not negative.
          {"tabphase", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"><phase type="tabphase">@</phase></medium></shape>)",
                        {refused("values", "string")}, R"(<string name="values" value="1, 2"/>)"}},
          // Its one property is a volume (a 6-channel gridvolume in Mitsuba 3), whose numbers are in a file.
          {"sggx", {R"(<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"><phase type="sggx">@</phase></medium></shape>)",
                    {}, R"(<volume name="S" type="gridvolume"><string name="filename" value=")" + aux("sggx.vol") + R"("/></volume>)"}}}},
        {"film",
         {{"hdrfilm", {sensor("perspective", "<film type=\"hdrfilm\">@</film>"),
                       {refused("width", "integer"), refused("height", "integer"), refused("crop_offset_x", "integer"),
                        refused("crop_offset_y", "integer"), refused("crop_width", "integer"), refused("crop_height", "integer")}}}}},
        {"rfilter",
         {{"box", {sensor("perspective", R"(<film type="hdrfilm"><rfilter type="box">@</rfilter></film>)"), {refused("radius", "float")}}},
          {"tent", {sensor("perspective", R"(<film type="hdrfilm"><rfilter type="tent">@</rfilter></film>)"), {refused("radius", "float")}}},
          {"gaussian", {sensor("perspective", R"(<film type="hdrfilm"><rfilter type="gaussian">@</rfilter></film>)"),
                        {refused("stddev", "float")}}}}},
        {"sampler",
         {{"independent", {sensor("perspective", R"(<sampler type="independent">@</sampler>)"), sampler}},
          {"sobol", {sensor("perspective", R"(<sampler type="sobol">@</sampler>)"), sampler}},
          {"stratified", {sensor("perspective", R"(<sampler type="stratified">@</sampler>)"), sampler}},
          {"multijitter", {sensor("perspective", R"(<sampler type="multijitter">@</sampler>)"), sampler}},
          {"ldsampler", {sensor("perspective", R"(<sampler type="ldsampler">@</sampler>)"), sampler}},
          {"orthogonal", {sensor("perspective", R"(<sampler type="orthogonal">@</sampler>)"), sampler}}}},
        {"integrator",
         {{"path", {integrator("path"), kDepths}},
          {"bdpt", {integrator("bdpt"), kDepths}},
          {"light", {integrator("light"), kDepths}},
          // Its own options (bootstrap, chains, large_step, sigma) are bounded where the integrator is made.
          {"pssmlt", {integrator("pssmlt"), kDepths}},
          {"prb", {integrator("prb"), kDepths}},
          {"prb_basic", {integrator("prb_basic"), kDepths}},
          {"prb_projective", {integrator("prb_projective"), with(kDepths, projective)}},
          {"volpath", {integrator("volpath"), kDepths}},
          {"volpathmis", {integrator("volpathmis"), kDepths}},
          {"direct", {integrator("direct"), {refused("emitter_samples", "integer"), refused("bsdf_samples", "integer"),
                                             refused("shading_samples", "integer")}}},
          {"direct_projective", {integrator("direct_projective"), projective}},
          {"ptracer", {integrator("ptracer"), with(kDepths, {refused("samples_per_pass", "integer")})}},
          // Wrappers: their image is their nested integrator's, whose numbers are checked.
          {"moment", {R"(<integrator type="moment"><integrator type="path">@</integrator></integrator>)", kDepths}},
          {"aov", {R"(<integrator type="aov"><string name="aovs" value="d:depth"/><integrator type="path">@</integrator></integrator>)",
                   kDepths}}}},
    };
}

std::string property_xml(const Property &p, const std::string &value) {
    if (p.element == "transform")
        return "<transform name=\"" + p.name + "\"><translate x=\"" + value + "\"/></transform>";
    if (p.element == "point" || p.element == "vector")
        return "<" + p.element + " name=\"" + p.name + "\" value=\"" + value + " 0 1\"/>";
    return "<" + p.element + " name=\"" + p.name + "\" value=\"" + value + "\"/>";
}

// The scene, and the line the property is on.
std::pair<std::string, int> make_scene(const std::string &kind, const PluginCase &c, const Property &p, const std::string &value) {
    const size_t at = c.body.find('@');
    const std::string body = c.body.substr(0, at) + "\n" + p.beside + property_xml(p, value) + "\n" + c.body.substr(at + 1);
    const bool own_sensor = kind == "sensor" || kind == "film" || kind == "rfilter" || kind == "sampler";
    const std::string head = std::string("<scene version=\"3.0.0\">\n") + (own_sensor ? "" : kCamera) + "\n" + kLight + "\n";
    const std::string xml = head + body + "\n</scene>\n";
    const int line = int(std::count(head.begin(), head.end(), '\n') + std::count(body.begin(), body.begin() + long(at) + 1, '\n')) + 1;
    return {xml, line};
}

// The error loading gives, or "" when the scene loads.
std::string load_message(const std::string &xml) {
    try {
        load_scene(write_temp_scene(xml, "numbers.xml"));
    } catch (const std::exception &e) {
        return e.what();
    }
    return "";
}

void expect_refused(const std::string &what, const std::string &xml, int line, const Property &p, const std::string &value) {
    const std::string msg = load_message(xml);
    ASSERT_FALSE(msg.empty()) << what << ": " << value << " loaded:\n" << xml;
    EXPECT_NE(msg.find("numbers.xml:" + std::to_string(line) + ":"), std::string::npos) << what << ": no file:line " << line << ": " << msg;
    EXPECT_NE(msg.find("\"" + p.name + "\""), std::string::npos) << what << ": the property is not named: " << msg;
    EXPECT_NE(msg.find("\"" + value + "\""), std::string::npos) << what << ": the value " << value << " is not named: " << msg;
}

TEST(NumericProperties, EveryPluginsNumbersAreChecked) {
    const auto cases = plugin_cases();
    for (const auto &[kind, names] : supported_plugins())
        for (const std::string &type : names) {
            const auto k = cases.find(kind);
            if (k == cases.end() || !k->second.count(type))
                ADD_FAILURE() << "the " << kind << " plugin '" << type << "' has no row in this test's table: add its numeric "
                              << "properties (and their checks in the loader), or an empty list if it has none";
        }
    int checked = 0;
    for (const auto &[kind, rows] : cases) {  // the rows: every plugin listed, and thinlens, which the list omits
        for (const auto &[type, c] : rows) {
            {  // the host scene loads with none of the properties set: what fails below fails for the value
                const size_t at = c.body.find('@');
                const bool own_sensor = kind == "sensor" || kind == "film" || kind == "rfilter" || kind == "sampler";
                const std::string xml = std::string("<scene version=\"3.0.0\">\n") + (own_sensor ? "" : kCamera) + "\n" +
                                        kLight + "\n" + c.body.substr(0, at) + c.required + c.body.substr(at + 1) + "\n</scene>\n";
                EXPECT_EQ(load_message(xml), "") << kind << " " << type << ": the scene without the property does not load";
            }
            for (const Property &p : c.properties) {
                const std::string what = kind + " " + type + " '" + p.name + "' (" + p.element + ")";
                std::vector<std::string> bad = {"nan", "inf", "-inf", "1e39", "-1e39", "NaN"};
                if (p.element == "integer") bad.insert(bad.end(), {"4294967296", "-4294967296", "99999999999999999999"});
                for (const std::string &v : bad) {
                    auto [xml, line] = make_scene(kind, c, p, v);
                    expect_refused(what, xml, line, p, v);
                    ++checked;
                }
                auto [xml, line] = make_scene(kind, c, p, p.negative_value);
                if (p.negative == Negative::Refused) {
                    expect_refused(what, xml, line, p, p.negative_value);
                } else {
                    EXPECT_EQ(load_message(xml), "") << what << ": Mitsuba 3 accepts " << p.negative_value;
                }
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 500);
}

// Mitsuba 3's rules where it has them: an RGB reflectance is within [0, 1], a float one is not bounded
// above; an emission may be as bright as a float holds; -0 is zero.
TEST(NumericProperties, MitsubasBoundsHoldWhereItHasThem) {
    auto body = [](const std::string &prop) {
        return std::string("<scene version=\"3.0.0\">\n") + kCamera + "\n" + kLight + "\n<shape type=\"sphere\"><bsdf type=\"diffuse\">\n" +
               prop + "\n</bsdf></shape>\n</scene>\n";
    };
    const std::string msg = load_message(body(R"(<rgb name="reflectance" value="0.5, 1.5, 0.5"/>)"));
    EXPECT_NE(msg.find("numbers.xml:5:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"reflectance\" = \"0.5, 1.5, 0.5\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("[0, 1]"), std::string::npos) << msg;
    EXPECT_EQ(load_message(body(R"(<float name="reflectance" value="1.5"/>)")), "");
    EXPECT_EQ(load_message(body(R"(<rgb name="reflectance" value="-0"/>)")), "");
    EXPECT_EQ(load_message(body(R"(<spectrum name="reflectance" value="400:0.2, 700:3"/>)")), "");  // clamped, as Mitsuba
    auto scene = load_scene(write_temp_scene(std::string("<scene version=\"3.0.0\">\n") + kCamera +
                                             "\n<emitter type=\"constant\"><rgb name=\"radiance\" value=\"3e38\"/></emitter>\n</scene>\n"));
    EXPECT_EQ(scene->lights().size(), 1u);
    // A negative emission renders a negative image: refused, whichever way it is written.
    const std::string negative = load_message(std::string("<scene version=\"3.0.0\">\n") + kCamera +
                                              "\n<emitter type=\"constant\"><spectrum name=\"radiance\" value=\"400:1, 500:-2, 700:1\"/></emitter>\n</scene>\n");
    EXPECT_NE(negative.find("numbers.xml:3:"), std::string::npos) << negative;
    EXPECT_NE(negative.find("negative"), std::string::npos) << negative;
    // Each step of a transform is finite, but together they overflow.
    const std::string product = load_message(std::string("<scene version=\"3.0.0\">\n") + kCamera + "\n" + kLight +
                                             "\n<shape type=\"sphere\"><transform name=\"to_world\"><scale value=\"1e30\"/>"
                                             "<scale value=\"1e30\"/></transform></shape>\n</scene>\n");
    EXPECT_NE(product.find("\"to_world\""), std::string::npos) << product;
    EXPECT_NE(product.find("not finite"), std::string::npos) << product;
}

}  // namespace
