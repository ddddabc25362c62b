#include "neepp/integrators/path_batch.h"

#include "neepp/base/light_selection_learner.h"

#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "neepp/base/bsdf.h"
#include "neepp/base/light_selection_learner.h"
#include "neepp/base/light_steps.h"
#include "neepp/integrators/path_guiding.h"
#include "neepp/lights/light_lanes.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"

namespace neepp {

struct PathBatch::Candidate {
    SampledLight light;
    const ContextLightSampler *within = nullptr;  // samples points of the light, if not the light itself
    LightSampleStart start;  // begun by begin_light, from the light's variates
    const LightSampleSteps *steps = nullptr;  // the light's samples in steps, if it offers them
    LightSample sample;      // taken by sample_light, alone or in lanes
    // Resampling only: the BSDF toward the sample, the cell of its light point, its target p̂.
    BSDFEval bsdf;
    uint32_t cell = 0;
    float target = 0;
};

struct PathBatch::Path {
    Sampler *sampler = nullptr;
    Color L{0.f}, beta{1.f};
    float eta = 1.f;
    Ray ray;
    int depth = 0;
    LightSampleContext prev;   // the previous scattering vertex, for MIS on emitters hit
    float prev_bsdf_pdf = 1.f;
    bool prev_delta = true;    // the camera counts as a delta vertex: no MIS on directly seen lights
    // The vertex being shaded: what the ray hit, and the light chosen for next event estimation there.
    RayHit hit;
    SurfaceInteraction si;
    LightSampleContext ctx;
    bool nee = false;
    // m candidate light samples (options.ris, or 1 where this vertex does not resample), and the one next
    // event estimation uses.
    Candidate *candidates = nullptr;
    int m = 1;
    int chosen = 0;
    float u_choice = 0;    // the resampling's variate
    float ris_weight = 0;  // its weight W = Σw / (M p̂(y))
    float learn = 0;       // for a learning light sampler: luminance(f·Le) / pdf of the plain NEE sample
    uint32_t cell = 0;     // the shading point's voxel, for the map
    // Next event estimation's shadow query, while its ray waits to be traced with the batch's others.
    ShadowQuery shadow;
    ShadowTest test;
    // guiding: the vertex's guide (none: the BSDF samples alone), and what the path tells the guide when
    // it ends (null: it learns nothing).
    VertexGuide guide;
    GuideRecorder *recorder = nullptr;

    // A new camera path in this slot. Only the state read before it is written is reset: the vertex,
    // light and shadow-query fields are written at each bounce before any read (and the texture memo in si
    // is keyed by what it holds), so the slot's ~0.5 KB need not be cleared.
    void start(const Ray &camera_ray, Sampler *s) {
        sampler = s;
        ray = camera_ray;
        L = Color(0.f);
        beta = Color(1.f);
        eta = 1.f;
        depth = 0;
        prev_bsdf_pdf = 1.f;
        prev_delta = true;
        if (recorder) recorder->clear();
    }
};

bool PathBatch::begin_vertex(const Scene &scene, Path &path) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    const bool show_emission = path.depth > 0 || !pi.options_.hide_emitters;
    const Ray &ray = path.ray;
    if (path.recorder && path.depth > 0) path.recorder->ended(path.depth - 1, path.si.p, !path.hit.valid());
    if (!path.hit.valid()) {
        if (show_emission)
            for (const Light *env : scene.infinite_lights()) {
                Color Le = env->eval_environment(ray.d);
                if (is_black(Le)) continue;
                float w = path.prev_delta ? 1.f
                                          : pi.emission_weight(*env, path.prev, direction_sample_from_miss(ray.d),
                                                            path.prev_bsdf_pdf);
                path.L += path.beta * Le * w;
                if (path.recorder && !pi.options_.guiding_learn_direct)
                    path.recorder->found_emission(path.depth - 1, path.beta * Le * w);
            }
        return false;
    }
    const SurfaceInteraction &si = path.si;  // filled by Li_batch, with the batch's other hits
    if (const Light *area = si.shape->area_light; area && show_emission) {
        Color Le = area->eval_surface(si, -ray.d);
        if (!is_black(Le)) {
            float w = path.prev_delta ? 1.f
                                      : pi.emission_weight(*area, path.prev, direction_sample_from_hit(path.prev.p, si),
                                                        path.prev_bsdf_pdf);
            path.L += path.beta * Le * w;
            if (path.recorder && !pi.options_.guiding_learn_direct)
                path.recorder->found_emission(path.depth - 1, path.beta * Le * w);
        }
    }
    if (pi.options_.max_depth >= 0 && path.depth + 1 >= pi.options_.max_depth) return false;

