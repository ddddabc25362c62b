#include <stdexcept>
#include "neepp/integrators/path.h"

namespace neepp {

std::unique_ptr<Integrator> make_integrator(const std::string &name, const Options &options) {
    std::unique_ptr<Integrator> integrator;
    if (name == "path") {
        PathOptions o;
        o.max_depth = options.get_int("max_depth", o.max_depth);
        o.rr_depth = options.get_int("rr_depth", o.rr_depth);
        o.hide_emitters = options.get_bool("hide_emitters", o.hide_emitters);
        o.nee = options.get_bool("nee", o.nee);
        o.light_sampler = options.get_string("light_sampler", o.light_sampler);
        if (o.max_depth < -1 || o.max_depth == 0) throw std::invalid_argument("max_depth must be -1 or >= 1");
        if (o.rr_depth < 1) throw std::invalid_argument("rr_depth must be >= 1");
        std::string policy = options.get_string("shadow_rays", "nee");
        if (policy != "nee") throw std::invalid_argument("unknown shadow-ray policy '" + policy + "' (supported: nee)");
        integrator = std::make_unique<PathIntegrator>(o, std::make_unique<TraceAllShadowRays>());
    } else {
        throw std::invalid_argument("unknown integrator '" + name + "' (supported: path)");
    }
    if (auto unused = options.unused(); !unused.empty()) {
        std::string list;
        for (auto &k : unused) list += (list.empty() ? "" : ", ") + k;
        throw std::invalid_argument("integrator '" + name + "' has no option(s): " + list);
    }
    return integrator;
}

}  // namespace neepp
