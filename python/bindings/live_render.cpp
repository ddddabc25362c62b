// neepp.LiveRender: neepp view's renderer. One scene rendered again and again while a person moves its
// camera and switches options, each render cancelled at once by the next one's request. The integrator is
// prepared once and kept across camera moves (RenderJob::prepared): what it learned of the scene (NEE++'s
// visibility map, the light distributions that read it, the adaptive calibration) belongs to the scene,
// not to the view, so it carries over to the next view and keeps learning there. What it learned can be
// looked into (the map view: a pixel's first hit, the map's row of its cell, the light distribution there)
// and saved, between passes.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include <tbb/parallel_for.h>
#include "bindings.h"
#include "neepp/base/light_sampler.h"
#include "neepp/integrators/bdpt.h"
#include "neepp/integrators/factory.h"
#include "neepp/integrators/path.h"
#include "neepp/integrators/option_table.h"
#include "neepp/light_selection/factory.h"
#include "neepp/render/render_output.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_file.h"

namespace neepp::python {

namespace {

using OptionOverrides = std::map<std::string, std::string>;

nb::dict frame_info(const DisplayFrame &f, int width, int height) {
    nb::dict d;
    // Within a pass the finished tiles' pixels have its samples too: the fewest, the most and the mean.
    d["spp"] = f.spp;
    d["spp_max"] = f.spp_max;
    d["spp_mean"] = f.spp_mean;
    d["within_pass"] = f.within_pass;
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
        : scene_(scene), threads_(threads), sampler_(sampler.empty() ? scene.settings.sampler : sampler), seed_(seed),
          view_(scene.camera) {
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
        view_ = scene_.camera;
    }

    // Renders up to spp samples per pixel (at 1/scale of the film's resolution: a coarse first image),
    // calling on_frame(image, info) display_interval_s apart and with the final image, until done or
    // cancel(). Returns the statistics (JSON text, as render's). A frame comes from this thread between
    // passes, or (info["within_pass"]) from a thread of the render's own while a pass runs, once the first
    // is complete: the completed passes with the tiles of the running one that are finished, so that the
    // image moves on ten times a second however long a pass of the scene takes. Never two at once. With
    // first_pass_frames, within the first pass too: its finished tiles, NaN in the other pixels (info["spp"]
    // 0), which the caller fills with what it has (neepp view: the coarse image of the view).
    std::string render(int spp, int scale, double display_interval_s, nb::object on_frame, bool first_pass_frames) {
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
        job.max_pass_s = display_interval_s;  // and a pass takes about that long, as far as one spp allows
        job.display_within_pass = true;
        job.display_first_pass = first_pass_frames;
        const int width = cam.width, height = cam.height;
        std::optional<nb::python_error> raised;
        if (!on_frame.is_none())
            job.on_display = [&](DisplayFrame frame) {
                nb::gil_scoped_acquire acquire;
                if (raised) return;
                // Between passes what the integrator learned holds still, so on_frame may look into it; within
                // a pass it is changing, and the map view is refused.
                struct InFrame {
                    std::atomic<bool> &flag;
                    const bool between;
                    InFrame(std::atomic<bool> &f, bool b) : flag(f), between(b) { if (between) flag = true; }
                    ~InFrame() { if (between) flag = false; }
                } in_frame{in_frame_, !frame.within_pass};
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

    // The map view. These read what the integrator learned, which a pass changes: they are answered between
    // renders or from on_frame (between passes), never while a pass runs.

    // The map the integrator keeps (resolution, cells, pairs known), or None: an integrator without NEE++'s
    // map (plain NEE with a light sampler that reads none), or not prepared yet.
    nb::object map_info() const {
        refuse_during_pass("map_info");
        const MapParts m = parts();
        if (!m.map) return nb::none();
        nb::dict d;
        d["resolution"] = m.grid->resolution();
        d["voxel_count"] = m.grid->voxel_count();
        d["cell_count"] = m.grid->cell_count();
        d["known_pairs"] = m.map->known_pairs();
        d["fingerprint"] = scene_fingerprint(scene_);
        return d;
    }

    // The map's cell of each pixel's first hit (the camera ray through the pixel's centre), -1 where the ray
    // leaves the scene: (height, width) int32, of the full image at the camera set.
    nb::ndarray<nb::numpy, int32_t, nb::ndim<2>> pixel_cells() const {
        refuse_during_pass("pixel_cells");
        const MapParts m = parts();
        if (!m.map) throw std::runtime_error("pixel_cells: the integrator keeps no visibility map");
        const int W = view_.width, H = view_.height;
        auto *cells = new std::vector<int32_t>(size_t(W) * size_t(H), -1);
        {
            nb::gil_scoped_release release;
            tbb::parallel_for(0, H, [&](int y) {
                for (int x = 0; x < W; ++x) {
                    SurfaceInteraction si;
                    if (scene_.intersect(view_.pixel_ray(x, y, Vec2(0.5f, 0.5f)), si))
                        (*cells)[size_t(y) * size_t(W) + size_t(x)] = int32_t(m.grid->voxel_of(si.p));
                }
            });
        }
        nb::capsule owner(cells, [](void *p) noexcept { delete static_cast<std::vector<int32_t> *>(p); });
        return nb::ndarray<nb::numpy, int32_t, nb::ndim<2>>(cells->data(), {size_t(H), size_t(W)}, owner);
    }

    // What the pixel (x, y) of the full image sees first: None where its ray leaves the scene, else its point,
    // normal (turned toward the camera), map cell (-1 without a map) and the probability with which NEE's
    // light choice there picks each of the scene's lights (their order; None where the integrator has no
    // light choice).
    nb::object pick(int x, int y) const {
        refuse_during_pass("pick");
        if (x < 0 || y < 0 || x >= view_.width || y >= view_.height)
            throw std::invalid_argument("pick: (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                                        std::to_string(view_.width) + "x" + std::to_string(view_.height) + " image");
        const Ray ray = view_.pixel_ray(x, y, Vec2(0.5f, 0.5f));
        SurfaceInteraction si;
        if (!scene_.intersect(ray, si)) return nb::none();
        const MapParts m = parts();
        // The side the camera ray arrived from, as the path tracer turns a vertex's normal for its light
        // choice (PathIntegrator::light_context), so the distribution shown is the one it samples from.
        const Vec3 n = dot(ray.d, si.n) > 0 ? -si.n : si.n;
        nb::dict d;
        d["point"] = nb::make_tuple(si.p.x, si.p.y, si.p.z);
        d["normal"] = nb::make_tuple(n.x, n.y, n.z);
        d["cell"] = m.map ? int64_t(m.grid->voxel_of(si.p)) : int64_t(-1);
        if (m.lights) {
            const LightSampleContext ctx{si.p, n};
            std::vector<float> pmf;
            for (const auto &light : scene_.lights()) pmf.push_back(m.lights->pmf(ctx, *light));
            d["light_pmf"] = vector_to_numpy(std::move(pmf));
            d["light_sampler"] = m.lights->name();
        } else {
            d["light_pmf"] = nb::none();
        }
        return d;
    }

    // The map's row of a cell: Ṽ(cell, b) for every cell b, NaN where no shadow ray between the two was traced
    // yet (the map knows nothing of the pair).
    nb::ndarray<nb::numpy, float> visibility_row(int64_t cell) const {
        refuse_during_pass("visibility_row");
        const MapParts m = parts();
        if (!m.map) throw std::runtime_error("visibility_row: the integrator keeps no visibility map");
        if (cell < 0 || cell >= int64_t(m.map->cell_count()))
            throw nb::index_error(("visibility_row: cell " + std::to_string(cell) + " out of range (the map has " +
                                   std::to_string(m.map->cell_count()) + " cells)").c_str());
        std::vector<float> row(m.map->cell_count());
        for (uint32_t b = 0; b < m.map->cell_count(); ++b) {
            const PairCounts c = m.map->counts(uint32_t(cell), b);
            row[b] = c.traced ? VisibilityMap::estimate(c) : std::numeric_limits<float>::quiet_NaN();
        }
        return vector_to_numpy(std::move(row));
    }

    // Writes the map as a visibility-map file (the format of -I visibility_map=FILE, which a render then
    // loads); false where the integrator keeps none.
    bool save_visibility_map(const std::filesystem::path &path) const {
        refuse_during_pass("save_visibility_map");
        const MapParts m = parts();
        if (!m.map) return false;
        save_visibility_map_file(path.string(), *m.grid, *m.map);
        return true;
    }

private:
    void refuse_while_rendering(const char *what) const {
        if (rendering_) throw std::runtime_error(std::string("LiveRender.") + what + ": not while a render runs");
    }
    void refuse_during_pass(const char *what) const {
        if (rendering_ && !in_frame_)
            throw std::runtime_error(std::string("LiveRender.") + what +
                                     ": only between renders or from on_frame between passes");
    }
    void save_visibility_map_file(const std::string &path, const VoxelGrid &grid, const VisibilityMap &map) const {
        neepp::save_visibility_map(path, grid, map, scene_fingerprint(scene_));
    }

    // The integrator's NEE++ parts: its map and grid (null where it keeps none) and its light choice.
    struct MapParts {
        const VoxelGrid *grid = nullptr;
        const VisibilityMap *map = nullptr;
        const LightSampler *lights = nullptr;
    };
    MapParts parts() const {
        MapParts out;
        if (!prepared_) return out;  // the map is built by the first render's prepare()
        const ShadowRayTester *shadow = nullptr;
        if (auto *path = dynamic_cast<PathIntegrator *>(integrator_.get())) {
            shadow = &path->shadow_rays();
            out.lights = path->light_sampler();
        } else if (auto *bdpt = dynamic_cast<BDPTIntegrator *>(integrator_.get())) {
            shadow = &bdpt->shadow_rays();
            out.lights = bdpt->light_sampler();
        }
        // A map whose seeding was deferred and then not needed (rejection off) has no cells: nothing to show.
        if (shadow && shadow->voxel_grid() && shadow->visibility_map() && shadow->voxel_grid()->resolution() > 0 &&
            shadow->visibility_map()->cell_count() == shadow->voxel_grid()->cell_count()) {
            out.grid = shadow->voxel_grid();
            out.map = shadow->visibility_map();
        }
        return out;
    }

    Scene &scene_;
    const int threads_;
    const std::string sampler_;
    const uint64_t seed_;
    std::unique_ptr<Integrator> integrator_;
    bool prepared_ = false;
    std::atomic<bool> cancel_{false};
    std::atomic<bool> rendering_{false};
    std::atomic<bool> in_frame_{false};  // on_frame runs (between passes)
    Camera view_;  // the camera set, at the full resolution (the scene's is smaller during a coarse render)
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
             nb::arg("on_frame").none() = nb::none(), nb::arg("first_pass_frames") = false,
             "Renders up to spp samples per pixel at 1/scale of the resolution, calling on_frame(image, info) "
             "between passes, within them (info['within_pass']) and with the final image, until done or cancel(); "
             "returns the statistics as JSON text. first_pass_frames: frames within the first pass too, NaN in the "
             "pixels of its unfinished tiles (info['spp'] 0).")
        .def("cancel", &LiveRender::cancel, "Stops the render under way (or the next one, until clear_cancel).")
        .def("clear_cancel", &LiveRender::clear_cancel)
        .def_prop_ro("prepared", &LiveRender::prepared,
                     "Whether the integrator was prepared by an earlier render (and the next one continues it).")
        .def("map_info", &LiveRender::map_info,
             "The integrator's visibility map (resolution, voxel_count, cell_count, known_pairs, fingerprint), or None "
             "where it keeps none. This and the map view's calls below: between renders or from on_frame.")
        .def("pixel_cells", &LiveRender::pixel_cells,
             "The map cell of each pixel's first hit (camera ray through its centre), -1 where it leaves the scene: "
             "(height, width) int32.")
        .def("pick", &LiveRender::pick, nb::arg("x"), nb::arg("y"),
             "What pixel (x, y) sees first: None, or point, normal, cell (-1 without a map), light_pmf (the "
             "probability of each scene light under NEE's light choice there, or None) and light_sampler.")
        .def("visibility_row", &LiveRender::visibility_row, nb::arg("cell"),
             "V~(cell, b) for every cell b (float32), NaN where the pair was never traced.")
        .def("save_visibility_map", &LiveRender::save_visibility_map, nb::arg("path"),
             "Writes the map as a visibility-map file (-I visibility_map=FILE loads it); False where there is none.");
    m.def("catalog", &catalog,
          "What there is to choose from: integrators (name, description, options with default, description and "
          "needs), light_samplers, shadow_ray_policies ((name, description) pairs).");
}

}  // namespace neepp::python
