// Image reading on arbitrary bytes, through the project's code as textures and environment maps use it:
// the format is sniffed from the content (OpenEXR, JPEG through libjpeg, PNG/HDR/TGA/BMP/PNM through
// stb_image), then both the float path and the 8-bit path a bitmap texture takes are run.
#include <exception>
#include <fmt/format.h>
#include <stb/stb_image_write.h>
#include <fstream>
#include <vector>
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
        // The stb_image formats, small, each as its checks read it: BMP (24- and 32-bit), TGA (plain and
        // run-length coded), Radiance HDR (flat under 8 pixels wide, run-length coded from 8), 8- and 16-bit PNM.
        std::vector<unsigned char> px(12 * 4 * 4);
        for (size_t i = 0; i < px.size(); ++i) px[i] = (unsigned char)(i < 16 ? 200 : i * 37 % 251);
        std::vector<float> hdr(px.begin(), px.end());
        const auto at = [&](const char *name) { return (dir / name).string(); };
        stbi_write_bmp(at("rgb.bmp").c_str(), 12, 4, 3, px.data());
        stbi_write_bmp(at("rgba.bmp").c_str(), 12, 4, 4, px.data());
        stbi_write_tga_with_rle = 0;
        stbi_write_tga(at("rgb.tga").c_str(), 12, 4, 3, px.data());
        stbi_write_tga_with_rle = 1;
        stbi_write_tga(at("rle.tga").c_str(), 12, 4, 4, px.data());
        stbi_write_hdr(at("flat.hdr").c_str(), 5, 4, 3, hdr.data());
        stbi_write_hdr(at("rle.hdr").c_str(), 12, 4, 3, hdr.data());
        std::ofstream(at("rgb.ppm"), std::ios::binary) << "P6\n12 4\n255\n"
                                                       << std::string(px.begin(), px.begin() + 144);
        std::ofstream(at("gray16.pgm"), std::ios::binary) << "P5 12 4 65535\n"
                                                          << std::string(px.begin(), px.begin() + 96);
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
