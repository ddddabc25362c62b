// Spectra as Mitsuba 3's <spectrum> gives them (a constant, wavelength:value pairs or a .spd file),
// turned into linear sRGB as its RGB variants turn them: integrated against the CIE 1931 matching
// functions and converted from XYZ. A reflectance is seen under D65 (so a flat 1 is white) and kept
// within [0, 1]; an emitter's spectrum is taken as it is (a flat one is the purple-ish equal-energy
// white, as in Mitsuba's spectral variants) and only kept non-negative.
#pragma once
#include <string>
#include <vector>
#include "neepp/math/vec.h"

namespace neepp {

struct Spectrum {
    // Increasing wavelengths in nm with their values; a constant has no wavelengths and one value.
    std::vector<double> wavelengths, values;
    bool constant() const { return wavelengths.empty(); }
};

enum class SpectrumUse {
    Reflectance,  // bounded to [0, 1], under D65 (Mitsuba's textures)
    Unbounded,    // non-negative, under D65 (an index of refraction, a roughness)
    Emission,     // non-negative, as radiance (Mitsuba's emitters)
};

// Parses Mitsuba's value attribute: "0.5" (a constant) or "400:0.1, 500:0.5, ..." pairs. Throws
// std::invalid_argument naming what is wrong.
Spectrum parse_spectrum(const std::string &text);
// Reads a .spd file: lines "wavelength value", '#' comments. Throws std::runtime_error.
Spectrum read_spectrum_file(const std::string &path);
Color spectrum_to_rgb(const Spectrum &s, SpectrumUse use);
Color xyz_to_linear_srgb(double x, double y, double z);

}  // namespace neepp
