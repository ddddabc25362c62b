// The parts of the neepp._neepp extension module, and what they share.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include "neepp/io/image.h"

namespace neepp {
class Integrator;
class Scene;
}  // namespace neepp

namespace neepp::python {

namespace nb = nanobind;

void bind_errors(nb::module_ &m);
void bind_images(nb::module_ &m);
void bind_scene(nb::module_ &m);
void bind_render(nb::module_ &m);
void bind_visibility(nb::module_ &m);
void bind_live_render(nb::module_ &m);

// The integrator a render of the scene uses: the named one (empty: the file's), with the file's options
// and then the overrides (the CLI's -I).
std::unique_ptr<Integrator> scene_integrator(const Scene &scene, const std::string &name,
                                             const std::map<std::string, std::string> &overrides);

// An (H, W, C) float32 numpy array that takes over the image's pixels (no copy).
nb::ndarray<nb::numpy, float> to_numpy(Image &&image);
// An image from an (H, W), (H, W, 1), (H, W, 3) or (H, W, 4) float32 array (copied).
Image from_numpy(const nb::ndarray<const float, nb::c_contig, nb::device::cpu> &array);

}  // namespace neepp::python
