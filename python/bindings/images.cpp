// Images between numpy and neepp: EXR (and PNG/JPEG/HDR) reading, EXR and sRGB PNG writing.
#include <stdexcept>
#include <nanobind/stl/string.h>
#include <nanobind/stl/filesystem.h>
#include "bindings.h"

namespace neepp::python {

nb::ndarray<nb::numpy, float> to_numpy(Image &&image) {
    auto *pixels = new std::vector<float>(std::move(image.data));
    nb::capsule owner(pixels, [](void *p) noexcept { delete static_cast<std::vector<float> *>(p); });
    return nb::ndarray<nb::numpy, float>(pixels->data(), {size_t(image.height), size_t(image.width), size_t(image.channels)},
                                         owner);
}

Image from_numpy(const nb::ndarray<const float, nb::c_contig, nb::device::cpu> &array) {
    const size_t channels = array.ndim() == 3 ? array.shape(2) : 1;
    if ((array.ndim() != 2 && array.ndim() != 3) || channels < 1 || channels > 4)
        throw std::invalid_argument("an image is an (H, W) or (H, W, C) float32 array with C in 1..4");
    Image image(int(array.shape(1)), int(array.shape(0)), int(channels));
    std::copy(array.data(), array.data() + image.data.size(), image.data.begin());
    return image;
}

void bind_images(nb::module_ &m) {
    using Array = nb::ndarray<const float, nb::c_contig, nb::device::cpu>;
    m.def("read_image", [](const std::filesystem::path &path) { return to_numpy(read_image(path.string())); }, nb::arg("path"),
          "Reads an image (OpenEXR, PNG, JPEG, HDR...) as an (H, W, C) float32 array. 8-bit files come back "
          "sRGB-encoded in [0, 1], EXR linear.");
    m.def("write_exr", [](const std::filesystem::path &path, const Array &image, bool half) { write_exr(path.string(), from_numpy(image), half); },
          nb::arg("path"), nb::arg("image"), nb::arg("half") = false,
          "Writes an (H, W[, C]) float32 array to OpenEXR (float, or half), replacing the file atomically.");
    m.def("write_png", [](const std::filesystem::path &path, const Array &image, float exposure) {
              write_png_srgb(path.string(), from_numpy(image), exposure);
          },
          nb::arg("path"), nb::arg("image"), nb::arg("exposure") = 1.f,
          "Writes a linear image as an 8-bit sRGB PNG, scaled by exposure and clamped.");
}

}  // namespace neepp::python