    const BSDF &bsdf = *si.shape->bsdf;
    bsdf.prefetch(si);
    path.ctx = PathIntegrator::light_context(si, ray.d);
    path.guide = pi.vertex_guide(si);
    path.nee = pi.options_.nee && (si.shape->bsdf_flags & BSDFSmooth);
    path.m = pi.candidates_at(path.depth);
    if (!path.nee) return true;
    const int M = path.m;
    if (M == 1) {
        Candidate &c = path.candidates[0];
        c.light = pi.light_sampler_->sample(path.ctx, path.sampler->next_1d());
        c.start.u = path.sampler->next_2d();
    } else {  // each candidate's numbers in the order one candidate takes them, then the choice's; the
              // lights chosen together (the light BVH's shared descent)
        float u[PathOptions::kMaxCandidates];
        SampledLight lights[PathOptions::kMaxCandidates];
        for (int i = 0; i < M; ++i) {
            u[i] = path.sampler->next_1d();
            path.candidates[i].start.u = path.sampler->next_2d();
        }
        path.u_choice = path.sampler->next_1d();
        pi.light_sampler_->sample_many(path.ctx, u, M, lights);
        for (int i = 0; i < M; ++i) path.candidates[i].light = lights[i];
    }
    path.chosen = 0;
    for (int i = 0; i < M; ++i) {
        Candidate &c = path.candidates[i];
        c.within = c.light.light ? pi.within_light_.for_light(*c.light.light) : nullptr;
        c.steps = c.light.light && !c.within ? c.light.light->steps() : nullptr;
        if (c.within) c.within->prefetch(path.ctx, c.start.u);
        else if (c.steps) c.steps->prefetch(c.start.u);
    }
    return true;
}

void PathBatch::begin_light(Path &path) const {
    if (!path.nee) return;
    for (int i = 0; i < path.m; ++i) {
        Candidate &c = path.candidates[i];
        if (!c.light.light) continue;
        c.start = c.within ? c.within->begin(path.ctx, c.start.u)
                  : c.steps  ? c.steps->begin(c.start.u)
                             : LightSampleStart{c.start.u};
    }
}

void PathBatch::sample_light(Path &path, LightSampleLanes &lanes) const {
    if (!path.nee) return;
    bool any = false;  // from here on, path.nee: whether there is a sample to use
    for (int i = 0; i < path.m; ++i) {
        Candidate &c = path.candidates[i];
        const SampledLight &sl = c.light;
        if (!sl.light || !(sl.pmf > 0)) {
            c.sample.ds.pdf = 0.f;  // a candidate all the same (resampling counts it), of weight 0
            continue;
        }
        any = true;
        if (c.within) {
            if (const LightLaneRecord *record = c.within->own_lane_record(path.ctx))
                lanes.add(*record, path.si.p, c.start.u, c.sample);
            else
                c.sample.ds = c.within->finish(path.ctx, c.start, c.sample.radiance);
        }
        else if (const LightLaneRecord *record = sl.light->lane_record())
            lanes.add(*record, path.si.p, c.start.u, c.sample);
        else if (c.steps)
            c.sample.ds = c.steps->finish(path.si.p, c.start, c.sample.radiance);
        else
            c.sample.ds = sl.light->sample_direction(path.si.p, c.start.u, c.sample.radiance);
    }
    path.nee = any;
}

