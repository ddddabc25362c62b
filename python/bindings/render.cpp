// neepp.render: the render loop the CLI runs, on a scene loaded in Python. The render runs on a thread of
// its own with the GIL released, while the calling thread watches it: it forwards the fraction done to the
// progress callback and turns Ctrl-C (a pending KeyboardInterrupt) or the callback's False into the render
// loop's cancel, which ends the render with the image of the passes completed, as the CLI does on SIGINT.
// The render thread never touches Python: the GIL is free for other Python threads (their own renders
// included) the whole time, taken back only to call the callback and to check for signals.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <nanobind/stl/map.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include "bindings.h"
#include "neepp/integrators/factory.h"
#include "neepp/render/render_output.h"
#include "neepp/scene/scene.h"

namespace neepp::python {

std::unique_ptr<Integrator> scene_integrator(const Scene &scene, const std::string &name,
                                             const std::map<std::string, std::string> &overrides) {
    Options options(scene.settings.integrator_options);
    for (const auto &[key, value] : overrides) options.set(key, value);
    return make_integrator(name.empty() ? scene.settings.integrator : name, options);
}

namespace {

struct InFlight {
    std::mutex mutex;
    std::condition_variable ended;
    std::set<std::atomic<bool> *> cancels;
    bool exiting = false;  // set by stop_renders: a render that starts after it stops at once
};
InFlight &in_flight() {
    static InFlight &f = *new InFlight;  // never destroyed: a daemon thread's render may outlive exit's destructors
    return f;
}

// neepp's atexit handler: cancels every render under way and waits (GIL released: they may need it to end)
// until each has returned, or timeout_s. Python runs it before finalization, while daemon threads still
// run: their renders end with the image so far and nothing is left running into the teardown.
bool stop_renders(double timeout_s) {
    InFlight &f = in_flight();
    nb::gil_scoped_release release;
    std::unique_lock<std::mutex> lock(f.mutex);
    f.exiting = true;
    for (std::atomic<bool> *c : f.cancels) *c = true;
    return f.ended.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return f.cancels.empty(); });
}

}  // namespace

RenderInFlight::RenderInFlight(std::atomic<bool> &cancel) : cancel_(cancel) {
    InFlight &f = in_flight();
    std::lock_guard<std::mutex> lock(f.mutex);
    f.cancels.insert(&cancel_);
    if (f.exiting) cancel_ = true;
}

RenderInFlight::~RenderInFlight() {
    InFlight &f = in_flight();
    std::lock_guard<std::mutex> lock(f.mutex);
    f.cancels.erase(&cancel_);
    f.ended.notify_all();
}

namespace {

RenderJob make_job(const Scene &scene, int spp, double time_s, uint64_t seed, int threads, const std::string &sampler) {
    RenderJob job;
    job.spp = spp > 0 ? spp : (time_s > 0 ? 0 : scene.settings.spp);
    job.time_limit_s = time_s;
    job.seed = seed;
    job.threads = threads;
    job.sampler = sampler.empty() ? scene.settings.sampler : sampler;
    return job;
}

struct Watched {
    RenderResult result;
    bool interrupted = false;  // by Ctrl-C
    bool cancelled = false;    // by the progress callback's False
};

// Renders on a thread of its own while this (the Python) thread forwards progress and watches for Ctrl-C.
Watched render_watched(const Scene &scene, Integrator &integrator, RenderJob job, nb::object progress) {
    std::atomic<bool> cancel{false};
    std::atomic<double> fraction{0};
    job.cancel = &cancel;
    const bool callback = !progress.is_none() && PyCallable_Check(progress.ptr());
    if (!callback && nb::bool_(progress)) job.progress = ProgressStyle::bar;
    job.on_progress = [&](double f, double) { fraction = f; };

    Watched watched;
    std::exception_ptr failure;
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::optional<nb::python_error> raised;  // by the callback or a signal handler: ends the render, raised after it
    // Until this function is back in Python, GIL held: the interpreter's exit must not begin before, since
    // a daemon thread that takes the GIL after it has begun is ended by pthread_exit, whose unwinding
    // cannot pass nanobind's GIL guards (noexcept) and aborts the process.
    const RenderInFlight flight(cancel);
    {
        nb::gil_scoped_release release;
        std::thread worker([&] {
            try {
                watched.result = render(scene, integrator, job);
            } catch (...) {
                failure = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(mutex);
            done = true;
            finished.notify_all();
        });
        std::unique_lock<std::mutex> lock(mutex);
        while (!finished.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; })) {
            lock.unlock();
            {
                nb::gil_scoped_acquire acquire;
                if (PyErr_CheckSignals() != 0) {
                    cancel = true;
                    if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) {  // Ctrl-C: keep the image, as the CLI does
                        PyErr_Clear();
                        watched.interrupted = true;
                    } else {
                        raised.emplace();
                    }
                } else if (callback && !cancel) {
                    try {
                        // False (not None, what a callback that returns nothing gives): stop as Ctrl-C
                        // does, with the image of the passes completed. The one way to stop a render
                        // running on another Python thread and keep its image, since Ctrl-C reaches the
                        // main thread only.
                        if (progress(fraction.load()).is(nb::handle(Py_False))) {
                            cancel = true;
                            watched.cancelled = true;
                        }
                    } catch (nb::python_error &e) {
                        cancel = true;
                        raised.emplace(e);
                    }
                }
            }
            lock.lock();
        }
        lock.unlock();
        worker.join();
    }
    if (raised) throw *raised;
    if (failure) std::rethrow_exception(failure);
    if (callback) progress(1.0);
    return watched;
}

