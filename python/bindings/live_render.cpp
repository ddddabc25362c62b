// neepp.LiveRender: neepp view's renderer. One scene rendered again and again while a person moves its
// camera and switches options, each render cancelled at once by the next one's request. The integrator is
// prepared once and kept across camera moves (RenderJob::prepared): what it learned of the scene (NEE++'s
// visibility map, the light distributions that read it, the adaptive calibration) belongs to the scene,
// not to the view, so it carries over to the next view and keeps learning there.
#include <atomic>
#include <cmath>
#include <optional>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include "bindings.h"
#include "neepp/integrators/factory.h"
#include "neepp/integrators/option_table.h"
#include "neepp/light_selection/factory.h"
#include "neepp/render/render_output.h"
#include "neepp/scene/scene.h"

namespace neepp::python {

namespace {

using OptionOverrides = std::map<std::string, std::string>;

nb::dict frame_info(const DisplayFrame &f, int width, int height) {
    nb::dict d;
    d["spp"] = f.spp;
    d["render_time_s"] = f.render_time_s;
    d["width"] = width;
    d["height"] = height;
    d["rays"] = f.counters.rays;
    d["shadow_rays"] = f.counters.shadow_rays;
    d["shadow_rays_occluded"] = f.counters.shadow_rays_occluded;
    d["shadow_rays_skipped"] = f.counters.shadow_rays_skipped;
    d["final"] = f.final;
    return d;
}

class LiveRender {
public:
    LiveRender(Scene &scene, const std::string &integrator, const OptionOverrides &options, int threads,
               const std::string &sampler, uint64_t seed)
        : scene_(scene), threads_(threads), sampler_(sampler.empty() ? scene.settings.sampler : sampler), seed_(seed) {
        set_integrator(integrator, options);
    }

    // A new integrator (prepared by the next render: what the old one learned goes with it, since another
    // policy or light sampler keeps another state). Throws ValueError for an unknown name or option.
    void set_integrator(const std::string &name, const OptionOverrides &overrides) {
        refuse_while_rendering("set_integrator");
        integrator_ = scene_integrator(scene_, name, overrides);
        prepared_ = false;
    }

    // The camera's placement (a rigid motion, 4x4 rows) and field of view in degrees along its fov_axis.
    void set_camera(const std::vector<std::vector<double>> &to_world, double fov) {
        refuse_while_rendering("set_camera");
        Matrix4 m;
        if (to_world.size() != 4) throw std::invalid_argument("set_camera: to_world must be 4 rows of 4 numbers");
        for (int r = 0; r < 4; ++r) {
            if (to_world[size_t(r)].size() != 4) throw std::invalid_argument("set_camera: to_world must be 4 rows of 4 numbers");
            for (int c = 0; c < 4; ++c) {
                const double v = to_world[size_t(r)][size_t(c)];
                if (!std::isfinite(v)) throw std::invalid_argument("set_camera: to_world must be finite");
                m.m[size_t(r)][size_t(c)] = float(v);
            }
        }
        const Camera before = scene_.camera;
        try {
            scene_.camera.to_world = Transform(m);
            if (!scene_.camera.to_world.preserves_lengths(1e-3f))
                throw std::invalid_argument("set_camera: to_world must be a rotation and a translation");
            scene_.camera.fov = float(fov);
            scene_.camera.finalize();
        } catch (...) {
            scene_.camera = before;
            throw;
        }
    }

    // Renders up to spp samples per pixel (at 1/scale of the film's resolution: a coarse first image),
    // calling on_frame(image, info) from this thread between passes (display_interval_s apart) and with the
    // final image, until done or cancel(). Returns the statistics (JSON text, as render's).
    std::string render(int spp, int scale, double display_interval_s, nb::object on_frame) {
        if (spp < 1) throw std::invalid_argument("render: spp must be at least 1");
        if (scale < 1) throw std::invalid_argument("render: scale must be at least 1");
        if (rendering_.exchange(true)) throw std::runtime_error("LiveRender.render: not while a render runs");
        struct Rendering {
            std::atomic<bool> &flag;
            ~Rendering() { flag = false; }
        } rendering{rendering_};
        // Stopped by the interpreter's exit (stop_renders), which waits until this is back in Python.
        const RenderInFlight flight(cancel_);

        Camera &cam = scene_.camera;
        const Camera full = cam;
        if (scale > 1 && cam.film_width == 0) {  // a cropped film keeps its window
            cam.width = std::max(1, (full.width + scale - 1) / scale);
            cam.height = std::max(1, (full.height + scale - 1) / scale);
            cam.finalize();
        }
        RenderJob job;
        job.spp = spp;
        job.seed = seed_;
        job.threads = threads_;
        job.sampler = sampler_;
        job.cancel = &cancel_;
        // PSSMLT's chains and their normalisation are paths through the camera: they belong to the view,
        // so it starts afresh at each one.
        job.prepared = prepared_ && !dynamic_cast<const PassIntegrator *>(integrator_.get());
        job.display_interval_s = display_interval_s;
        job.max_pass_s = display_interval_s;  // a pass longer than the interval would hold the image back
        const int width = cam.width, height = cam.height;
        std::optional<nb::python_error> raised;
        if (!on_frame.is_none())
            job.on_display = [&](DisplayFrame frame) {
                nb::gil_scoped_acquire acquire;
                if (raised) return;
                try {
                    nb::dict info = frame_info(frame, width, height);
                    on_frame(to_numpy(std::move(frame.image)), info);
                } catch (nb::python_error &e) {  // ends the render; raised after it
                    raised.emplace(e);
                    cancel_ = true;
                }
            };
        RenderResult result;
        try {
            nb::gil_scoped_release release;
            result = neepp::render(scene_, *integrator_, job);
        } catch (...) {
            cam = full;
            throw;
        }
        prepared_ = true;
        cam = full;
        if (raised) throw *raised;
        nlohmann::json stats = render_statistics(scene_, *integrator_, result, job);
        stats["scale"] = scale;
        return stats.dump();
    }