void PathBatch::weigh_candidates(Path &path) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    if (!path.nee || path.m == 1) return;
    const SurfaceInteraction &si = path.si;
    const BSDF &bsdf = *si.shape->bsdf;
    path.cell = pi.resampling_visibility_.shading_cell(si.p);
    for (int i = 0; i < path.m; ++i) {
        Candidate &c = path.candidates[i];
        const DirectionSample &ds = c.sample.ds;
        c.target = 0.f;
        if (!(ds.pdf > 0) || is_black(c.sample.radiance)) continue;
        c.bsdf = bsdf.eval_pdf(BSDFContext{}, si, si.wi, si.to_local(ds.d));
        c.target = luminance(c.bsdf.f * c.sample.radiance);
        if (!(c.target > 0.f)) continue;
        c.cell = pi.resampling_visibility_.light_cell(ds);
        pi.resampling_visibility_.prefetch(path.cell, c.cell);  // read by resample, after the batch's other paths
    }
}

void PathBatch::resample(Path &path) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    if (!path.nee || path.m == 1) return;
    float w[PathOptions::kMaxCandidates];
    for (int i = 0; i < path.m; ++i) {
        Candidate &c = path.candidates[i];
        w[i] = 0.f;
        if (!(c.target > 0.f)) continue;
        c.target *= pi.resampling_visibility_(path.cell, c.cell);
        const float wi = c.target / (c.light.pmf * c.sample.ds.pdf);
        if (std::isfinite(wi)) w[i] = wi;
    }
    float sum = 0.f;
    const int s = choose_proportional(w, path.m, path.u_choice, sum);
    path.nee = s >= 0;
    if (!path.nee) return;
    path.chosen = s;
    path.ris_weight = sum / (float(path.m) * path.candidates[s].target);
}

bool PathBatch::begin_direct(Path &path) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    if (!path.nee) return false;
    const Candidate &c = path.candidates[path.chosen];
    const SampledLight &sl = c.light;
    const SurfaceInteraction &si = path.si;
    const DirectionSample &ds = c.sample.ds;
    const Color &Le = c.sample.radiance;
    const bool resampled = path.m > 1;
    // A learning light sampler hears of every plain NEE sample, as in PathIntegrator::sample_direct.
    const LightSelectionLearner *learner = resampled || !sl.light ? nullptr : pi.learner_;
    if (!(ds.pdf > 0) || is_black(Le)) {
        if (learner) learner->record(path.ctx, *sl.light, 0.f);
        return false;
    }
    const BSDF &bsdf = *si.shape->bsdf;
    const auto [f, bsdf_pdf] = resampled ? c.bsdf : bsdf.eval_pdf(BSDFContext{}, si, si.wi, si.to_local(ds.d));
    if (is_black(f)) {
        if (learner) learner->record(path.ctx, *sl.light, 0.f);
        return false;
    }
    if (learner) path.learn = luminance(f * Le) / ds.pdf;
    float light_pdf = ds.pdf * sl.pmf;
    // See emission_weight; with a guide too, the BSDF strategy's density is the BSDF's own (sample_guided).
    float w = ds.delta ? 1.f : mis_power(light_pdf, bsdf_pdf);
    ShadowQuery &q = path.shadow = ShadowQuery{};  // nothing the policy kept from the last bounce
    q.ray = ds.dist >= kInfinity ? si.spawn_ray(ds.d) : si.spawn_ray_to(ds.p);
    q.from = si.p;
    q.to = ds.p;
    if (resampled) {
        q.unoccluded = path.beta * f * Le * (w * path.ris_weight);
        if (pi.resampling_visibility_.uses_map()) q.from_cell = path.cell, q.to_cell = c.cell;  // located already
    } else {
        q.unoccluded = path.beta * f * Le * (w / light_pdf);
    }
    pi.queries_->prepare(q);
    return true;
}

