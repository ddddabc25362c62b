#include "neepp/math/spectrum.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace neepp {
namespace {

constexpr int kCieSamples = 95;
constexpr double kCieMin = 360, kCieMax = 830;
#include "neepp/math/cie_tables.inc"
// Mitsuba 3's normalizations, so that its conversions are reproduced to float precision: Y of the
// equal-energy spectrum 1 over its integration, and D65 to 1 near 560 nm.
constexpr double kCieYNormalization = 1.0 / 106.7502593994140625;
constexpr double kD65Normalization = 1.0 / 98.99741751876255;

// Linear interpolation in a 5 nm table (w within [360, 830]).
double table_at(const float *table, double w) {
    const double t = (w - kCieMin) * ((kCieSamples - 1) / (kCieMax - kCieMin));
    const int i0 = std::clamp(int(t), 0, kCieSamples - 2);
    const double f = t - i0;
    return (1 - f) * double(table[i0]) + f * double(table[i0 + 1]);
}

double parse_number(const std::string &text, const std::string &what) {
    const char *begin = text.c_str();
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(v))
        throw std::invalid_argument("could not parse " + what + " \"" + text + "\"");
    return v;
}

std::vector<std::string> split(const std::string &s, const std::string &delims) {
    std::vector<std::string> out;
    size_t pos = 0;
    while (pos < s.size()) {
        const size_t start = s.find_first_not_of(delims, pos);
        if (start == std::string::npos) break;
        const size_t stop = s.find_first_of(delims, start);
        out.push_back(s.substr(start, stop == std::string::npos ? std::string::npos : stop - start));
        pos = stop == std::string::npos ? s.size() : stop;
    }
    return out;
}

void check_pairs(const Spectrum &s) {
    if (s.wavelengths.size() < 2) throw std::invalid_argument("a spectrum needs at least two wavelength:value pairs");
    for (size_t i = 1; i < s.wavelengths.size(); ++i)
        if (!(s.wavelengths[i] > s.wavelengths[i - 1]))
            throw std::invalid_argument("the wavelengths of a spectrum must increase");
}

}  // namespace

Spectrum parse_spectrum(const std::string &text) {
    const std::vector<std::string> tokens = split(text, ", \t\r\n");
    Spectrum s;
    if (tokens.size() == 1 && tokens[0].find(':') == std::string::npos) {
        s.values.push_back(parse_number(tokens[0], "spectrum value"));
        return s;
    }
    for (const std::string &token : tokens) {
        const size_t colon = token.find(':');
        if (colon == std::string::npos || token.find(':', colon + 1) != std::string::npos)
            throw std::invalid_argument("\"" + token + "\" is not a wavelength:value pair");
        s.wavelengths.push_back(parse_number(token.substr(0, colon), "wavelength"));
        s.values.push_back(parse_number(token.substr(colon + 1), "spectrum value"));
    }
    check_pairs(s);
    return s;
}

Spectrum read_spectrum_file(const std::string &path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open spectrum file \"" + path + "\"");
    Spectrum s;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
        const std::vector<std::string> fields = split(line, " \t\r");
        if (fields.size() != 2)
            throw std::runtime_error("spectrum file \"" + path + "\", line " + std::to_string(number) +
                                     ": expected \"wavelength value\"");
        try {
            s.wavelengths.push_back(parse_number(fields[0], "wavelength"));
            s.values.push_back(parse_number(fields[1], "spectrum value"));
        } catch (const std::invalid_argument &e) {
            throw std::runtime_error("spectrum file \"" + path + "\", line " + std::to_string(number) + ": " + e.what());
        }
    }
    try {
        check_pairs(s);
    } catch (const std::invalid_argument &e) {
        throw std::runtime_error("spectrum file \"" + path + "\": " + e.what());
    }
    return s;
}

Color xyz_to_linear_srgb(double x, double y, double z) {
    return Color(float(3.240479 * x - 1.537150 * y - 0.498535 * z), float(-0.969256 * x + 1.875991 * y + 0.041556 * z),
                 float(0.055648 * x - 0.204043 * y + 1.057311 * z));
}

Color spectrum_to_rgb(const Spectrum &s, SpectrumUse use) {
    if (s.constant()) {
        // A constant reflectance is grey; a constant emission is equal-energy light, which sRGB (white
        // at D65) sees as slightly purple.
        const double v = s.values.at(0);
        return use == SpectrumUse::Emission ? xyz_to_linear_srgb(v, v, v) : Color(float(v));
    }
    // As Mitsuba: a Riemann sum over 1000 wavelengths spanning the CIE range, the spectrum linearly
    // interpolated between its pairs and zero outside them.
    const bool d65 = use != SpectrumUse::Emission;
    constexpr int kSteps = 1000;
    const std::vector<double> &wl = s.wavelengths, &val = s.values;
    double x = 0, y = 0, z = 0;
    for (int i = 0; i < kSteps; ++i) {
        const double w = kCieMin + (i / double(kSteps - 1)) * (kCieMax - kCieMin);
        if (w < wl.front() || w > wl.back()) continue;
        const size_t k = std::min<size_t>(size_t(std::upper_bound(wl.begin(), wl.end(), w) - wl.begin()), wl.size() - 1) - 1;
        const double w0 = wl[k], w1 = wl[k + 1];
        double v = ((w - w1) * val[k] + (w0 - w) * val[k + 1]) / (w0 - w1);
        if (d65) v *= table_at(kCieD65, w) * kD65Normalization;
        x += table_at(kCieX, w) * v;
        y += table_at(kCieY, w) * v;
        z += table_at(kCieZ, w) * v;
    }
    const double norm = (kCieMax - kCieMin) * kCieYNormalization / kSteps;
    Color rgb = xyz_to_linear_srgb(x * norm, y * norm, z * norm);
    rgb = Color(std::max(rgb.x, 0.f), std::max(rgb.y, 0.f), std::max(rgb.z, 0.f));
    if (use == SpectrumUse::Reflectance) rgb = Color(std::min(rgb.x, 1.f), std::min(rgb.y, 1.f), std::min(rgb.z, 1.f));
    return rgb;
}

}  // namespace neepp
