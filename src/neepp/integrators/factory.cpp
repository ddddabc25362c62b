#include "neepp/integrators/factory.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include "neepp/integrators/bdpt.h"
#include "neepp/integrators/neepp_auto.h"
#include "neepp/integrators/option_table.h"
#include "neepp/integrators/path.h"
#include "neepp/integrators/pssmlt.h"
#include "neepp/light_selection/factory.h"
#include "neepp/visibility/neepp_shadow_rays.h"

namespace neepp {

// The shadow-ray component every integrator traces its shadow rays and connections through, from the
// options they share: nee traces every shadow ray; the neepp* policies (NEE++) play Russian roulette
// driven by a visibility map. Their options are only accepted with them (or when the integrator needs a
// map anyway), so a typo'd or meaningless option is still reported as unused.
std::unique_ptr<ShadowRayTester> make_shadow_ray_tester(const Options &options, bool needs_map, int voxels,
                                                        bool defer_seeding) {
    std::string policy = options.get_string("shadow_rays", "nee");
    if (policy == "nee" && !needs_map) return std::make_unique<TraceAllShadowRays>();
    NeeppOptions n;
    n.policy = parse_shadow_ray_policy(policy);
    n.voxels = voxels;
    n.samples_per_pair = options.get_int("samples_per_pair", n.samples_per_pair);
    n.grid_bounds = options.get_string("grid_bounds", n.grid_bounds);
    n.q_min = options.get_float("q_min", n.q_min);
    n.map_file = options.get_string("visibility_map", n.map_file);
    n.learn = options.get_bool("learn", n.learn);
    n.learn_until = options.get_int("learn_until", n.learn_until);
    if (n.learn_until < 1) throw std::invalid_argument("learn_until must be at least 1");
    n.min_occluded = options.get_float("min_occluded", n.min_occluded);
    n.defer_seeding = defer_seeding;
    if (!(n.min_occluded >= 0.f && n.min_occluded <= 1.f)) throw std::invalid_argument("min_occluded must be in [0, 1]");
    if (n.policy == ShadowRayPolicy::NeeppAdaptive) {
        n.adaptive_target = options.get_string("adaptive_target", n.adaptive_target);
        n.shadow_ray_cost = options.get_float("shadow_ray_cost", n.shadow_ray_cost);
        if (n.adaptive_target != "efficiency" && n.adaptive_target != "rays")
            throw std::invalid_argument("adaptive_target must be 'efficiency' or 'rays'");
        if (!(n.shadow_ray_cost > 0 && n.shadow_ray_cost <= 1))
            throw std::invalid_argument("shadow_ray_cost must be in (0, 1]");
    }
    return std::make_unique<NeeppShadowRays>(n);
}

namespace {

std::string read_area_light_sampling(const Options &options) {
    const std::string s = options.get_string("area_light_sampling", "area");
    const auto &names = WithinLightSampling::area_light_names();
    if (std::find(names.begin(), names.end(), s) == names.end())
        throw std::invalid_argument("area_light_sampling must be 'area' or 'solid-angle', not '" + s + "'");
    return s;
}

std::unique_ptr<Integrator> make_bdpt(bool light_tracer, const Options &options) {
    BDPTOptions o;
    o.light_tracer = light_tracer;
    o.max_depth = options.get_int("max_depth", o.max_depth);
    o.rr_depth = options.get_int("rr_depth", o.rr_depth);
    o.hide_emitters = options.get_bool("hide_emitters", o.hide_emitters);
    if (o.max_depth < -1 || o.max_depth == 0) throw std::invalid_argument("max_depth must be -1 or >= 1");
    if (o.rr_depth < 1) throw std::invalid_argument("rr_depth must be >= 1");
    if (!light_tracer) {
        if (options.has("strategy")) {
            const std::string st = options.get_string("strategy", "");
            char comma = 0;
            std::istringstream in(st);
            if (!(in >> o.strategy_s >> comma >> o.strategy_t) || comma != ',' || !in.eof() || o.strategy_s < 0 ||
                o.strategy_t < 1)
                throw std::invalid_argument("option 'strategy': '" + st + "' is not S,T with S >= 0 and T >= 1");
            const std::string w = options.get_string("strategy_weight", "mis");
            if (w != "mis" && w != "none") throw std::invalid_argument("strategy_weight must be 'mis' or 'none'");
            o.strategy_mis = w == "mis";
        }
        const std::string mis = options.get_string("mis", "power");
        if (mis != "power" && mis != "balance") throw std::invalid_argument("mis must be 'power' or 'balance'");
        o.power_heuristic = mis == "power";
        const std::string lp = options.get_string("light_paths", "independent");
        if (lp != "independent" && lp != "neepp")
            throw std::invalid_argument("light_paths must be 'independent' or 'neepp'");
        o.neepp_selection = lp == "neepp";
        o.area_light_sampling = read_area_light_sampling(options);
        if (o.neepp_selection) {
            o.candidates = options.get_int("candidates", o.candidates);
            o.pool = options.get_int("pool", o.pool);
            if (o.candidates < 1 || o.candidates > 64) throw std::invalid_argument("candidates must be in [1, 64]");
            if (o.pool < 1) throw std::invalid_argument("pool must be at least 1");
        }
    }
    const bool needs_map = o.neepp_selection;
    if (needs_map || options.get_string("shadow_rays", "nee") != "nee") o.voxels = options.get_int("voxels", o.voxels);
    auto shadow = make_shadow_ray_tester(options, needs_map, o.voxels, !needs_map);
    return std::make_unique<BDPTIntegrator>(o, std::move(shadow));
}

std::unique_ptr<PathIntegrator> make_path(const Options &options, bool volumetric) {
    PathOptions o;
    o.volumetric = volumetric;
    o.max_depth = options.get_int("max_depth", o.max_depth);
    o.rr_depth = options.get_int("rr_depth", o.rr_depth);
    o.hide_emitters = options.get_bool("hide_emitters", o.hide_emitters);
    o.nee = options.get_bool("nee", o.nee);
    o.light_sampler = options.get_string("light_sampler", o.light_sampler);
    check_light_sampler_name(o.light_sampler);
    o.within_light = options.get_string("within_light", o.within_light);
    // volpath has its reference form only, and resamples nothing (yet).
    const std::string form = volumetric ? "reference" : options.get_string("form", "fast");
    if (form != "fast" && form != "reference")
        throw std::invalid_argument("form must be 'fast' or 'reference', not '" + form + "'");
    o.reference = form == "reference";
    if (!volumetric) {
        o.guiding = options.get_string("guiding", "none");
        if (o.guiding != "none" && o.guiding != "sdtree" && o.guiding != "map" && o.guiding != "sdtree+map")
            throw std::invalid_argument("guiding must be 'none', 'sdtree', 'map' or 'sdtree+map', not '" + o.guiding + "'");
        o.guiding_tree_share = options.get_float("guiding_tree_share", o.guiding_tree_share);
        if (!(o.guiding_tree_share >= 0.f && o.guiding_tree_share <= 1.f))
            throw std::invalid_argument("guiding_tree_share must be in [0, 1]");
        o.guiding_bsdf_fraction = options.get_float("guiding_bsdf_fraction", o.guiding_bsdf_fraction);
        if (!(o.guiding_bsdf_fraction > 0.f && o.guiding_bsdf_fraction <= 1.f))
            throw std::invalid_argument("guiding_bsdf_fraction must be in (0, 1]: the BSDF's share keeps guiding unbiased");
        o.guiding_spatial_threshold = double(options.get_float("guiding_spatial_threshold", float(o.guiding_spatial_threshold)));
        o.guiding_learn_direct = options.get_bool("guiding_learn_direct", o.guiding_learn_direct);
        if (!(o.guiding_spatial_threshold >= 0))
            throw std::invalid_argument("guiding_spatial_threshold must be >= 0 (0: scaled to the image)");
    } else if (options.has("guiding")) {
        throw std::invalid_argument("volpath: guiding is refused: it is the path integrator's (path -I guiding=sdtree)");
    }
    const auto &within = WithinLightSampling::names();
    if (std::find(within.begin(), within.end(), o.within_light) == within.end())
        throw std::invalid_argument("within_light must be 'own' or 'visibility', not '" + o.within_light + "'");
    o.area_light_sampling = read_area_light_sampling(options);
    if (o.max_depth < -1 || o.max_depth == 0) throw std::invalid_argument("max_depth must be -1 or >= 1");
    if (o.rr_depth < 1) throw std::invalid_argument("rr_depth must be >= 1");
    if (!volumetric) o.ris = options.get_int("ris", o.ris);
    if (o.ris < 1 || o.ris > PathOptions::kMaxCandidates)
        throw std::invalid_argument("ris must be in [1, " + std::to_string(PathOptions::kMaxCandidates) + "]");
    if (o.ris > 1) {
        o.ris_floor = options.get_float("ris_floor", o.ris_floor);
        o.ris_depth = options.get_int("ris_depth", o.ris_depth);
        if (o.ris_depth < -1 || o.ris_depth == 0) throw std::invalid_argument("ris_depth must be -1 (all vertices) or >= 1");
        if (!(o.ris_floor > 0.f && o.ris_floor <= 1.f))
            throw std::invalid_argument("ris_floor must be in (0, 1]: a target of 0 where light arrives would bias the image");
    }
    // Resampling reads the map whatever the light sampler: its target holds Ṽ.
    const bool needs_map = light_sampler_needs_visibility_map(o.light_sampler) || o.within_light != "own" || o.ris > 1 ||
                           o.guides_by_map();
    if (o.light_sampler.rfind("spatial", 0) == 0 || o.light_sampler.rfind("bayes", 0) == 0 || needs_map || options.get_string("shadow_rays", "nee") != "nee")
        o.voxels = options.get_int("voxels", o.voxels);
    // A light sampler reading the map needs it from the first pass: no deferred seeding then.
    std::unique_ptr<ShadowRayTester> shadow = make_shadow_ray_tester(options, needs_map, o.voxels, !needs_map);
    return std::make_unique<PathIntegrator>(o, std::move(shadow));
}

// neepp=auto: the candidates' options are the user's with each candidate's overrides; every candidate is
// built once here, so that a bad option is reported before the scene loads, and an option counts as
// unused only if no candidate reads it.
std::unique_ptr<Integrator> make_auto_path(const Options &options, bool volumetric) {
    if (options.has("guiding") && options.get_string("guiding", "none") != "none")
        throw std::invalid_argument("neepp=auto with guiding is refused: guiding is a candidate of its own "
                                    "(-I auto_guiding=true), or use neepp=off");
    const bool guiding = options.get_bool("auto_guiding", false);
    if (guiding && volumetric)
        throw std::invalid_argument("auto_guiding: volpath has no path guiding (it is the path integrator's)");
    for (const char *key : {"light_sampler", "within_light", "shadow_rays"})
        if (options.has(key))
            throw std::invalid_argument(std::string("neepp=auto chooses light_sampler, within_light and shadow_rays itself: "
                                                    "drop -I ") + key + ", or use neepp=off");
    std::map<std::string, std::string> values = options.values();
    values.erase("neepp");
    values.erase("auto_guiding");
    auto candidate_options = [values](const AutoCandidate &c) {
        Options o(values);
        for (const auto &[k, v] : c.overrides) o.set(k, v);
        return o;
    };
    std::set<std::string> read;
    for (const AutoCandidate &c : auto_candidates(guiding)) {
        Options o = candidate_options(c);
        make_path(o, volumetric);
        const std::vector<std::string> unused = o.unused();
        for (const auto &[k, v] : values)
            if (std::find(unused.begin(), unused.end(), k) == unused.end()) read.insert(k);
    }
    for (const std::string &k : read) options.get_string(k, "");  // read by some candidate: not unused
    return std::make_unique<AutoIntegrator>(auto_candidates(guiding),
                                            [candidate_options, volumetric](const AutoCandidate &c) {
                                                return make_path(candidate_options(c), volumetric);
                                            });
}


std::mutex registry_mutex;
std::map<std::string, IntegratorPlugin> &registry() {
    static std::map<std::string, IntegratorPlugin> r;
    return r;
}

const IntegratorPlugin *find_registered(const std::string &name) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    auto it = registry().find(name);
    return it == registry().end() ? nullptr : &it->second;
}

}  // namespace

