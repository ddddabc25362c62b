#include "neepp/loader/supported_plugins.h"

#include <stdexcept>
#include "neepp/loader/plugins.h"

namespace neepp {

const std::vector<std::pair<std::string, std::vector<std::string>>> &supported_plugins() {
    static const std::vector<std::pair<std::string, std::vector<std::string>>> plugins = {
        {"shape", {"obj", "ply", "rectangle", "cube", "sphere", "disk", "cylinder", "serialized", "sdfgrid",
                   "linearcurve", "bsplinecurve", "shapegroup", "instance"}},
        {"bsdf", {"diffuse", "twosided", "mask", "bumpmap", "conductor", "roughconductor", "plastic", "roughplastic",
                  "dielectric", "roughdielectric", "thindielectric", "principled", "principledthin", "null", "normalmap",
                  "blendbsdf", "hair", "pplastic", "polarizer"}},
        {"texture", {"bitmap", "checkerboard", "rawconstant", "mesh_attribute"}},
        {"emitter", {"area", "envmap", "constant", "point", "spot", "directional", "projector"}},
        {"sensor", {"perspective", "orthographic"}},
        {"medium", {"homogeneous", "heterogeneous"}},
        {"volume", {"constvolume", "gridvolume"}},
        {"phase", {"isotropic", "hg", "rayleigh", "blendphase", "tabphase", "sggx"}},
        {"film", {"hdrfilm"}},
        {"rfilter", {"box", "tent", "gaussian"}},
        // Mitsuba's stratified and low-discrepancy samplers render with neepp's sobol: the same expected image.
        {"sampler", {"independent", "sobol", "stratified", "multijitter", "ldsampler", "orthogonal"}},
        // Mitsuba 3's integrators, each rendered by neepp's own that gives the same image (loader/integrators.cpp).
        {"integrator", {"path", "bdpt", "light", "pssmlt", "prb", "prb_basic", "prb_projective", "volpath", "volpathmis",
                        "direct", "direct_projective", "ptracer", "moment", "aov"}},
    };
    return plugins;
}

const std::vector<std::string> &supported_names(const std::string &kind) {
    for (const auto &[k, names] : supported_plugins())
        if (k == kind) return names;
    throw std::logic_error("supported_names: no plugin kind '" + kind + "'");
}

std::string supported_list(const std::string &kind) {
    std::string list;
    for (const std::string &n : supported_names(kind)) list += (list.empty() ? "" : ", ") + n;
    for (const std::string &n : registered_plugins(kind)) list += ", " + n + " (registered)";
    return list;
}

}  // namespace neepp
