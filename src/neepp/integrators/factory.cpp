#include <stdexcept>
#include "neepp/integrators/path.h"
#include "neepp/light_selection/factory.h"
#include "neepp/visibility/neepp_shadow_rays.h"

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
        check_light_sampler_name(o.light_sampler);
        if (o.max_depth < -1 || o.max_depth == 0) throw std::invalid_argument("max_depth must be -1 or >= 1");
        if (o.rr_depth < 1) throw std::invalid_argument("rr_depth must be >= 1");
        // Shadow-ray policy: nee traces every shadow ray; the neepp* policies (NEE++) play Russian roulette
        // driven by a visibility map. Their options are only accepted with them (or with a light sampler
        // that reads the map), so a typo'd or meaningless option is still reported as unused.
        std::string policy = options.get_string("shadow_rays", "nee");
        const bool needs_map = light_sampler_needs_visibility_map(o.light_sampler);
        if (o.light_sampler.rfind("spatial", 0) == 0 || needs_map || policy != "nee") o.voxels = options.get_int("voxels", o.voxels);
        std::unique_ptr<ShadowRayTester> shadow;
        if (policy == "nee" && !needs_map) {
            shadow = std::make_unique<TraceAllShadowRays>();
        } else {
            NeeppOptions n;
            n.policy = parse_shadow_ray_policy(policy);
            n.voxels = o.voxels;
            n.samples_per_pair = options.get_int("samples_per_pair", n.samples_per_pair);
            n.q_min = options.get_float("q_min", n.q_min);
            n.map_file = options.get_string("visibility_map", n.map_file);
            n.learn = options.get_bool("learn", n.learn);
            n.learn_until = options.get_int("learn_until", n.learn_until);
            if (n.learn_until < 1) throw std::invalid_argument("learn_until must be at least 1");
            n.min_occluded = options.get_float("min_occluded", n.min_occluded);
            n.defer_seeding = !needs_map;  // a light sampler reading the map needs it from the first pass
            if (!(n.min_occluded >= 0.f && n.min_occluded <= 1.f)) throw std::invalid_argument("min_occluded must be in [0, 1]");
            if (n.policy == ShadowRayPolicy::NeeppAdaptive) {
                n.adaptive_target = options.get_string("adaptive_target", n.adaptive_target);
                n.shadow_ray_cost = options.get_float("shadow_ray_cost", n.shadow_ray_cost);
                if (n.adaptive_target != "efficiency" && n.adaptive_target != "rays")
                    throw std::invalid_argument("adaptive_target must be 'efficiency' or 'rays'");
                if (!(n.shadow_ray_cost > 0 && n.shadow_ray_cost <= 1))
                    throw std::invalid_argument("shadow_ray_cost must be in (0, 1]");
            }
            shadow = std::make_unique<NeeppShadowRays>(n);
        }
        integrator = std::make_unique<PathIntegrator>(o, std::move(shadow));
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
