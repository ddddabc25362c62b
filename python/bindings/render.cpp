// neepp.render: the render loop the CLI runs, on a scene loaded in Python. The render runs on a thread of
// its own with the GIL released, while the calling thread watches it: it forwards the fraction done to the
// progress callback and turns Ctrl-C (a pending KeyboardInterrupt) into the render loop's cancel, which
// ends the render with the image of the passes completed, as the CLI does on SIGINT.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>
#include <nanobind/stl/map.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include "bindings.h"
#include "neepp/integrators/integrator.h"
#include "neepp/render/render_output.h"
#include "neepp/scene/scene.h"

namespace neepp::python {

namespace {

std::pair<nb::ndarray<nb::numpy, float>, std::string> render_scene(const Scene &scene, const std::string &integrator_name,
                                                                   const std::map<std::string, std::string> &overrides,
                                                                   int spp, double time_s, uint64_t seed, int threads,
                                                                   const std::string &sampler, nb::object progress) {
    Options options(scene.settings.integrator_options);
    for (const auto &[key, value] : overrides) options.set(key, value);
    const std::string name = integrator_name.empty() ? scene.settings.integrator : integrator_name;
    std::unique_ptr<Integrator> integrator = make_integrator(name, options);

    std::atomic<bool> cancel{false};
    std::atomic<double> fraction{0};
    RenderJob job;
    job.spp = spp > 0 ? spp : (time_s > 0 ? 0 : scene.settings.spp);
    job.time_limit_s = time_s;
    job.seed = seed;
    job.threads = threads;
    job.sampler = sampler.empty() ? scene.settings.sampler : sampler;
    job.cancel = &cancel;
    const bool callback = !progress.is_none() && PyCallable_Check(progress.ptr());
    if (!callback && nb::bool_(progress)) job.progress = ProgressStyle::bar;
    job.on_progress = [&](double f, double) { fraction = f; };

    RenderResult result;
    std::exception_ptr failure;
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    bool interrupted = false;
    std::optional<nb::python_error> raised;  // by the callback or a signal handler: ends the render, raised after it
    {
        nb::gil_scoped_release release;
        std::thread worker([&] {
            try {
                result = render(scene, *integrator, job);
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
                        interrupted = true;
                    } else {
                        raised.emplace();
                    }
                } else if (callback && !cancel) {
                    try {
                        progress(fraction.load());
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
    nlohmann::json stats = render_statistics(scene, *integrator, result, job);
    if (interrupted) stats["interrupted"] = true;
    return {to_numpy(std::move(result.image)), stats.dump()};
}

}  // namespace

void bind_render(nb::module_ &m) {
    m.def("render", &render_scene, nb::arg("scene"), nb::arg("integrator"), nb::arg("options"), nb::arg("spp"),
          nb::arg("time"), nb::arg("seed"), nb::arg("threads"), nb::arg("sampler"), nb::arg("progress").none(),
          "Renders the scene; returns the (H, W, 3) float32 image and the statistics as JSON text. "
          "Use neepp.render, which wraps this.");
}

}  // namespace neepp::python