void register_integrator(const std::string &name, IntegratorPlugin make) {
    for (const char *own : {"path", "volpath", "bdpt", "light", "pssmlt"})
        if (name == own) throw std::invalid_argument("register_integrator: '" + name + "' is one of neepp's own");
    if (name.empty()) throw std::invalid_argument("register_integrator: an integrator needs a name");
    std::lock_guard<std::mutex> lock(registry_mutex);
    registry()[name] = std::move(make);
}

bool integrator_registered(const std::string &name) { return find_registered(name) != nullptr; }

std::unique_ptr<Integrator> make_integrator(const std::string &name, const Options &options) {
    std::unique_ptr<Integrator> integrator;
    if (name == "path" || name == "volpath") {
        const bool volumetric = name == "volpath";
        const std::string mode = options.get_string("neepp", "off");
        if (mode != "off" && mode != "auto") throw std::invalid_argument("neepp must be 'off' or 'auto', not '" + mode + "'");
        integrator = mode == "auto" ? make_auto_path(options, volumetric) : make_path(options, volumetric);
    } else if (name == "bdpt" || name == "light") {
        integrator = make_bdpt(name == "light", options);
    } else if (name == "pssmlt") {
        PSSMLTOptions o;
        o.bidirectional = options.get_bool("bidirectional", o.bidirectional);
        o.bootstrap = options.get_int("bootstrap", o.bootstrap);
        o.chains = options.get_int("chains", o.chains);
        o.large_step = options.get_float("large_step", o.large_step);
        o.sigma = options.get_float("sigma", o.sigma);
        if (o.bootstrap < 1) throw std::invalid_argument("bootstrap must be at least 1");
        if (o.chains < 1) throw std::invalid_argument("chains must be at least 1");
        if (!(o.large_step >= 0.f && o.large_step <= 1.f)) throw std::invalid_argument("large_step must be in [0, 1]");
        if (!(o.sigma > 0.f && o.sigma <= 1.f)) throw std::invalid_argument("sigma must be in (0, 1]");
        // The chain's target must be a function of its numbers, and never negative.
        if (options.get_string("shadow_rays", "nee") == "neepp-cv")
            throw std::invalid_argument("pssmlt: shadow_rays=neepp-cv is refused: its estimate can be negative, and "
                                        "a Markov chain needs a target that never is (use neepp or neepp-adaptive)");
        // Guiding changes what a sample is worth from one pass to the next, as the pool below would.
        if (options.has("guiding") && options.get_string("guiding", "none") != "none")
            throw std::invalid_argument("pssmlt: guiding is refused: the guide learns anew every pass, so a sample would "
                                        "not be a function of the chain's numbers");
        if (o.bidirectional && options.get_string("light_paths", "independent") == "neepp")
            throw std::invalid_argument("pssmlt: light_paths=neepp is refused: its pool of light subpaths is traced anew "
                                        "every pass, so a sample would not be a function of the chain's numbers");
        const std::string over = o.bidirectional ? "bdpt" : "path";
        std::unique_ptr<Integrator> inner, volumetric;
        try {
            inner = make_integrator(over, options);
            // Over the path tracer, scenes with media run the chains over its volumetric form.
            if (!o.bidirectional) volumetric = make_integrator("volpath", options);
        } catch (const std::invalid_argument &e) {
            throw std::invalid_argument("pssmlt (over " + over + "): " + e.what());
        }
        integrator = std::make_unique<PSSMLTIntegrator>(o, std::move(inner), std::move(volumetric));
    } else if (const IntegratorPlugin *make = find_registered(name)) {
        integrator = (*make)(options);
        if (!integrator) throw std::invalid_argument("the registered integrator '" + name + "' made nothing");
    } else {
        throw std::invalid_argument("unknown integrator '" + name + "' (supported: path, volpath, bdpt, light, pssmlt)");
    }
    if (auto unused = options.unused(); !unused.empty()) {
        // An option of the integrator that another one's setting turns on (its table's `needs`) says which.
        std::map<std::string, std::string> needs;
        for (const IntegratorDoc &d : integrator_docs())
            if (d.name == name)
                for (const OptionDoc &o : d.options)
                    if (!o.needs.empty()) needs[o.name] = o.needs;
        std::string list;
        for (auto &k : unused) {
            list += (list.empty() ? "" : ", ") + k;
            if (auto it = needs.find(k); it != needs.end()) list += " (read only with -I " + it->second + ")";
        }
        throw std::invalid_argument("integrator '" + name + "' has no option(s): " + list);
    }
    return integrator;
}

}  // namespace neepp
