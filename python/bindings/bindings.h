// The parts of the neepp._neepp extension module, and what they share.
#pragma once
#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include "neepp/base/integrator.h"
#include "neepp/io/image.h"
#include "neepp/scene/scene.h"

namespace neepp::python {

namespace nb = nanobind;

void bind_errors(nb::module_ &m);
void bind_images(nb::module_ &m);
void bind_scene(nb::module_ &m);
void bind_render(nb::module_ &m);
void bind_visibility(nb::module_ &m);
void bind_live_render(nb::module_ &m);
void bind_checkpoint(nb::module_ &m);

// The integrator `name` (empty: the scene's) with the scene's options, overridden by `overrides`: as
// the CLI makes it.
std::unique_ptr<Integrator> scene_integrator(const Scene &scene, const std::string &name,
                                             const std::map<std::string, std::string> &overrides);

// The renders under way in this process, by their cancel flags, so that the interpreter's exit can stop
// them first (stop_renders, neepp's atexit handler). A render thread left running into the interpreter's
// finalization is ended there (pthread_exit) when it next takes the GIL, which aborts the process
// (its unwinding meets nanobind's noexcept GIL guards), and the render's own threads would run on while
// the process tears down what they use. Held, with the GIL, from before a render starts until its
// binding returns to Python.
class RenderInFlight {
public:
    explicit RenderInFlight(std::atomic<bool> &cancel);
    ~RenderInFlight();
    RenderInFlight(const RenderInFlight &) = delete;
    RenderInFlight &operator=(const RenderInFlight &) = delete;

private:
    std::atomic<bool> &cancel_;
};

// An (H, W, C) float32 numpy array that takes over the image's pixels (no copy).
nb::ndarray<nb::numpy, float> to_numpy(Image &&image);
// An image from an (H, W), (H, W, 1), (H, W, 3) or (H, W, 4) float32 array (copied).
Image from_numpy(const nb::ndarray<const float, nb::c_contig, nb::device::cpu> &array);

// A 1-D numpy array that takes over the vector (no copy), and a vector copied from one (a render's sums).
template <typename T> nb::ndarray<nb::numpy, T> vector_to_numpy(std::vector<T> &&v) {
    auto *owned = new std::vector<T>(std::move(v));
    nb::capsule owner(owned, [](void *p) noexcept { delete static_cast<std::vector<T> *>(p); });
    return nb::ndarray<nb::numpy, T>(owned->data(), {owned->size()}, owner);
}
template <typename T> using Array1D = nb::ndarray<const T, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
template <typename T> std::vector<T> numpy_to_vector(const Array1D<T> &a) {
    return std::vector<T>(a.data(), a.data() + a.shape(0));
}

}  // namespace neepp::python