    // From any thread, at any time: the render running (or the next one, until clear_cancel) stops after
    // the tiles under way, with the image of what it completed.
    void cancel() { cancel_ = true; }
    void clear_cancel() { cancel_ = false; }
    bool prepared() const { return prepared_; }

private:
    void refuse_while_rendering(const char *what) const {
        if (rendering_) throw std::runtime_error(std::string("LiveRender.") + what + ": not while a render runs");
    }

    Scene &scene_;
    const int threads_;
    const std::string sampler_;
    const uint64_t seed_;
    std::unique_ptr<Integrator> integrator_;
    bool prepared_ = false;
    std::atomic<bool> cancel_{false};
    std::atomic<bool> rendering_{false};
};

// What there is to choose from (neepp list): integrators with their options, light samplers, shadow-ray
// policies; neepp view's page offers them.
nb::dict catalog() {
    nb::list integrators;
    for (const IntegratorDoc &d : integrator_docs()) {
        nb::list options;
        for (const OptionDoc &o : d.options) {
            nb::dict od;
            od["name"] = o.name;
            od["default"] = o.default_value;
            od["description"] = o.description;
            od["needs"] = o.needs;
            options.append(od);
        }
        nb::dict dd;
        dd["name"] = d.name;
        dd["description"] = d.description;
        dd["options"] = options;
        integrators.append(dd);
    }
    nb::list policies;
    for (const auto &[name, what] : shadow_ray_policy_docs()) policies.append(nb::make_tuple(name, what));
    nb::dict out;
    out["integrators"] = integrators;
    out["light_samplers"] = light_sampler_names();
    out["shadow_ray_policies"] = policies;
    return out;
}

}  // namespace

void bind_live_render(nb::module_ &m) {
    nb::class_<LiveRender>(m, "LiveRender",
                           "neepp view's renderer: a scene rendered again at each camera move, each render cancelled at "
                           "once by cancel(), with the integrator prepared once and kept (NEE++'s map keeps learning). "
                           "It changes the scene's camera: keep the scene for it alone.")
        .def(nb::init<Scene &, const std::string &, const OptionOverrides &, int, const std::string &, uint64_t>(),
             nb::arg("scene"), nb::arg("integrator"), nb::arg("options"), nb::arg("threads") = 0,
             nb::arg("sampler") = "", nb::arg("seed") = 0, nb::keep_alive<1, 2>())
        .def("set_integrator", &LiveRender::set_integrator, nb::arg("integrator"), nb::arg("options"),
             "Switches to a new integrator (name: empty for the scene's; options over the scene's); ValueError for a "
             "bad name or option.")
        .def("set_camera", &LiveRender::set_camera, nb::arg("to_world"), nb::arg("fov"),
             "Places the camera: to_world (4 rows of 4, a rotation and a translation) and fov in degrees.")
        .def("render", &LiveRender::render, nb::arg("spp"), nb::arg("scale") = 1, nb::arg("display_interval") = 0.1,
             nb::arg("on_frame").none() = nb::none(),
             "Renders up to spp samples per pixel at 1/scale of the resolution, calling on_frame(image, info) "
             "between passes and with the final image, until done or cancel(); returns the statistics as JSON text.")
        .def("cancel", &LiveRender::cancel, "Stops the render under way (or the next one, until clear_cancel).")
        .def("clear_cancel", &LiveRender::clear_cancel)
        .def_prop_ro("prepared", &LiveRender::prepared,
                     "Whether the integrator was prepared by an earlier render (and the next one continues it).");
    m.def("catalog", &catalog,
          "What there is to choose from: integrators (name, description, options with default, description and "
          "needs), light_samplers, shadow_ray_policies ((name, description) pairs).");
}

}  // namespace neepp::python
