#include "neepp/integrators/path_vertex.h"

#include "neepp/base/light.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"

namespace neepp {

bool PathVertex::connectible() const {
    switch (kind) {
    case VertexKind::Camera: return true;
    // A light at a point (point, spot, projector) is a delta in position: no camera sees it, as no camera
    // path can hit it (Mitsuba's ptracer never connects delta emitters to the sensor, and its path tracer
    // and neepp's never find them). Connecting one to the camera would splat its intensity, unshaped by
    // its emission profile, onto the pixel it projects to.
    case VertexKind::Light: return !infinite && !(light && light->is_delta());
    case VertexKind::Surface: return (si.shape->bsdf_flags & BSDFSmooth) != 0;
    }
    return false;
}

Vec3 direction_between(const PathVertex &a, const PathVertex &b) {
    if (b.infinite) return b.dir;
    if (a.infinite) return -a.dir;
    return normalize(b.p - a.p);
}

float solid_angle_to_area(float pdf, const PathVertex &from, const PathVertex &to) {
    if (to.infinite) return pdf;
    const Vec3 d = to.p - from.p;
    const float dist2 = squared_norm(d);
    if (!(dist2 > 0)) return 0.f;
    if (to.on_surface()) pdf *= std::abs(dot(to.n, d)) / std::sqrt(dist2);
    return pdf / dist2;
}

namespace {

// The shading normal of a vertex's surface (an area light's too); zero where there is none.
Vec3 shading_normal(const PathVertex &v) { return v.on_surface() ? v.si.sh_frame.n : Vec3(0.f); }

// Veach's correction for shading normals when importance is transported (Veach's thesis §5.3): the
// adjoint of a BSDF evaluated with a shading normal is not the BSDF itself, it is that times
// |wi·ns| |wo·ng| / (|wi·ng| |wo·ns|). Without it light tracing and BDPT disagree with path tracing on
// meshes with vertex normals (pbrt-v4 issues #13 and #385). wi toward the light, wo toward the camera.
float shading_correction(const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) {
    const float num = std::abs(dot(wi, si.sh_frame.n) * dot(wo, si.n));
    const float den = std::abs(dot(wi, si.n) * dot(wo, si.sh_frame.n));
    return den > 0 ? num / den : 0.f;
}

}  // namespace

Color scatter(const PathVertex &v, const Vec3 &w) {
    switch (v.kind) {
    case VertexKind::Camera: return Color(0.f);
    case VertexKind::Light:
        if (v.infinite || !v.on_surface()) return Color(0.f);
        return dot(v.si.sh_frame.n, w) > 0 ? Color(std::abs(dot(v.n, w))) : Color(0.f);
    case VertexKind::Surface: {
        const SurfaceInteraction &si = v.si;
        Color f = si.shape->bsdf->eval(BSDFContext{v.mode}, si, si.wi, si.to_local(w));
        if (v.mode == TransportMode::Importance) f *= shading_correction(si, si.to_world(si.wi), w);
        return f;
    }
    }
    return Color(0.f);
}

Color emitted_toward(const BidirContext &ctx, const PathVertex &v, const PathVertex &prev) {
    if (v.infinite) {
        Color L(0.f);
        for (const Light *env : ctx.scene->infinite_lights()) L += env->eval_environment(v.dir);
        return L;
    }
    if (v.kind == VertexKind::Surface && v.light) return v.light->eval_surface(v.si, direction_between(v, prev));
    return Color(0.f);
}

float pdf_light(const BidirContext &ctx, const PathVertex &v, const PathVertex &next) {
    if (v.infinite) return next.on_surface() ? ctx.disk_pdf * std::abs(dot(next.n, v.dir)) : ctx.disk_pdf;
    const Vec3 d = next.p - v.p;
    const float dist2 = squared_norm(d);
    if (!(dist2 > 0) || !v.light) return 0.f;
    const Vec3 w = d / std::sqrt(dist2);
    float pdf = v.light->pdf_emission(v.p, v.n, shading_normal(v), w).dir / dist2;
    if (next.on_surface()) pdf *= std::abs(dot(next.n, w));
    return pdf;
}

float pdf_light_origin(const BidirContext &ctx, const PathVertex &v, const PathVertex &next) {
    if (v.infinite) {
        // The sky seen along a direction is every infinite light at once: any of them could have been
        // chosen and have emitted along it.
        float pdf = 0;
        for (const Light *env : ctx.scene->infinite_lights())
            pdf += ctx.lights->pmf({}, *env) * env->pdf_emission(Vec3(0.f), Vec3(0.f), Vec3(0.f), -v.dir).dir;
        return pdf;
    }
    if (!v.light) return 0.f;
    const EmissionDensity d = v.light->pdf_emission(v.p, v.n, shading_normal(v), direction_between(v, next));
    return ctx.lights->pmf({}, *v.light) * d.pos;
}

float pdf_next(const BidirContext &ctx, const PathVertex &v, const PathVertex *prev, const PathVertex &next) {
    if (v.kind == VertexKind::Light) return pdf_light(ctx, v, next);
    const Vec3 wn = direction_between(v, next);
    float pdf = 0;
    if (v.kind == VertexKind::Camera) {
        pdf = ctx.camera->pdf_direction(wn);
    } else {
        const SurfaceInteraction &si = v.si;
        pdf = si.shape->bsdf->pdf(BSDFContext{v.mode}, si, si.to_local(direction_between(v, *prev)), si.to_local(wn));
    }
    return solid_angle_to_area(pdf, v, next);
}

void random_walk(const BidirContext &ctx, Ray ray, Color beta, float pdf_dir, TransportMode mode,
                 const WalkOptions &options, Sampler &sampler, std::vector<PathVertex> &path, RenderCounters &counters) {
    const Scene &scene = *ctx.scene;
    float pdf_fwd = pdf_dir;
    Color throughput(1.f);  // the BSDFs' part of beta, for Russian roulette (a light path's beta holds Le)
    float eta = 1.f;
    while (int(path.size()) < options.max_vertices) {
        PathVertex v;
        v.mode = mode;
        ++counters.rays;
        if (mode == TransportMode::Importance) ++counters.light_rays;
        if (!scene.intersect(ray, v.si)) {
            // A camera path that leaves the scene ends on the sky: a vertex the s = 0 strategy can use.
            if (mode == TransportMode::Radiance && !scene.infinite_lights().empty()) {
                v.kind = VertexKind::Light;
                v.infinite = true;
                v.dir = ray.d;
                v.beta = beta;
                v.pdf_fwd = pdf_fwd;
                path.push_back(v);
            }
            break;
        }
        PathVertex &prev = path.back();
        const SurfaceInteraction &si = v.si;
        v.kind = VertexKind::Surface;
        v.p = si.p;
        v.n = si.n;
        v.light = si.shape->area_light;
        v.beta = beta;
        // After an infinite light the ray's density is the disk's, per unit area across the ray.
        v.pdf_fwd = prev.infinite ? ctx.disk_pdf * std::abs(dot(v.n, ray.d)) : solid_angle_to_area(pdf_fwd, prev, v);
        path.push_back(v);
        if (int(path.size()) >= options.max_vertices) break;

        PathVertex &cur = path.back();
        PathVertex &before = path[path.size() - 2];
        const BSDF &bsdf = *si.shape->bsdf;
        const float u1 = sampler.next_1d();
        const Vec2 u2 = sampler.next_2d();
        const BSDFSample bs = bsdf.sample(BSDFContext{mode}, cur.si, cur.si.wi, u1, u2);
        if (!bs.valid()) break;
        const Vec3 wo = cur.si.to_world(bs.wo);
        pdf_fwd = bs.pdf;
        float pdf_rev = bsdf.pdf(BSDFContext{flip(mode)}, cur.si, bs.wo, cur.si.wi);
        if (bs.sampled_flags & BSDFDelta) {
            cur.delta = true;
            pdf_fwd = pdf_rev = 0;
        }
        Color weight = bs.weight;
        if (mode == TransportMode::Importance) weight *= shading_correction(cur.si, cur.si.to_world(cur.si.wi), wo);
        beta *= weight;
        throughput *= weight;
        eta *= bs.eta;
        before.pdf_rev = solid_angle_to_area(pdf_rev, cur, before);
        // Russian roulette as the path integrator plays it (Mitsuba's rule), from rr_depth bounces.
        const int depth = int(path.size()) - 1;
        if (depth >= options.rr_depth) {
            const float q = std::min(max_component(throughput) * eta * eta, 0.95f);
            if (!(sampler.next_1d() < q)) break;
            beta /= q;
            throughput /= q;
        }
        if (!(max_component(beta) > 0)) break;
        ray = cur.si.spawn_ray(wo);
    }
}

void camera_subpath(const BidirContext &ctx, const Ray &ray, const WalkOptions &options, Sampler &sampler,
                    std::vector<PathVertex> &path, RenderCounters &counters) {
    path.clear();
    PathVertex c;
    c.kind = VertexKind::Camera;
    c.p = ctx.camera->position();
    path.push_back(c);
    random_walk(ctx, ray, Color(1.f), ctx.camera->pdf_direction(ray.d), TransportMode::Radiance, options, sampler,
                path, counters);
}

void light_subpath(const BidirContext &ctx, const WalkOptions &options, Sampler &sampler,
                   std::vector<PathVertex> &path, RenderCounters &counters) {
    path.clear();
    const SampledLight sl = ctx.lights->sample({}, sampler.next_1d());
    const Vec2 u_pos = sampler.next_2d(), u_dir = sampler.next_2d();
    if (!sl.light || !(sl.pmf > 0) || options.max_vertices < 1) return;
    const EmissionSample es = sl.light->sample_emission(u_pos, u_dir);
    if (!es.valid()) return;
    PathVertex v;
    v.kind = VertexKind::Light;
    v.mode = TransportMode::Importance;
    v.light = sl.light;
    v.beta = es.radiance / (sl.pmf * es.pdf_pos);
    float cos_emit = 1.f;
    if (sl.light->is_infinite()) {
        v.infinite = true;
        v.dir = -es.ray.d;
    } else {
        v.p = es.p;
        v.n = es.n;
        v.si.p = es.p;
        v.si.n = es.n;
        v.si.sh_frame = Frame(es.ns);
        v.si.uv = es.uv;
        if (v.on_surface()) cos_emit = std::abs(dot(es.n, es.ray.d));
    }
    // The density of starting here: light choice times position, or for the sky, its direction density
    // summed over the infinite lights (the `next` argument is not read for them).
    v.pdf_fwd = v.infinite ? pdf_light_origin(ctx, v, v) : sl.pmf * es.pdf_pos;
    path.push_back(v);
    random_walk(ctx, es.ray, v.beta * (cos_emit / es.pdf_dir), es.pdf_dir, TransportMode::Importance, options, sampler,
                path, counters);
}

}  // namespace neepp
