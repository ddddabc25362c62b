#include "neepp/integrators/bdpt.h"

#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include "neepp/light_selection/basic_light_samplers.h"
#include "neepp/lights/environment_light.h"
#include "neepp/render/film.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

namespace {

// Unbounded depth (max_depth -1) still needs a bound on a subpath's vertices; Russian roulette has ended
// all but a vanishing fraction of paths long before it.
constexpr int kMaxUnboundedVertices = 64;
// NEE++ selection: share of the uniform choice mixed into the visibility-driven one, so that a
// candidate the map wrongly believes hidden keeps a probability of at least 0.1 / K.
constexpr float kUniformMix = 0.1f;
// Vertices of each side a candidate's score looks at: each pair is a visibility-map read (a cache miss,
// the map being tens of MB), and deep vertices carry little throughput. Scoring all of them (up to 17 x 17
// pairs per candidate) would make each sample much slower.
constexpr int kScoreVertices = 3;
// Pool paths' sampler: its own seed, so that pool paths and camera samples never share numbers.
constexpr uint64_t kPoolSeed = 0x706f6f6c6c696768ULL;

float remap0(float x) { return x != 0.f ? x : 1.f; }

// The ray that decides whether a and b see each other: from the end that has a surface to leave from,
// stopping short of the other end.
Ray connection_ray(const PathVertex &a, const PathVertex &b) {
    if (b.infinite) return a.on_surface() ? spawn_ray(a.p, a.n, b.dir) : Ray{a.p, b.dir, 0.f, kInfinity};
    if (a.on_surface()) return spawn_ray_to(a.p, a.n, b.p);
    if (b.on_surface()) return spawn_ray_to(b.p, b.n, a.p);
    const Vec3 d = b.p - a.p;
    const float dist = norm(d);
    return Ray{a.p, d / dist, 0.f, dist * (1.f - kShadowEpsilon)};
}

}  // namespace

BDPTIntegrator::BDPTIntegrator(BDPTOptions options, std::unique_ptr<ShadowRayTester> shadow)
    : options_(std::move(options)), shadow_(std::move(shadow)) {
    const bool unbounded = options_.max_depth < 0;
    camera_walk_ = {unbounded ? kMaxUnboundedVertices + 1 : options_.max_depth + 1, options_.rr_depth};
    light_walk_ = {unbounded ? kMaxUnboundedVertices : options_.max_depth, options_.rr_depth};
}

void BDPTIntegrator::prepare(const Scene &scene) {
    // An orthographic camera: Mitsuba 3's ptracer refuses it too (it has no sample_direction), as a light
    // path would meet its rays with probability zero. A thin lens: Mitsuba's ptracer samples the lens, but
    // neepp's light paths connect to a pinhole only (a lens point would be one more vertex to sample and
    // weigh in MIS).
    const std::string name = options_.light_tracer ? "light" : "bdpt";
    if (scene.has_media())
        throw std::invalid_argument(name + ": participating media are not supported by light paths yet; render this "
                                           "scene with the volpath integrator");
    if (scene.camera.has_lens())
        throw std::invalid_argument(name + ": light paths cannot connect to the thinlens sensor in neepp (its lens "
                                           "is not sampled by light paths); render this scene with the path integrator");
    if (!scene.camera.has_importance())
        throw std::invalid_argument(name + ": the orthographic sensor cannot be reached by light paths (it has no "
                                           "importance function); render this scene with the path integrator");
    shadow_->prepare(scene);
    queries_ = &shadow_->query_tester();
    if (options_.neepp_selection && !shadow_->visibility_map())
        throw std::logic_error("bdpt: light_paths=neepp needs a shadow-ray component that keeps a visibility map");
    // Light subpaths choose their light before they have a point to choose from: by power, context-free,
    // so that an emitter a camera path finds can be given the density of having been chosen.
    light_sampler_ = std::make_unique<PowerLightSampler>(scene.light_pointers());
    ctx_.scene = &scene;
    ctx_.camera = &scene.camera;
    ctx_.lights = light_sampler_.get();
    area_lights_ = WithinLightSampling("own", scene, nullptr, nullptr, options_.area_light_sampling);
    ctx_.disk_pdf = SceneSphere(scene.bounds()).disk_pdf();
    pool_.clear();
    pool_cells_.clear();
    pool_paths_traced_ = 0;
}

void BDPTIntegrator::end_pass(const Scene &, const PassStatistics &pass) {
    shadow_->end_pass(pass);
    queries_ = &shadow_->query_tester();
}

