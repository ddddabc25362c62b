#include "neepp/loader/supported_plugins.h"
#include "neepp/loader/scene_loader.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include <fmt/core.h>
#include "neepp/io/image.h"
#include "neepp/loader/factories.h"
#include "neepp/loader/problems.h"

namespace neepp {

namespace loader {

void load_fov(const XmlNode &sensor, Camera &cam) {
    if (sensor.has("fov")) {
        cam.fov = sensor.get_float("fov", 0.f, NumberRange{0, 180, true, true});
        cam.fov_axis = sensor.get_string("fov_axis", "x");
        return;
    }
    // fov_axis is then left unread, as Mitsuba does (it refuses the scene, neepp warns).
    // Mitsuba 3's default: a focal length (35 mm film equivalent, 50mm unless given), which sets the
    // angle across the 36 x 24 mm frame's diagonal, applied to the film's diagonal whatever fov_axis
    // says (a square film gets 34.0° in x, a 3:2 one 39.6°).
    const std::string text = sensor.get_string("focal_length", "50mm");
    char *end = nullptr;
    const float f = std::strtof(text.c_str(), &end);
    if (end == text.c_str() || !(std::string(end).empty() || std::string(end) == "mm") || !(f > 0) || !std::isfinite(f))
        throw sensor.error("focal_length '" + text + "' is not a length in millimetres (e.g. 50mm)");
    cam.fov = 2.f * std::atan(std::sqrt(36.f * 36.f + 24.f * 24.f) / (2.f * f)) * 180.f / kPi;
    cam.fov_axis = "diagonal";
}

}  // namespace loader

namespace {

void load_film(const XmlNode &film, Scene &scene) {
    if (film.type != "hdrfilm") throw film.error("unsupported film '" + film.type + "' (supported: " + supported_list("film") + ")");
    constexpr int kMaxSide = kMaxImageSide;
    const NumberRange side = NumberRange::between(1, kMaxSide);
    scene.camera.width = film.get_int("width", 768, side);
    scene.camera.height = film.get_int("height", 576, side);
    // Mitsuba's film also carries output settings that do not change the image.
    film.get_string("file_format", "openexr");
    film.get_string("pixel_format", "rgb");
    film.get_string("component_format", "float16");
    film.get_bool("banner", false);
    if (scene.camera.width < 1 || scene.camera.height < 1 || scene.camera.width > kMaxSide || scene.camera.height > kMaxSide)
        throw film.error(fmt::format("film size {}x{} is out of range (1 to {} pixels per side)", scene.camera.width,
                                     scene.camera.height, kMaxSide));
    // Mitsuba's crop window: the image is that part of the film.
    const int cx = film.get_int("crop_offset_x", 0, NumberRange::between(0, scene.camera.width - 1)),
              cy = film.get_int("crop_offset_y", 0, NumberRange::between(0, scene.camera.height - 1));
    const int cw = film.get_int("crop_width", scene.camera.width - cx, NumberRange::between(1, scene.camera.width - cx)),
              ch = film.get_int("crop_height", scene.camera.height - cy, NumberRange::between(1, scene.camera.height - cy));
    if (cx != 0 || cy != 0 || cw != scene.camera.width || ch != scene.camera.height) {
        try {
            scene.camera.crop(cx, cy, cw, ch);
        } catch (const std::invalid_argument &e) {
            throw film.error(e.what());
        }
    }
    for (const auto &child : film.children) {
        if (child->tag != "rfilter") throw child->error("unexpected <" + child->tag + "> inside the film");
        RenderSettings &s = scene.settings;
        s.rfilter = child->type;
        // A filter wider than 16 pixels is no scene's intent, and each sample would touch thousands of pixels.
        const NumberRange radius{0, 16, true, false};
        if (s.rfilter == "box") s.rfilter_radius = child->get_float("radius", 0.5f, radius);
        else if (s.rfilter == "tent") s.rfilter_radius = child->get_float("radius", 1.f, radius);
        else if (s.rfilter == "gaussian") {
            s.rfilter_stddev = child->get_float("stddev", 0.5f, NumberRange{0, 4, true, false});
            s.rfilter_radius = 4.f * s.rfilter_stddev;
        } else {
            throw child->error("unsupported reconstruction filter '" + s.rfilter + "' (box, tent, gaussian)");
        }
        if (!(s.rfilter_radius > 0 && s.rfilter_radius <= 16)) throw child->error("filter radius out of range (0, 16]");
        loader::warn_unused(*child);
    }
    loader::warn_unused(film);
}

// Mitsuba instantiates a <sampler> wherever it stands, so a bad one is an error even where nothing uses it.
void load_sampler(const XmlNode &sampler, RenderSettings &settings) {
    const std::vector<std::string> &names = supported_names("sampler");
    if (std::find(names.begin(), names.end(), sampler.type) == names.end())
        throw sampler.error("unsupported sampler '" + sampler.type + "' (supported: " + supported_list("sampler") + ")");
    settings.sampler = sampler.type;
    settings.spp = sampler.get_int("sample_count", 4);
    if (settings.spp < 1) throw sampler.property_error("sample_count", "sample_count must be at least 1");
    // Mitsuba 3 reads the seed as an unsigned integer and refuses a negative one.
    settings.seed = uint64_t(sampler.get_int("seed", 0, NumberRange::at_least(0)));
    loader::warn_unused(sampler);
}

void load_thin_lens(const XmlNode &sensor, Camera &cam) {
    // Mitsuba's thinlens requires the radius, and refuses a camera transform that scales (the lens would
    // no longer be a disk of that radius).
    cam.aperture_radius = sensor.get_float("aperture_radius");
    if (!(cam.aperture_radius >= 0)) throw sensor.property_error("aperture_radius", "aperture_radius must be zero or more");
    if (!(cam.focus_distance > 0)) throw sensor.property_error("focus_distance", "focus_distance must be greater than zero");
    if (!cam.to_world.preserves_lengths(1e-3f))
        throw sensor.error("the thinlens sensor's to_world must not scale (Mitsuba 3 refuses scale factors there)");
    if (cam.aperture_radius == 0)  // Mitsuba warns too, and renders with a radius of float epsilon: a pinhole
        loader::warn(sensor.file, sensor.line, "thinlens: aperture_radius 0 renders as a pinhole camera");
}

void load_sensor(const XmlNode &sensor, Scene &scene, loader::Factories &factories) {
    if (sensor.type != "perspective" && sensor.type != "thinlens" && sensor.type != "orthographic")
        throw sensor.error("unsupported sensor '" + sensor.type + "' (supported: " + supported_list("sensor") + ")");
    Camera &cam = scene.camera;
    cam.to_world = sensor.get_transform("to_world");
    if (sensor.type == "orthographic") cam.projection = Projection::Orthographic;
    else loader::load_fov(sensor, cam);
    cam.near_clip = sensor.get_float("near_clip", 1e-2f);
    if (!(cam.near_clip > 0)) throw sensor.property_error("near_clip", "near_clip must be greater than zero");
    cam.far_clip = sensor.get_float("far_clip", 1e4f);
    if (!(cam.far_clip > cam.near_clip)) throw sensor.property_error("far_clip", "far_clip must be greater than near_clip");
    // Every Mitsuba projective sensor reads it; only a lens uses it.
    cam.focus_distance = sensor.get_float("focus_distance", cam.far_clip);
    if (sensor.type == "thinlens") load_thin_lens(sensor, cam);
    for (const auto &child : sensor.children) {
        if (child->tag == "film") {
            load_film(*child, scene);
        } else if (child->tag == "sampler") {
            load_sampler(*child, scene.settings);
        } else if (child->tag == "medium") {  // the medium the camera sits in
            if (cam.medium) throw child->error("a sensor sits in one medium (this is its second)");
            cam.medium = factories.medium(*child);
        } else {
            throw child->error("unexpected <" + child->tag + "> inside the sensor");
        }
    }
    try {
        cam.finalize();
    } catch (const std::exception &e) {
        throw sensor.error(e.what());
    }
    loader::warn_unused(sensor);
}


std::unique_ptr<Scene> read_scene(const std::string &path, const std::map<std::string, std::string> &defines,
                                  const std::set<std::string> &may_be_unused) {
    using loader::attempt;
    std::vector<std::string> unused;
    std::shared_ptr<XmlNode> root = parse_mitsuba_xml(path, defines, &unused);
    std::erase_if(unused, [&](const std::string &u) { return may_be_unused.count(u.substr(0, u.find('='))) != 0; });
    if (!unused.empty()) attempt([&] { throw SceneError(path, unused_parameters_problem(unused)); });
    auto scene = std::make_unique<Scene>();
    scene->source_path = path;
    loader::Factories factories;
    bool have_sensor = false;
    // Elements that shapes hold (an area emitter may be declared at the top level and <ref>'d by a shape),
    // and those sensors hold (a sampler may be too, and is then read once, by the sensor).
    std::set<const XmlNode *> in_shapes, in_sensors;
    for (const auto &node : root->children)
        if (node->tag == "shape" || node->tag == "sensor")
            for (const auto &child : node->children) (node->tag == "shape" ? in_shapes : in_sensors).insert(child.get());
    for (const auto &node : root->children) attempt([&] {  // when checking, a broken element is left out
        const std::string &tag = node->tag;
        if (tag == "shape") {
            factories.shape(*node, *scene);
        } else if (tag == "emitter" && node->type == "area") {
            // Made by the shapes that <ref> it, each its own light, as in Mitsuba.
            if (!in_shapes.count(node.get()))
                throw node->error("this 'area' emitter is attached to no shape (nest it in a <shape>, or <ref> it from one)");
        } else if (tag == "emitter") {
            factories.emitter(*node, *scene);
        } else if (tag == "sensor") {
            if (have_sensor) throw node->error("only one sensor is supported");
            load_sensor(*node, *scene, factories);
            have_sensor = true;
        } else if (tag == "sampler") {
            // Mitsuba makes it and leaves it to the <ref>s that use it (a sensor's): alone it changes nothing,
            // but is checked all the same.
            RenderSettings unused_settings;
            if (!in_sensors.count(node.get())) load_sampler(*node, unused_settings);
        } else if (tag == "integrator") {
            loader::load_integrator(*node, scene->settings);
        } else if (tag == "bsdf" || tag == "texture") {
            // Declared for later <ref>s; built when a shape uses them (and, when checking, now, so that one
            // no shape uses is checked too).
            if (loader::checking()) tag == "bsdf" ? (void)factories.bsdf(*node) : (void)factories.texture(*node);
        } else if (tag == "medium") {
            factories.medium(*node, false);  // declared for the shapes and the sensor that <ref> it
        } else {
            throw node->error("unsupported element <" + tag + "> at the top level of the scene");
        }
    });
    factories.warn_unused_media();
    factories.give_media_to(*scene);
    if (!have_sensor) {
        scene->camera.finalize();  // Mitsuba's default sensor would look from the origin; warn instead of guessing
        loader::warn(path, 0, "no <sensor>; using a default camera at the origin");
    }
    if (scene->lights().empty())
        attempt([&] { throw SceneError(path, "the scene has no light source (no emitter): the image would be black"); });
    return scene;
}

}  // namespace

std::unique_ptr<Scene> load_scene(const std::string &path, const std::map<std::string, std::string> &defines,
                                  const std::set<std::string> &may_be_unused) {
    auto scene = read_scene(path, defines, may_be_unused);
    try {
        scene->build();
    } catch (const std::exception &e) {
        throw SceneError(path, e.what());
    }
    return scene;
}

std::vector<SceneProblem> check_scene(const std::string &path, const std::map<std::string, std::string> &defines,
                                     const std::set<std::string> &may_be_unused) {
    std::vector<SceneProblem> problems;
    loader::CheckingScope scope(problems);
    try {
        read_scene(path, defines, may_be_unused);  // the BVH is not built: it cannot fail where loading succeeded
    } catch (const SceneError &e) {  // what stops even a check (a malformed XML file)
        loader::record(e);
    }
    return problems;
}

}  // namespace neepp
