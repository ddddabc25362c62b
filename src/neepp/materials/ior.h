// Named indices of refraction, as Mitsuba 3 resolves them from scene files.
#pragma once
#include <optional>
#include <string_view>
#include "neepp/math/vec.h"

namespace neepp {

// Mitsuba's dielectric IOR table (render/ior.h: "bk7", "water", "air", "vacuum", "polypropylene", ...),
// matched case-insensitively. nullopt for an unknown name.
std::optional<float> lookup_dielectric_ior(std::string_view name);

struct ConductorIOR {
    Color eta, k;
};

// Mitsuba's conductor presets ("Cu", "Au", "Ag", "Al", "Cr", ... and "none"), case-sensitive like
// Mitsuba's file lookup. The RGB values are what Mitsuba 3's RGB variants load: the measured spectra
// (data/ior/<name>.{eta,k}.spd) integrated against the CIE 1931 matching functions without an
// illuminant and converted to linear sRGB, negative components clamped to 0. "none" is a perfect mirror
// (eta = 0, k = 1 gives reflectance 1 at all angles). nullopt for an unknown name.
std::optional<ConductorIOR> lookup_conductor_ior(std::string_view name);

}  // namespace neepp