void BDPTIntegrator::restore_state(const Scene &, const std::string &state) {
    shadow_->restore_state(state);
    queries_ = &shadow_->query_tester();
}

nlohmann::json BDPTIntegrator::describe() const {
    nlohmann::json j = {{"name", options_.light_tracer ? "light" : "bdpt"},
                        {"max_depth", options_.max_depth},
                        {"rr_depth", options_.rr_depth},
                        {"hide_emitters", options_.hide_emitters},
                        {"shadow_rays", shadow_->policy()},
                        {"shadow_ray_options", shadow_->describe()}};
    if (!options_.light_tracer) {
        j["mis"] = options_.power_heuristic ? "power" : "balance";
        j["light_paths"] = options_.neepp_selection ? "neepp" : "independent";
        j["area_light_sampling"] = options_.area_light_sampling;
        if (options_.neepp_selection) {
            j["candidates"] = options_.candidates;
            j["pool"] = options_.pool;
        }
    }
    if (options_.strategy_s >= 0) {
        j["strategy"] = std::to_string(options_.strategy_s) + "," + std::to_string(options_.strategy_t);
        j["strategy_weight"] = options_.strategy_mis ? "mis" : "none";
    }
    return j;
}

nlohmann::json BDPTIntegrator::statistics() const {
    nlohmann::json out = nlohmann::json::object();
    if (nlohmann::json s = shadow_->statistics(); !s.empty()) out["shadow_rays"] = s;
    if (options_.neepp_selection) out["pool_paths_traced"] = pool_paths_traced_;
    return out;
}

bool BDPTIntegrator::wants(int s, int t) const {
    const int edges = s + t - 1;
    if (options_.max_depth >= 0 && edges > options_.max_depth) return false;
    if (options_.hide_emitters && s + t == 2) return false;
    if (options_.strategy_s >= 0) return s == options_.strategy_s && t == options_.strategy_t;
    if (options_.light_tracer) return t == 1;
    // A light seen directly is the camera path's (s = 0); connecting the light's own point to the camera
    // (s = t = 1) would count it twice, and BDPT's weights do not include it (pbrt's choice too).
    return !(s == 1 && t == 1);
}

float BDPTIntegrator::mis_weight(const std::vector<PathVertex> &light, const std::vector<PathVertex> &camera,
                                 const PathVertex &sampled, int s, int t) const {
    if (s + t == 2) return 1.f;
    // Not zero-filled: only the first s and t entries are read (filling the arrays would be a good part of
    // the function's time).
    const PathVertex *lv[kMaxUnboundedVertices + 2], *cv[kMaxUnboundedVertices + 2];
    cv[0] = &sampled;  // t >= 1 always; tells the compiler cv[t - 1] is written
    float lfwd[kMaxUnboundedVertices + 2], lrev[kMaxUnboundedVertices + 2];
    float cfwd[kMaxUnboundedVertices + 2], crev[kMaxUnboundedVertices + 2];
    bool ldelta[kMaxUnboundedVertices + 2], cdelta[kMaxUnboundedVertices + 2];
    for (int i = 0; i < s; ++i) {
        lv[i] = (s == 1 && i == 0) ? &sampled : &light[i];
        lfwd[i] = lv[i]->pdf_fwd, lrev[i] = lv[i]->pdf_rev, ldelta[i] = lv[i]->delta;
    }
    for (int i = 0; i < t; ++i) {
        cv[i] = (t == 1 && i == 0) ? &sampled : &camera[i];
        cfwd[i] = cv[i]->pdf_fwd, crev[i] = cv[i]->pdf_rev, cdelta[i] = cv[i]->delta;
    }
    const PathVertex *qs = s > 0 ? lv[s - 1] : nullptr, *pt = cv[t - 1];
    const PathVertex *qs_minus = s > 1 ? lv[s - 2] : nullptr, *pt_minus = t > 1 ? cv[t - 2] : nullptr;
    // The strategy joins the path at qs and pt: they are connected, whatever lobe their subpath sampled,
    // and the densities toward and past the join are those of the other direction.
    cdelta[t - 1] = false;
    if (s > 0) ldelta[s - 1] = false;
    crev[t - 1] = s > 0 ? pdf_next(ctx_, *qs, qs_minus, *pt) : pdf_light_origin(ctx_, *pt, *pt_minus);
    if (pt_minus) crev[t - 2] = s > 0 ? pdf_next(ctx_, *pt, qs, *pt_minus) : pdf_light(ctx_, *pt, *pt_minus);
    if (qs) lrev[s - 1] = pdf_next(ctx_, *pt, pt_minus, *qs);
    if (qs_minus) lrev[s - 2] = pdf_next(ctx_, *qs, pt, *qs_minus);

    // Ratios of the other strategies' densities to this one's, walking the join along the path.
    auto h = [&](float r) { return options_.power_heuristic ? r * r : r; };
    float sum = 0, r = 1;
    for (int i = t - 1; i > 0; --i) {
        r *= remap0(crev[i]) / remap0(cfwd[i]);
        if (!cdelta[i] && !cdelta[i - 1]) sum += h(r);
    }
    r = 1;
    for (int i = s - 1; i >= 0; --i) {
        r *= remap0(lrev[i]) / remap0(lfwd[i]);
        const bool delta_before = i > 0 ? ldelta[i - 1] : lv[0]->is_delta_light();
        if (!ldelta[i] && !delta_before) sum += h(r);
    }
    return 1.f / (1.f + sum);
}