bool PathBatch::decide_direct(Path &path, RenderCounters &counters) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    path.test = pi.queries_->begin_test(path.shadow, *path.sampler, counters);
    if (path.test.trace) return true;
    path.L += path.shadow.unoccluded * path.test.if_skipped;
    learn_direct(path, path.test.if_skipped);
    return false;
}

void PathBatch::learn_direct(const Path &path, float visibility) const {
    const Candidate &c = path.candidates[path.chosen];
    if (pi_.learner_ && path.m == 1 && c.light.light) pi_.learner_->record(path.ctx, *c.light.light, path.learn * visibility);
}

void PathBatch::end_direct(Path &path, bool occluded) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    pi.queries_->end_test(path.test, occluded);
    path.L += path.shadow.unoccluded * path.test.weight(occluded);
    learn_direct(path, path.test.weight(occluded));
}

bool PathBatch::finish_vertex(Path &path) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    const SurfaceInteraction &si = path.si;
    const BSDF &bsdf = *si.shape->bsdf;
    Sampler &sampler = *path.sampler;
    const VertexGuide &guide = path.guide;
    const float u_choice = guide.guides() ? sampler.next_1d() : 0.f;  // in Li's order
    float u1 = sampler.next_1d();
    Vec2 u2 = sampler.next_2d();
    float own_pdf = 0.f;  // the BSDF's density of a guided sample, for MIS (sample_guided)
    BSDFSample bs = guide.guides() ? sample_guided(guide, bsdf, si, u_choice, u1, u2, own_pdf)
                               : bsdf.sample(BSDFContext{}, si, si.wi, u1, u2);
    if (!bs.valid()) return false;
    path.beta *= bs.weight;
    path.eta *= bs.eta;
    path.prev = path.ctx;
    path.prev_bsdf_pdf = guide.guides() ? own_pdf : bs.pdf;
    path.prev_delta = (bs.sampled_flags & BSDFDelta) != 0;
    path.ray = si.spawn_ray(si.to_world(bs.wo));
    ++path.depth;

    // Russian roulette on the throughput (times eta^2 so refraction does not trigger it), Mitsuba's rule.
    if (path.depth >= pi.options_.rr_depth) {
        float q = std::min(max_component(path.beta) * path.eta * path.eta, 0.95f);
        if (!(sampler.next_1d() < q)) return false;
        path.beta /= q;
    }
    if (!(max_component(path.beta) > 0)) return false;
    if (guide.record && path.recorder) path.recorder->add(path.depth - 1, si.p, path.ray.d, bs.pdf, path.beta, path.L);
    return true;
}

