// neepp.Scene: a Mitsuba 3 scene loaded by the renderer's loader, with what a script wants to know of it
// (film, camera, lights, bounds, the render settings the file carries).
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>
#include <nanobind/stl/vector.h>
#include <nanobind/stl/filesystem.h>
#include "bindings.h"
#include "neepp/lights/area_light.h"
#include "neepp/lights/environment_light.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/visibility/map_file.h"

namespace neepp::python {

namespace {

nb::tuple vec(const Vec3 &v) { return nb::make_tuple(v.x, v.y, v.z); }

const char *light_type(const Light &light) {
    if (dynamic_cast<const AreaLight *>(&light)) return "area";
    if (dynamic_cast<const EnvironmentMapLight *>(&light)) return "envmap";
    if (dynamic_cast<const ConstantEnvironmentLight *>(&light)) return "constant";
    if (dynamic_cast<const PointLight *>(&light)) return "point";
    return "other";
}

}  // namespace

void bind_scene(nb::module_ &m) {
    nb::class_<Scene>(m, "Scene", "A scene loaded from a Mitsuba 3 XML file (neepp.load).")
        .def_prop_ro("path", [](const Scene &s) { return s.source_path; }, "The scene file it was loaded from.")
        .def_prop_ro("width", [](const Scene &s) { return s.camera.width; }, "Film width in pixels.")
        .def_prop_ro("height", [](const Scene &s) { return s.camera.height; }, "Film height in pixels.")
        .def_prop_ro("camera", [](const Scene &s) {
                const Camera &c = s.camera;
                nb::list rows;
                for (const auto &row : c.to_world.matrix.m) rows.append(nb::make_tuple(row[0], row[1], row[2], row[3]));
                nb::dict d;
                d["type"] = c.projection == Projection::Orthographic ? "orthographic" : c.has_lens() ? "thinlens" : "perspective";
                d["position"] = vec(c.position());
                d["to_world"] = rows;
                d["fov"] = c.fov;
                d["fov_axis"] = c.fov_axis;
                d["near_clip"] = c.near_clip;
                d["far_clip"] = c.far_clip;
                if (c.has_lens()) {
                    d["aperture_radius"] = c.aperture_radius;
                    d["focus_distance"] = c.focus_distance;
                }
                d["width"] = c.width;
                d["height"] = c.height;
                return d;
            },
            "The camera: type (perspective, thinlens, orthographic), position, to_world (4x4 rows), fov in degrees along fov_axis (perspective, thinlens), clip distances, film size; a thinlens's aperture_radius and focus_distance.")
        .def_prop_ro("lights", [](const Scene &s) {
                nb::list lights;
                for (const auto &light : s.lights()) {
                    nb::dict d;
                    d["type"] = light_type(*light);
                    d["power"] = vec(light->power());
                    d["infinite"] = light->is_infinite();
                    d["delta"] = light->is_delta();
                    // Where it is, for tools that name a light (neepp view's light distribution); none for
                    // infinite lights.
                    if (const auto b = light->bounds()) d["center"] = vec(b->bounds.center());
                    lights.append(d);
                }
                return lights;
            },
            "One dict per light (type: area, envmap, constant or point; power as RGB; infinite; delta; center, the middle of "
            "its bounds, for lights that have bounds).")
        .def_prop_ro("bounds", [](const Scene &s) { return nb::make_tuple(vec(s.bounds().lo), vec(s.bounds().hi)); },
                     "The scene's bounding box, ((x, y, z) low, (x, y, z) high).")
        .def_prop_ro("triangle_count", &Scene::triangle_count)
        .def_prop_ro("integrator", [](const Scene &s) { return s.settings.integrator; }, "The integrator the file names.")
        .def_prop_ro("integrator_options", [](const Scene &s) { return s.settings.integrator_options; },
                     "The integrator's options as the file gives them.")
        .def_prop_ro("spp", [](const Scene &s) { return s.settings.spp; }, "The file's sample count.")
        .def_prop_ro("sampler", [](const Scene &s) { return s.settings.sampler; })
        .def_prop_ro("seed", [](const Scene &s) { return s.settings.seed; }, "The file's sampler seed.")
        .def_prop_ro("fingerprint", [](const Scene &s) { return scene_fingerprint(s); },
                     "A hash of what visibility depends on (geometry, lights, bounds): a visibility map is valid for "
                     "every scene with the same fingerprint.")
        .def("__repr__", [](const Scene &s) {
            return "<neepp.Scene '" + s.source_path + "' " + std::to_string(s.camera.width) + "x" +
                   std::to_string(s.camera.height) + ", " + std::to_string(s.triangle_count()) + " triangles, " +
                   std::to_string(s.lights().size()) + " lights>";
        });
    m.def("check", [](const std::filesystem::path &path, const std::map<std::string, std::string> &parameters) {
              std::vector<SceneProblem> problems;
              {
                  nb::gil_scoped_release release;
                  problems = check_scene(path.string(), parameters);
              }
              nb::list out;
              for (const SceneProblem &p : problems) {
                  nb::dict d;
                  d["file"] = p.file;
                  d["line"] = p.line;
                  d["severity"] = p.error ? "error" : "warning";
                  d["problem"] = p.problem;
                  d["text"] = p.text();
                  out.append(d);
              }
              return out;
          },
          nb::arg("path"), nb::arg("parameters") = std::map<std::string, std::string>{},
          "Every problem of a scene at once, without rendering it (neepp check): a list of dicts with file, line, "
          "severity (error or warning), problem and text.");
    m.def("load", [](const std::filesystem::path &path, const std::map<std::string, std::string> &parameters) {
              nb::gil_scoped_release release;  // meshes, textures and the BVH take a while
              return load_scene(path.string(), parameters);
          },
          nb::arg("path"), nb::arg("parameters") = std::map<std::string, std::string>{},
          "Loads a Mitsuba 3 XML scene; parameters override its <default> values (as -D name=value).");
}

}  // namespace neepp::python