Color BDPTIntegrator::connect(const std::vector<PathVertex> &light, const std::vector<PathVertex> &camera, int s,
                              int t, Sampler &sampler, RenderCounters &counters, Vec2 &raster) const {
    const PathVertex &pt = camera[t - 1];
    if (t > 1 && s != 0 && pt.infinite) return Color(0.f);
    // The vertex a strategy samples afresh (the camera for t = 1, a light point for s = 1): a slot kept
    // per thread, since a vertex is large and most strategies need none.
    thread_local PathVertex sampled;
    Color L(0.f);
    bool test = true;            // a shadow ray decides
    const PathVertex *from = &pt, *to = nullptr;  // its ends: camera side, light side
    if (s == 0) {
        if (!pt.is_light()) return Color(0.f);
        L = pt.beta * emitted_toward(ctx_, pt, camera[t - 2]);
        test = false;
    } else if (t == 1) {
        const PathVertex &qs = light[s - 1];
        if (!qs.connectible()) return Color(0.f);
        const CameraConnection c = ctx_.camera->connect(qs.p);
        if (!c.valid()) return Color(0.f);
        sampled = PathVertex{};
        sampled.kind = VertexKind::Camera;
        sampled.p = ctx_.camera->position();
        L = qs.beta * scatter(qs, c.d) * c.weight;
        raster = c.raster;
        from = &sampled;
        to = &qs;
    } else if (s == 1) {
        if (!pt.connectible()) return Color(0.f);
        const SampledLight sl = ctx_.lights->sample({}, sampler.next_1d());
        const Vec2 u = sampler.next_2d();
        if (!sl.light || !(sl.pmf > 0)) return Color(0.f);
        Color Le;
        // Its weight divides by the density it was drawn with; its MIS weight (below) takes the light vertex's
        // density as light subpaths draw it (by area), as pbrt-v4's does: the weights of every strategy still
        // sum to one, and with solid-angle sampling that density is not this one's (slightly worse weights,
        // never a bias).
        const ContextLightSampler *within = area_lights_.for_light(*sl.light);
        const DirectionSample ds = within ? within->sample({pt.p, pt.n}, u, Le) : sl.light->sample_direction(pt.p, u, Le);
        if (!(ds.pdf > 0) || is_black(Le)) return Color(0.f);
        sampled = PathVertex{};
        sampled.kind = VertexKind::Light;
        sampled.mode = TransportMode::Importance;
        sampled.light = sl.light;
        if (ds.dist >= kInfinity) {
            sampled.infinite = true;
            sampled.dir = ds.d;
        } else {
            sampled.p = ds.p;
            sampled.n = ds.n;
            sampled.si.p = ds.p;
            sampled.si.n = ds.n;
            if (sampled.on_surface()) sampled.si.sh_frame = Frame(ds.ns);
        }
        sampled.beta = Le / (sl.pmf * ds.pdf);
        sampled.pdf_fwd = pdf_light_origin(ctx_, sampled, pt);
        L = pt.beta * scatter(pt, ds.d) * sampled.beta;
        to = &sampled;
    } else {
        const PathVertex &qs = light[s - 1];
        if (!qs.connectible() || !pt.connectible()) return Color(0.f);
        const Vec3 d = qs.p - pt.p;
        const float dist2 = squared_norm(d);
        if (!(dist2 > 0)) return Color(0.f);
        const Vec3 w = d / std::sqrt(dist2);
        L = qs.beta * scatter(qs, -w) * scatter(pt, w) * pt.beta / dist2;
        to = &qs;
    }
    if (is_black(L)) return Color(0.f);
    const bool weighted = options_.strategy_s < 0 ? !options_.light_tracer : options_.strategy_mis;
    // The MIS weight walks the whole path, the larger part of a connection's cost, and most connections
    // of a scene with hard visibility are occluded: unless the shadow-ray policy reads the contribution,
    // the weight is worked out after the test, and only where the test's weight is not zero.
    const bool weigh_first = weighted && (!test || queries_->reads_contribution());
    if (weigh_first) L *= mis_weight(light, camera, sampled, s, t);
    if (!test || is_black(L)) return L;
    ShadowQuery q;
    q.ray = connection_ray(*from, *to);
    q.from = from->p;
    q.to = to->infinite ? from->p + to->dir : to->p;  // a ray to the sky is mapped by its direction
    q.unoccluded = L;
    const float v = test_visibility(*queries_, *ctx_.scene, q, sampler, counters);
    if (v == 0.f) return Color(0.f);
    if (weighted && !weigh_first) L *= mis_weight(light, camera, sampled, s, t);
    return L * v;
}

