#include "neepp/integrators/option_table.h"

#include <fmt/format.h>
#include "neepp/integrators/bdpt.h"
#include "neepp/integrators/path.h"
#include "neepp/integrators/pssmlt.h"
#include "neepp/light_selection/factory.h"
#include "neepp/visibility/neepp_shadow_rays.h"

namespace neepp {

namespace {

std::string text(bool v) { return v ? "true" : "false"; }
std::string text(int v) { return std::to_string(v); }
std::string text(float v) { return fmt::format("{}", v); }

// The options every integrator's shadow-ray component reads (NEE++).
std::vector<OptionDoc> shadow_ray_options() {
    const NeeppOptions n;
    const std::string any = "shadow_rays=neepp*";  // any NEE++ policy
    return {
        {"shadow_rays", "nee", "how shadow rays (and BDPT's connections) are traced: nee, neepp, neepp-adaptive, neepp-cv", ""},
        {"voxels", text(n.voxels), "NEE++ grid resolution N (N^3 voxels)", any},
        {"samples_per_pair", text(n.samples_per_pair), "explicit shadow rays per voxel pair when seeding the map", any},
        {"grid_bounds", n.grid_bounds, "what the grid covers: scene (its bounds) or shading (where camera paths shade)", any},
        {"q_min", text(n.q_min), "the least probability with which a shadow ray is traced", any},
        {"visibility_map", "", "map file: loaded if it exists and belongs to this scene, else built and saved", any},
        {"learn", text(n.learn), "update the map from the shadow rays the render traces", any},
        {"learn_until", text(n.learn_until), "a pair stops learning once this many rays were traced for it", any},
        {"min_occluded", text(n.min_occluded), "rejection stays off when the first pass finds fewer shadow rays occluded", any},
        {"adaptive_target", n.adaptive_target, "efficiency (least time x variance) or rays (as many rays as neepp)",
         "shadow_rays=neepp-adaptive"},
        {"shadow_ray_cost", text(n.shadow_ray_cost), "a shadow ray's share of a sample's time, for the calibration",
         "shadow_rays=neepp-adaptive"},
    };
}

std::vector<IntegratorDoc> make_docs() {
    const PathOptions p;
    const BDPTOptions b;
    const PSSMLTOptions m;
    std::string samplers;
    for (const std::string &s : light_sampler_names()) samplers += (samplers.empty() ? "" : ", ") + s;
    auto common = [](int max_depth, int rr_depth, bool hide) {
        return std::vector<OptionDoc>{
            {"max_depth", text(max_depth), "longest path in edges (1: emitters only, 2: direct light, -1: unbounded)", ""},
            {"rr_depth", text(rr_depth), "path depth from which Russian roulette may end a path", ""},
            {"hide_emitters", text(hide), "emitters seen directly by the camera are black", ""}};
    };
    std::vector<IntegratorDoc> docs;
    IntegratorDoc path{"path", "unidirectional path tracing with next event estimation and MIS (Mitsuba 3's path)",
                       common(p.max_depth, p.rr_depth, p.hide_emitters)};
    path.options.push_back({"neepp", "off",
                            "off: the options below as given; auto: with several lights, a pilot measures plain NEE, "
                            "light_sampler=spatial-oriented and light_sampler=visibility, and renders with the most "
                            "efficient (docs/neepp.md)", ""});
    path.options.push_back({"auto_guiding", "false",
                            "neepp=auto: path guiding (guiding=sdtree) is a candidate too, on every scene (a pilot "
                            "then runs with one light as well)", "neepp=auto"});
    path.options.push_back({"form", "fast",
                            "fast (paths in batches, the default) or reference (one path at a time, the estimator's "
                            "definition: the same image in expectation, slower)", ""});
    path.options.push_back({"guiding", "none",
                            "none; sdtree: practical path guiding (Mueller et al. 2017), an SD-tree learned from "
                            "each pass's paths guides the next direction by one-sample MIS with the BSDF "
                            "where the BSDF has no delta part; map: the visibility map's guide, toward the grid's "
                            "cells by the flux each voxel learned from them, the map's visibility as the prior "
                            "(docs/neepp.md); sdtree+map: both, as a third strategy; unbiased whatever any "
                            "learned", ""});
    path.options.push_back({"guiding_bsdf_fraction", text(p.guiding_bsdf_fraction),
                            "guiding: the share of next directions the BSDF samples (the rest the guide), "
                            "in (0, 1]", ""});
    path.options.push_back({"guiding_tree_share", text(p.guiding_tree_share),
                            "guiding=sdtree+map: the SD-tree's share of the guide's directions where both guide "
                            "(the rest the map's guide), in [0, 1]", ""});
    path.options.push_back({"guiding_spatial_threshold", text(float(p.guiding_spatial_threshold)),
                            "guiding=sdtree: c, a spatial leaf of the SD-tree splits past c * sqrt(pass spp) "
                            "records (0: PPG's 12000 scaled by sqrt(pixels / 1280x720))", ""});
    path.options.push_back({"guiding_learn_direct", text(p.guiding_learn_direct),
                            "guiding: the guide learns the emission a guided direction finds directly too "
                            "(false: only the light next event estimation does not bring)", ""});
    path.options.push_back({"nee", text(p.nee), "next event estimation (false: BSDF sampling only, the paper's Path)", ""});
    path.options.push_back({"light_sampler", p.light_sampler, "which light NEE samples: " + samplers, ""});
    path.options.push_back({"within_light", p.within_light,
                            "where on it: own (the light's own sampling) or visibility (environment maps per "
                            "shading voxel by the visibility map)", ""});
    const std::string area_light_sampling =
        "how a point on a chosen area light is drawn: area (uniform in area, as Mitsuba 3) or solid-angle "
        "(uniform in the solid angle it subtends, as pbrt-v4 and Cycles: spheres from outside, rectangles from "
        "within half their diagonal; elsewhere and other shapes by area; docs/neepp.md)";
    path.options.push_back({"area_light_sampling", p.area_light_sampling, area_light_sampling, ""});
    path.options.push_back({"ris", text(p.ris),
                            "resampled NEE: M light-sample candidates per vertex, one chosen by f*Le*max(sqrt(V~), "
                            "ris_floor) for the shadow ray (1: plain NEE; keeps a visibility map)", ""});
    path.options.push_back({"ris_floor", text(p.ris_floor), "the least sqrt(V~) in the resampling target", "ris=M"});
    path.options.push_back({"ris_depth", text(p.ris_depth),
                            "resample at the path's first N vertices only (-1: all), plain NEE beyond", "ris=M"});
    for (OptionDoc o : shadow_ray_options()) {
        if (o.name == "voxels") o.description += " (also the grid of the spatial and visibility light samplers)";
        path.options.push_back(o);
    }
    docs.push_back(path);

    IntegratorDoc volpath = path;
    volpath.name = "volpath";
    volpath.description = "volumetric path tracing through participating media (Mitsuba 3's volpath): null surfaces "
                          "crossed without a bounce, shadow rays through media and null surfaces; the reference form "
                          "only";
    std::erase_if(volpath.options, [](const OptionDoc &o) { return o.name == "form" || o.name == "auto_guiding" || o.name.rfind("guiding", 0) == 0 || o.name.rfind("ris", 0) == 0;
    });
    docs.push_back(volpath);

    IntegratorDoc bdpt{"bdpt", "bidirectional path tracing, every (s, t) strategy, MIS-weighted", common(b.max_depth, b.rr_depth, b.hide_emitters)};
    bdpt.options.push_back({"mis", "power", "MIS heuristic: power or balance", ""});
    bdpt.options.push_back({"strategy", "", "render only strategy S,T (s light and t camera vertices)", ""});
    bdpt.options.push_back({"strategy_weight", "mis", "that strategy MIS-weighted (mis) or unweighted (none)", "strategy=S,T"});
    bdpt.options.push_back({"area_light_sampling", b.area_light_sampling, area_light_sampling + ", for s = 1", ""});
    bdpt.options.push_back({"light_paths", "independent", "independent, or neepp: NEE++ light-subpath selection", ""});
    bdpt.options.push_back({"candidates", text(b.candidates), "K light subpaths a camera subpath chooses among", "light_paths=neepp"});
    bdpt.options.push_back({"pool", text(b.pool), "M light subpaths traced before each pass", "light_paths=neepp"});
    for (OptionDoc o : shadow_ray_options()) {
        if (o.name == "voxels") o.description += " (also with light_paths=neepp)";
        bdpt.options.push_back(o);
    }
    docs.push_back(bdpt);

    IntegratorDoc light{"light", "light tracing (particle tracing): light paths splatted onto the film (Mitsuba 3's ptracer)",
                        common(b.max_depth, b.rr_depth, b.hide_emitters)};
    for (const OptionDoc &o : shadow_ray_options()) light.options.push_back(o);
    docs.push_back(light);

    IntegratorDoc pssmlt{"pssmlt",
                         "primary-sample-space Metropolis light transport (Kelemen et al. 2002) over bdpt, or over path; "
                         "also takes the options of the integrator it runs over",
                         {{"bidirectional", text(m.bidirectional), "over bdpt (true) or path (false)", ""},
                          {"bootstrap", text(m.bootstrap), "independent samples that estimate the normalization and start the chains", ""},
                          {"chains", text(m.chains), "Markov chains", ""},
                          {"large_step", text(m.large_step), "probability that a mutation draws every number afresh", ""},
                          {"sigma", text(m.sigma), "standard deviation of a small step's offset of each number", ""}}};
    docs.push_back(pssmlt);
    return docs;
}

}  // namespace

const std::vector<IntegratorDoc> &integrator_docs() {
    static const std::vector<IntegratorDoc> docs = make_docs();
    return docs;
}

const std::vector<std::pair<std::string, std::string>> &shadow_ray_policy_docs() {
    static const std::vector<std::pair<std::string, std::string>> docs = {
        {"nee", "trace every shadow ray (plain next event estimation)"},
        {"neepp", "NEE++ (the paper): trace with probability q = max(V~, q_min), weight 1/q"},
        {"neepp-adaptive", "NEE++ with q = c f sqrt(V~), c calibrated for least time x variance"},
        {"neepp-cv", "NEE++ as a control variate: V~ f when skipped, corrected when traced"},
    };
    return docs;
}

}  // namespace neepp