void PathBatch::Li_batch(const Scene &scene, std::span<const Ray> rays, std::span<Sampler *const> samplers,
                              std::span<Color> out, RenderCounters &counters) const {
    const PathIntegrator &pi = pi_;  // a local: the stages' stores through path cannot alias it
    constexpr size_t kBatch = 32;
    // The paths' slots live as long as the thread: built once, not at every call (a call takes only 32
    // samples, and building 32 slots of ~0.5 KB each every time is a cost for nothing). Path::start
    // resets what a new path reads before writing.
    struct Slots {
        std::array<Path, kBatch> paths;
        std::array<uint32_t, kBatch> active, pending;
        std::vector<Candidate> candidates;  // each path's options.ris, one after another
        std::vector<GuideRecorder> recorders;  // guiding while the guide learns: one per path
    };
    thread_local std::unique_ptr<Slots> slots;
    if (!slots) slots = std::make_unique<Slots>();
    auto &[paths, active, pending, candidates, recorders] = *slots;
    const size_t M = size_t(pi.options_.ris);
    if (candidates.size() < kBatch * M) candidates.resize(kBatch * M);
    const bool learning = pi.guide_learns_ && (pi.guide_ || pi.map_guide_);
    if (learning && recorders.size() < kBatch) recorders.resize(kBatch);
    for (size_t base = 0; base < rays.size(); base += kBatch) {
        const size_t n = std::min(kBatch, rays.size() - base);
        for (size_t i = 0; i < n; ++i) {
            paths[i].recorder = learning ? &recorders[i] : nullptr;
            paths[i].start(rays[base + i], samplers[base + i]);
            paths[i].candidates = &candidates[i * M];
            active[i] = uint32_t(i);
        }
        // Each stage runs over every live path before the next starts, so a prefetch issued for one path
        // has the other paths' work to complete in.
        for (size_t live = n; live > 0;) {
            // Rays go to Embree 16 at a time, as packets of its native width (Scene::packet_width), as
            // Mitsuba's vectorized variants trace them: cheaper per ray than one at a time, most of all for
            // a tile's coherent camera rays.
            for (size_t k0 = 0; k0 < live; k0 += 16) {
                const Ray *rs[16];
                RayHit *hs[16];
                const int m = int(std::min<size_t>(16, live - k0));
                for (int j = 0; j < m; ++j) rs[j] = &paths[active[k0 + j]].ray, hs[j] = &paths[active[k0 + j]].hit;
                // Camera rays (paths advance in lockstep, so all of a packet are at one depth) leave one
                // pixel or a few neighbours: Embree's coherent traversal suits them.
                scene.trace16(rs, hs, m, paths[active[k0]].depth == 0);
                counters.rays += m;
                for (int j = 0; j < m; ++j) scene.prefetch(*hs[j]);
            }
            // The hit records, most of them eight at a time (HitLanes): the triangles' data, fetched
            // for the prefetches above, is in cache by now.
            HitLanes lanes;
            for (size_t k = 0; k < live; ++k)
                if (Path &p = paths[active[k]]; p.hit.valid()) scene.fill_in_lanes(lanes, p.hit, p.ray, p.si);
            fill_lanes(lanes);
            size_t shading = 0;
            for (size_t k = 0; k < live; ++k)
                if (begin_vertex(scene, paths[active[k]])) active[shading++] = active[k];
            for (size_t k = 0; k < shading; ++k) begin_light(paths[active[k]]);
            LightSampleLanes light_lanes;
            for (size_t k = 0; k < shading; ++k) sample_light(paths[active[k]], light_lanes);
            light_lanes.flush();
            if (pi.resampling()) {
                for (size_t k = 0; k < shading; ++k) weigh_candidates(paths[active[k]]);
                for (size_t k = 0; k < shading; ++k) resample(paths[active[k]]);
            }
            // Next event estimation: each policy decides, then the rays it asks for go out as packets.
            size_t querying = 0, tracing = 0;
            for (size_t k = 0; k < shading; ++k)
                if (begin_direct(paths[active[k]])) pending[querying++] = active[k];
            for (size_t k = 0; k < querying; ++k)
                if (decide_direct(paths[pending[k]], counters)) pending[tracing++] = pending[k];
            for (size_t k0 = 0; k0 < tracing; k0 += 16) {
                const Ray *rs[16];
                bool occluded[16];
                const int m = int(std::min<size_t>(16, tracing - k0));
                for (int j = 0; j < m; ++j) rs[j] = &paths[pending[k0 + j]].shadow.ray;
                trace_shadow_rays16(scene, rs, m, occluded, counters);
                for (int j = 0; j < m; ++j) end_direct(paths[pending[k0 + j]], occluded[j]);
            }
            live = 0;
            for (size_t k = 0; k < shading; ++k)
                if (finish_vertex(paths[active[k]])) active[live++] = active[k];
        }
        for (size_t i = 0; i < n; ++i) out[base + i] = paths[i].L;
        if (learning)
            for (size_t i = 0; i < n; ++i) pi.commit_guide(recorders[i], paths[i].L);
    }
}

}  // namespace neepp