void BDPTIntegrator::splat_light_path(const std::vector<PathVertex> &light, Sampler &sampler, RenderCounters &counters,
                                      SplatSink &splats, float scale) const {
    static const std::vector<PathVertex> no_camera(1);  // t = 1 reads camera[0] only through `sampled`
    for (int s = 1; s <= int(light.size()); ++s) {
        if (!wants(s, 1)) continue;
        Vec2 raster;
        const Color c = connect(light, no_camera, s, 1, sampler, counters, raster);
        if (is_black(c)) continue;
        if (splats.add(raster.x, raster.y, c * scale)) ++counters.splats;
        else ++counters.invalid_samples;
    }
}

const std::vector<PathVertex> &BDPTIntegrator::choose_light_path(const std::vector<PathVertex> &camera,
                                                                 const std::vector<PathVertex> &own, Sampler &sampler,
                                                                 float &weight) const {
    const size_t M = pool_.size();
    const int K = M == 0 ? 1 : options_.candidates;
    weight = 1.f;
    if (K == 1) return own;
    const VoxelGrid &grid = *shadow_->voxel_grid();
    const VisibilityMap &map = *shadow_->visibility_map();
    // The camera vertices a connection can start from (t >= 2), with their cells and throughputs.
    uint32_t cells[kMaxUnboundedVertices + 2];
    float lum[kMaxUnboundedVertices + 2];
    int n = 0;
    for (size_t i = 1; i < camera.size() && n < kScoreVertices; ++i)
        if (camera[i].connectible()) {
            cells[n] = grid.voxel_of(camera[i].p);
            lum[n++] = luminance(camera[i].beta);
        }
    // Σ over connectible vertex pairs of Ṽ(camera vertex, light vertex) × both throughputs' luminance,
    // over the first kScoreVertices of each side.
    auto score_of = [&](const std::vector<PathVertex> &y, auto &&cell_of) {
        float sc = 0;
        for (size_t j = 1, used = 0; j < y.size() && used < size_t(kScoreVertices); ++j) {
            if (!y[j].connectible()) continue;
            ++used;
            const uint32_t cj = cell_of(j);
            float sj = 0;
            for (int i = 0; i < n; ++i) {
                const PairCounts c = map.counts(cells[i], cj);
                sj += lum[i] * (c.traced ? VisibilityMap::estimate(c) : 1.f);
            }
            sc += sj * luminance(y[j].beta);
        }
        return std::isfinite(sc) ? sc : 0.f;
    };
    // Candidate 0 is the camera sample's own light subpath, the others are drawn from the pool: all are
    // independent draws of a light subpath, so (1/K) Σ_k CONNECT(X, Y_k) estimates the same as CONNECT(X, Y),
    // and choosing one Y_k with probability p_k, weighted by 1 / (K p_k), estimates that.
    uint32_t chosen[64];
    float score[64], total = 0;
    score[0] = score_of(own, [&](size_t j) { return own[j].infinite ? 0u : grid.voxel_of(own[j].p); });
    total += score[0];
    for (int k = 1; k < K; ++k) {
        chosen[k] = uint32_t(std::min<size_t>(size_t(sampler.next_1d() * float(M)), M - 1));
        const std::vector<uint32_t> &ycells = pool_cells_[chosen[k]];
        score[k] = score_of(pool_[chosen[k]], [&](size_t j) { return ycells[j]; });
        total += score[k];
    }
    const float u = sampler.next_1d();
    float cdf = 0;
    int pick = K - 1;
    float p = 0;
    for (int k = 0; k < K; ++k) {
        const float pk = total > 0 ? (1.f - kUniformMix) * score[k] / total + kUniformMix / float(K) : 1.f / float(K);
        cdf += pk;
        if (u < cdf || k == K - 1) {
            pick = k;
            p = pk;
            break;
        }
    }
    weight = 1.f / (float(K) * p);
    return pick == 0 ? own : pool_[chosen[pick]];
}

