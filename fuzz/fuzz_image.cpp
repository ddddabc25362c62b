// Image reading on arbitrary bytes, through the project's code as textures and environment maps use it:
// the format is sniffed from the content (OpenEXR, JPEG through libjpeg, PNG/HDR/TGA/BMP through
// stb_image), then both the float path and the 8-bit path a bitmap texture takes are run.
#include <exception>
#include <fmt/format.h>
#include "fuzz_input.h"
#include "neepp/io/image.h"

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        for (int c : {1, 2, 3, 4}) {  // Y, YA, RGB, RGBA
            neepp::Image img(5, 3, c);
            for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(i % 7) / 6.f;
            neepp::write_exr((dir / fmt::format("float{}.exr", c)).string(), img);
            neepp::write_exr((dir / fmt::format("half{}.exr", c)).string(), img, true);
            neepp::write_png_srgb((dir / fmt::format("image{}.png", c)).string(), img);
        }
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string path = neepp::fuzz::write_input(data, size, "image");
    try {
        neepp::read_image(path);
    } catch (const std::exception &) {
    }
    try {
        neepp::read_image_bytes(path);
    } catch (const std::exception &) {
    }
    return 0;
}