std::pair<nb::ndarray<nb::numpy, float>, std::string> render_scene(const Scene &scene, const std::string &integrator_name,
                                                                   const std::map<std::string, std::string> &overrides,
                                                                   int spp, double time_s, uint64_t seed, int threads,
                                                                   const std::string &sampler, nb::object progress) {
    std::unique_ptr<Integrator> integrator = scene_integrator(scene, integrator_name, overrides);
    const RenderJob job = make_job(scene, spp, time_s, seed, threads, sampler);
    Watched w = render_watched(scene, *integrator, job, progress);
    nlohmann::json stats = render_statistics(scene, *integrator, w.result, job);
    if (w.interrupted) stats["interrupted"] = true;
    return {to_numpy(std::move(w.result.image)), stats.dump()};
}

// One range of sample indices, [first, last), continued from what earlier ranges learned (state, empty:
// nothing): its sums, what it learned, and its statistics. The unit of distributed rendering.
nb::dict render_range(const Scene &scene, const std::string &integrator_name,
                      const std::map<std::string, std::string> &overrides, int first, int last, uint64_t seed,
                      int threads, const std::string &sampler, const nb::bytes &state, nb::object progress) {
    if (first < 0 || last <= first) throw std::invalid_argument("render_range: the range must be 0 <= first < last");
    std::unique_ptr<Integrator> integrator = scene_integrator(scene, integrator_name, overrides);
    if (dynamic_cast<const PassIntegrator *>(integrator.get()))
        throw std::invalid_argument("integrator '" + integrator->describe().value("name", std::string()) +
                                    "' renders whole passes itself (its Markov chains), which cannot be split by sample index");
    RenderJob job = make_job(scene, last, 0, seed, threads, sampler);
    job.first_sample = first;
    const std::string state_in(state.c_str(), state.size());
    if (!state_in.empty()) job.integrator_state = &state_in;
    job.keep_state = true;
    Watched w = render_watched(scene, *integrator, job, progress);
    if (w.interrupted) {  // not a partial range: nothing of it counts
        PyErr_SetNone(PyExc_KeyboardInterrupt);
        throw nb::python_error();
    }
    if (w.cancelled && w.result.stopped_by == "cancel")
        throw std::runtime_error("render_range: stopped by the progress callback before the range was complete");
    RenderCheckpoint &c = w.result.state;
    nb::dict out;
    out["first"] = first;
    out["last"] = last;
    out["image_sums"] = vector_to_numpy(std::move(c.image_sums));
    out["splat_sums"] = vector_to_numpy(std::move(c.splat_sums));
    out["light_paths"] = c.light_paths;
    out["integrator_state"] = nb::bytes(c.integrator_state.data(), c.integrator_state.size());
    out["stats"] = render_statistics(scene, *integrator, w.result, job).dump();
    return out;
}

}  // namespace

void bind_render(nb::module_ &m) {
    m.def("_stop_renders", &stop_renders, nb::arg("timeout"),
          "Cancels every render under way and waits up to timeout seconds for them to return (True: all did). "
          "neepp's atexit handler.");
    using Doubles = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
    using Int64s = nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
    m.def("render_range", &render_range, nb::arg("scene"), nb::arg("integrator"), nb::arg("options"), nb::arg("first"),
          nb::arg("last"), nb::arg("seed"), nb::arg("threads"), nb::arg("sampler"), nb::arg("state"),
          nb::arg("progress").none(),
          "Renders samples first..last-1 of every pixel, continued from state (bytes; empty: nothing learned yet). "
          "Returns a dict: image_sums (float64: r, g, b, weight per pixel), splat_sums (int64 fixed point), "
          "light_paths, integrator_state (bytes: what it learned) and stats (JSON). Sums of several ranges add up; "
          "image_from_sums makes their image. Used by neepp.distributed.");
    m.def("image_from_sums", [](const Scene &scene, const Doubles &image_sums, const Int64s &splat_sums, double light_paths) {
              return to_numpy(image_from_sums(scene, numpy_to_vector<double>(image_sums), numpy_to_vector<int64_t>(splat_sums),
                                              light_paths));
          },
          nb::arg("scene"), nb::arg("image_sums"), nb::arg("splat_sums"), nb::arg("light_paths"),
          "The (H, W, 3) image that render_range's sums (added up over ranges) make.");
    m.def("merge_states", [](const std::string &integrator, const std::map<std::string, std::string> &options,
                             const nb::bytes &base, const std::vector<nb::bytes> &learned) {
              const std::unique_ptr<Integrator> i = make_integrator(integrator, Options(options));
              std::vector<std::string> states;
              for (const nb::bytes &b : learned) states.emplace_back(b.c_str(), b.size());
              const std::string merged = i->merge_states(std::string(base.c_str(), base.size()), states);
              return nb::bytes(merged.data(), merged.size());
          },
          nb::arg("integrator"), nb::arg("options"), nb::arg("base"), nb::arg("learned"),
          "What several ranges continued from base learned, as one state (NEE++: the first's, with the visibility "
          "counts the others added).");
    m.def("render", &render_scene, nb::arg("scene"), nb::arg("integrator"), nb::arg("options"), nb::arg("spp"),
          nb::arg("time"), nb::arg("seed"), nb::arg("threads"), nb::arg("sampler"), nb::arg("progress").none(),
          "Renders the scene; returns the (H, W, 3) float32 image and the statistics as JSON text. "
          "Use neepp.render, which wraps this.");
}

}  // namespace neepp::python