uint64_t BDPTIntegrator::begin_pass(const Scene &scene, const PassInfo &pass, SplatFilm &splats,
                                    RenderCounters &counters) {
    if (!options_.neepp_selection) return 0;
    const size_t M = size_t(options_.pool);
    pool_.resize(M);
    pool_cells_.resize(M);
    const VoxelGrid &grid = *shadow_->voxel_grid();
    tbb::enumerable_thread_specific<RenderCounters> local;
    const std::unique_ptr<Sampler> prototype = make_sampler("independent", pass.seed ^ kPoolSeed);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, M, 64), [&](const tbb::blocked_range<size_t> &r) {
        std::unique_ptr<Sampler> sampler = prototype->clone();
        RenderCounters &c = local.local();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            sampler->start_sample(uint32_t(i), uint32_t(pass.pass_index), 0x9e3779b9u);
            light_subpath(ctx_, light_walk_, *sampler, pool_[i], c);
            pool_cells_[i].resize(pool_[i].size());
            for (size_t j = 0; j < pool_[i].size(); ++j)
                pool_cells_[i][j] = pool_[i][j].infinite ? 0u : grid.voxel_of(pool_[i][j].p);
            splat_light_path(pool_[i], *sampler, c, splats, 1.f);
        }
    });
    for (const RenderCounters &c : local) counters += c;
    pool_paths_traced_ += M;
    return M;
}

Color BDPTIntegrator::visible_environment(const Scene &scene, const Ray &ray, RenderCounters &counters) const {
    // No light path can reach a pinhole from the sky it sees, so light tracing alone leaves the sky black
    // where the camera sees it. The camera ray finds it (strategy s = 0, t = 2, which no light path
    // samples for an infinite light: nothing is counted twice). Mitsuba's ptracer splats it instead.
    if (options_.hide_emitters || options_.max_depth == 0 || scene.infinite_lights().empty()) return Color(0.f);
    SurfaceInteraction si;
    ++counters.rays;
    if (scene.intersect(ray, si)) return Color(0.f);
    Color Le(0.f);
    for (const Light *env : scene.infinite_lights()) Le += env->eval_environment(ray.d);
    return Le;
}

Color BDPTIntegrator::Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters,
                         SplatSink &splats) const {
    thread_local std::vector<PathVertex> camera, light;
    // Each part of the sample on its own stream (Sampler::use_stream): PSSMLT's mutations stay local.
    if (options_.light_tracer) {
        sampler.use_stream(SampleStream::Light);
        light_subpath(ctx_, light_walk_, sampler, light, counters);
        sampler.use_stream(SampleStream::Connection);
        splat_light_path(light, sampler, counters, splats, 1.f);
        return visible_environment(scene, ray, counters);
    }
    sampler.use_stream(SampleStream::Camera);
    camera_subpath(ctx_, ray, camera_walk_, sampler, camera, counters);
    sampler.use_stream(SampleStream::Light);
    light_subpath(ctx_, light_walk_, sampler, light, counters);
    sampler.use_stream(SampleStream::Connection);
    Color L(0.f);
    // With NEE++ the s >= 2, t >= 2 connections go to the light subpath chosen among this one and K - 1
    // from the pool (s = 0 and s = 1 need no light subpath: they keep this one, as t = 1 does).
    float selection_weight = 1.f;
    const std::vector<PathVertex> &chosen =
        options_.neepp_selection ? choose_light_path(camera, light, sampler, selection_weight) : light;
    const int nc = int(camera.size());
    for (int t = 1; t <= nc; ++t) {
        // Camera connections of the light path (t = 1): splatted.
        if (t == 1) {
            splat_light_path(light, sampler, counters, splats, 1.f);
            continue;
        }
        if (wants(0, t)) {
            Vec2 unused;
            L += connect(light, camera, 0, t, sampler, counters, unused);
        }
        if (wants(1, t)) {
            Vec2 unused;
            L += connect(light, camera, 1, t, sampler, counters, unused);
        }
        for (int s = 2; s <= int(chosen.size()); ++s) {
            if (!wants(s, t)) continue;
            Vec2 unused;
            L += connect(chosen, camera, s, t, sampler, counters, unused) * selection_weight;
        }
    }
    return L;
}

}  // namespace neepp
