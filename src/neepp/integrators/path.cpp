#include "neepp/integrators/path.h"

#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "neepp/base/bsdf.h"
#include "neepp/base/light_selection_learner.h"
#include "neepp/integrators/path_batch.h"
#include "neepp/integrators/path_guiding.h"
#include "neepp/integrators/path_state.h"
#include "neepp/light_selection/factory.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include <fmt/core.h>

namespace neepp {

PathIntegrator::PathIntegrator(PathOptions options, std::unique_ptr<ShadowRayTester> shadow)
    : options_(std::move(options)), shadow_(std::move(shadow)), batch_(std::make_unique<PathBatch>(*this)) {}

PathIntegrator::~PathIntegrator() = default;

const RayBatch *PathIntegrator::batch() const {
    return options_.reference || options_.volumetric ? nullptr : batch_.get();
}

void PathIntegrator::prepare(const Scene &scene) {
    // As Mitsuba's path: media are volpath's; path renders the scene as if in vacuum.
    if (scene.has_media() && !options_.volumetric)
        fmt::print(stderr, "neepp: note: the path integrator ignores the scene's participating media (as Mitsuba 3's "
                           "path does); --integrator volpath renders them\n");
    // The factory keeps a map for a sampler that may read one; on a scene where it does not (one light),
    // a map that no shadow-ray policy uses either is not built. Resampling reads it on any scene.
    if (shadow_->policy() == "nee" && shadow_->visibility_map() &&
        !light_sampler_needs_visibility_map(options_.light_sampler, scene.lights().size()) &&
        options_.within_light == "own" && !resampling() && !options_.guides_by_map())
        shadow_ = std::make_unique<TraceAllShadowRays>();
    shadow_->prepare(scene);  // NEE++: build or load the visibility map
    queries_ = &shadow_->query_tester();
    LightSelectionInputs inputs{&scene, shadow_->voxel_grid(), shadow_->visibility_map(), options_.voxels};
    light_sampler_ = make_light_sampler(options_.light_sampler, scene.light_pointers(), inputs);
    learner_ = light_sampler_->learner();
    within_light_ = WithinLightSampling(options_.within_light, scene, shadow_->voxel_grid(), shadow_->visibility_map(),
                                        options_.area_light_sampling);
    refresh_resampling();
    if (options_.guides_by_map() && guide_learns_) {
        if (!shadow_->voxel_grid())
            throw std::invalid_argument("guiding=map: the shadow-ray component keeps no visibility map");
        map_guide_ = std::make_unique<MapGuide>(*shadow_->voxel_grid());
    }
    if (options_.guides_by_tree() && guide_learns_) {
        SDTreeOptions tree;
        // PPG's c = 12000 is for 1280x720 images: a leaf splits past c·√(pass spp) records, and the
        // records of a pass grow with the pixels, so at the same c a smaller image gets fewer leaves.
        // 0 scales c by √(pixels / 1280·720), which keeps the leaves' count at PPG's √(records) rate.
        const double pixels = double(scene.camera.width) * double(scene.camera.height);
        tree.spatial_threshold = options_.guiding_spatial_threshold > 0 ? options_.guiding_spatial_threshold
                                                                        : 12000.0 * std::sqrt(pixels / (1280.0 * 720.0));
        guide_ = std::make_unique<SDTree>(scene.bounds(), tree);
    }
    guide_spp_ = 0;
}

void PathIntegrator::refresh_resampling() {
    // A map seeded only after the first pass (deferred) is read from the pass after it.
    if (resampling())
        resampling_visibility_ = ResamplingVisibility(shadow_->voxel_grid(), shadow_->visibility_map(), options_.ris_floor);
}

void PathIntegrator::end_pass(const Scene &, const PassStatistics &pass) {
    shadow_->end_pass(pass);     // NEE++: merge what the pass learned into the map the next pass reads
    queries_ = &shadow_->query_tester();  // ... or, its rejection off, leave the queries to plain NEE
    light_sampler_->end_pass();  // ... and rebuild the light distributions that read it
    within_light_.end_pass();
    refresh_resampling();
    if (guide_ && guide_learns_) {  // what this pass recorded guides the next
        guide_->update(pass.spp - guide_spp_);
        guide_spp_ = pass.spp;
    }
    if (map_guide_ && guide_learns_) map_guide_->update(shadow_->visibility_map());
}

VertexGuide PathIntegrator::vertex_guide(const SurfaceInteraction &si) const {
    const float f = options_.guiding_bsdf_fraction;
    return guide_at(guide_.get(), map_guide_.get(), guide_learns_, si, f, options_.guiding_tree_share);
}

void PathIntegrator::commit_guide(const GuideRecorder &recorder, const Color &L) const {
    if (!guide_learns_) return;
    if (guide_) recorder.commit(*guide_, L);
    if (map_guide_) recorder.commit(*map_guide_, L);
}

void PathIntegrator::restore_state(const Scene &, const std::string &state) {
    const PathState parts = PathState::decode(state, framed_state(), options_.guides_by_map());
    shadow_->restore_state(parts.shadow);
    if (learner_ && !parts.light.empty()) learner_->restore_state(parts.light);
    if (guide_ && guide_learns_ && !parts.guide.empty()) {
        guide_->load(parts.guide);
        guide_spp_ = parts.guide_spp;
    }
    if (map_guide_ && guide_learns_ && !parts.map_guide.empty()) {
        map_guide_->load(parts.map_guide);
        map_guide_->update(shadow_->visibility_map());  // tables from the restored totals and map
    }
    queries_ = &shadow_->query_tester();
    light_sampler_->end_pass();  // its distributions read the restored map
    within_light_.end_pass();
    refresh_resampling();
}

nlohmann::json PathIntegrator::statistics() const {
    nlohmann::json out = nlohmann::json::object();
    if (nlohmann::json s = shadow_->statistics(); !s.empty()) out["shadow_rays"] = s;
    if (light_sampler_) {
        nlohmann::json l = light_sampler_->statistics();
        l["used"] = light_sampler_->name();  // "power" whatever was asked when the scene has one light
        out["light_sampler"] = l;
    }
    if (within_light_.any()) out["within_light"] = within_light_.statistics();
    if (guide_ && map_guide_)
        out["guiding"] = {{"kind", "sdtree+map"}, {"sdtree", guide_->statistics()}, {"map", map_guide_->statistics()}};
    else if (guide_) out["guiding"] = guide_->statistics();
    else if (map_guide_) out["guiding"] = map_guide_->statistics();
    return out;
}

nlohmann::json PathIntegrator::describe() const {
    return {{"name", options_.volumetric ? "volpath" : "path"},
            {"max_depth", options_.max_depth},
            {"rr_depth", options_.rr_depth},
            {"hide_emitters", options_.hide_emitters},
            {"nee", options_.nee},
            {"light_sampler", options_.light_sampler},
            {"within_light", options_.within_light},
            {"area_light_sampling", options_.area_light_sampling},
            {"ris", options_.ris},
            {"ris_floor", options_.ris_floor},
            {"ris_depth", options_.ris_depth},
            {"form", options_.reference || options_.volumetric ? "reference" : "fast"},
            {"guiding", options_.guiding},
            {"shadow_rays", shadow_->policy()},
            {"shadow_ray_options", shadow_->describe()}};
}

// The light strategy's density in both MIS weights (here and in begin_direct) is the candidates' source
// density p = pmf × pdf, with or without resampling. Resampling estimates ∫ g for any g that is 0 where its
// target is (resampling.h); the light strategy's g is f·Le·V·w_L with w_L = p²/(p² + p_bsdf²), and BSDF
// sampling estimates ∫ f·Le·V·w_B with w_B the weight below, p_bsdf²/(p² + p_bsdf²). w_L + w_B = 1 at every
// point, so the two add up to ∫ f·Le·V whatever density enters them: which one only changes the variance
// (and p, unlike the resampled sample's own density, can be evaluated for a point BSDF sampling found).
float PathIntegrator::emission_weight(const Light &light, const LightSampleContext &prev, const DirectionSample &ds,
                                      float prev_pdf) const {
    if (!options_.nee) return 1.f;
    const ContextLightSampler *within = within_light_.for_light(light);
    float light_pdf = light_sampler_->pmf(prev, light) * (within ? within->pdf(prev, ds) : light.pdf_direction(prev.p, ds));
    return mis_power(prev_pdf, light_pdf);
}


struct PathIntegrator::LightCandidate {
    SampledLight light;  // the light and the probability of choosing it
    DirectionSample ds;  // a point on it, and its solid-angle density (0: no sample)
    Color Le{0.f};       // the radiance arriving from it, occlusion aside
    // Resampling only: the BSDF toward it and its target p̂ (light_selection/resampling.h).
    BSDFEval bsdf;
    float target = 0;
};

Color PathIntegrator::sample_direct(const Scene &scene, const SurfaceInteraction &si, const LightSampleContext &ctx,
                                    const Color &beta, int M, Sampler &sampler, RenderCounters &counters) const {
    const BSDF &bsdf = *si.shape->bsdf;
    // M candidates, each a light chosen by the light sampler and a point on it, by the light's own sampling
    // or within_light's. Without resampling (M = 1) the one candidate is the sample.
    LightCandidate c[PathOptions::kMaxCandidates];
    for (int i = 0; i < M; ++i) {
        c[i].light = light_sampler_->sample(ctx, sampler.next_1d());
        const Vec2 u = sampler.next_2d();
        const Light *light = c[i].light.light;
        if (!light || !(c[i].light.pmf > 0)) continue;  // a candidate all the same (resampling counts it), of weight 0
        const ContextLightSampler *within = within_light_.for_light(*light);
        c[i].ds = within ? within->sample(ctx, u, c[i].Le) : light->sample_direction(si.p, u, c[i].Le);
    }
    // Resampling: one candidate y chosen with probability w / Σw, w = p̂ / (pmf × pdf), weighted by
    // W = Σw / (M p̂(y)); p̂ = luminance(f·Le) × max(√Ṽ, ris_floor).
    int s = 0;
    float W = 1.f;
    if (M > 1) {
        const float u_choice = sampler.next_1d();
        const uint32_t shading_cell = resampling_visibility_.shading_cell(si.p);
        float w[PathOptions::kMaxCandidates];
        for (int i = 0; i < M; ++i) {
            w[i] = 0.f;
            if (!(c[i].ds.pdf > 0) || is_black(c[i].Le)) continue;
            c[i].bsdf = bsdf.eval_pdf(BSDFContext{}, si, si.wi, si.to_local(c[i].ds.d));
            c[i].target = luminance(c[i].bsdf.f * c[i].Le);
            if (!(c[i].target > 0.f)) continue;
            c[i].target *= resampling_visibility_(shading_cell, resampling_visibility_.light_cell(c[i].ds));
            const float wi = c[i].target / (c[i].light.pmf * c[i].ds.pdf);
            if (std::isfinite(wi)) w[i] = wi;
        }
        float sum = 0.f;
        s = choose_proportional(w, M, u_choice, sum);
        if (s < 0) return Color(0.f);
        W = sum / (float(M) * c[s].target);
    }
    const LightCandidate &y = c[s];
    // A light sampler that learns (light_selection_learner.h) hears of every plain NEE sample, those that
    // contribute nothing included: which lights give nothing here is half of what it learns.
    const LightSelectionLearner *learner = M == 1 && y.light.light ? learner_ : nullptr;
    if (!(y.ds.pdf > 0) || is_black(y.Le)) {
        if (learner) learner->record(ctx, *y.light.light, 0.f);
        return Color(0.f);
    }
    const auto [f, bsdf_pdf] = M > 1 ? y.bsdf : bsdf.eval_pdf(BSDFContext{}, si, si.wi, si.to_local(y.ds.d));
    if (is_black(f)) {
        if (learner) learner->record(ctx, *y.light.light, 0.f);
        return Color(0.f);
    }
    // MIS against BSDF sampling, by the light strategy's source density (see emission_weight).
    const float light_pdf = y.ds.pdf * y.light.pmf;
    const float w_mis = y.ds.delta ? 1.f : mis_power(light_pdf, bsdf_pdf);
    // The shadow-ray component decides whether to trace (NEE++: with probability q, weight 1/q) and traces.
    ShadowQuery q;
    q.ray = y.ds.dist >= kInfinity ? si.spawn_ray(y.ds.d) : si.spawn_ray_to(y.ds.p);
    q.from = si.p;
    q.to = y.ds.p;
    q.unoccluded = M > 1 ? beta * f * y.Le * (w_mis * W) : beta * f * y.Le * (w_mis / light_pdf);
    const float visibility = test_visibility(*queries_, scene, q, sampler, counters);
    if (learner) learner->record(ctx, *y.light.light, luminance(f * y.Le) * visibility / y.ds.pdf);
    return q.unoccluded * visibility;
}

bool PathIntegrator::survives_roulette(Color &beta, float eta, Sampler &sampler) {
    const float q = std::min(max_component(beta) * eta * eta, 0.95f);
    if (!(sampler.next_1d() < q)) return false;
    beta /= q;
    return true;
}

Color PathIntegrator::Li(const Scene &scene, const Ray &camera_ray, Sampler &sampler, RenderCounters &counters) const {
    if (options_.volumetric) return Li_volumetric(scene, camera_ray, sampler, counters);
    Color L(0.f), beta(1.f);  // radiance so far, and the path throughput f·cos/pdf up to the current vertex
    float eta = 1.f;          // product of relative IORs crossed, for Russian roulette
    Ray ray = camera_ray;
    // The previous scattering vertex, for the MIS weight of emission that the BSDF-sampled ray finds.
    LightSampleContext prev;
    float prev_bsdf_pdf = 1.f;
    bool prev_delta = true;  // the camera counts as a delta vertex: no MIS on directly seen lights
    GuideRecorder recorder;  // guiding: what the path tells the guide
    const bool learn_direct = options_.guiding_learn_direct;
    for (int depth = 0;; ++depth) {
        SurfaceInteraction si;
        const bool hit = scene.intersect(ray, si);
        ++counters.rays;
        if (depth > 0) recorder.ended(depth - 1, si.p, !hit);
        const bool show_emission = depth > 0 || !options_.hide_emitters;

        // Emission along the ray: environments where it escapes, an area light where it lands.
        if (!hit) {
            if (show_emission)
                for (const Light *env : scene.infinite_lights()) {
                    const Color Le = env->eval_environment(ray.d);
                    if (is_black(Le)) continue;
                    const float w = prev_delta ? 1.f
                                               : emission_weight(*env, prev, direction_sample_from_miss(ray.d), prev_bsdf_pdf);
                    L += beta * Le * w;
                    if (!learn_direct) recorder.found_emission(depth - 1, beta * Le * w);
                }
            break;
        }
        if (const Light *area = si.shape->area_light; area && show_emission) {
            const Color Le = area->eval_surface(si, -ray.d);
            if (!is_black(Le)) {
                const float w = prev_delta ? 1.f
                                           : emission_weight(*area, prev, direction_sample_from_hit(prev.p, si), prev_bsdf_pdf);
                L += beta * Le * w;
                if (!learn_direct) recorder.found_emission(depth - 1, beta * Le * w);
            }
        }
        // max_depth counts vertices: the next one's emission would be one too many.
        if (options_.max_depth >= 0 && depth + 1 >= options_.max_depth) break;

        // Next event estimation, where the BSDF has a smooth part a light sample can reach.
        const LightSampleContext ctx = light_context(si, ray.d);
        const VertexGuide guide = vertex_guide(si);
        if (options_.nee && (si.shape->bsdf_flags & BSDFSmooth))
            L += sample_direct(scene, si, ctx, beta, candidates_at(depth), sampler, counters);

        // The next direction: by the BSDF, or where a guide has learned, by the BSDF or the guide.
        const BSDF &bsdf = *si.shape->bsdf;
        const float u_choice = guide.guides() ? sampler.next_1d() : 0.f;
        const float u1 = sampler.next_1d();
        const Vec2 u2 = sampler.next_2d();
        float own_pdf = 0.f;  // the BSDF's density of a guided sample, for MIS (sample_guided)
        const BSDFSample bs = guide.guides() ? sample_guided(guide, bsdf, si, u_choice, u1, u2, own_pdf)
                                         : bsdf.sample(BSDFContext{}, si, si.wi, u1, u2);
        if (!bs.valid()) break;
        beta *= bs.weight;
        eta *= bs.eta;
        prev = ctx;
        prev_bsdf_pdf = guide.guides() ? own_pdf : bs.pdf;
        prev_delta = (bs.sampled_flags & BSDFDelta) != 0;
        ray = si.spawn_ray(si.to_world(bs.wo));

        if (depth + 1 >= options_.rr_depth && !survives_roulette(beta, eta, sampler)) break;
        if (!(max_component(beta) > 0)) break;
        if (guide.record) recorder.add(depth, si.p, ray.d, bs.pdf, beta, L);
    }
    commit_guide(recorder, L);
    return L;
}

}  // namespace neepp
