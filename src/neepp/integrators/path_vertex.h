// Vertices of the subpaths bidirectional methods build (BDPT, light tracing), and the densities their MIS
// weights need: Veach's formulation, in the shape of pbrt's BDPT. Each vertex keeps the area density with
// which its own subpath reached it (pdf_fwd) and the one with which the other direction would have
// (pdf_rev); vertices on infinite lights keep solid-angle densities instead, since they are directions.
#pragma once
#include <vector>
#include "neepp/base/bsdf.h"
#include "neepp/base/interaction.h"
#include "neepp/base/light_sampler.h"
#include "neepp/base/stats.h"

namespace neepp {

class Scene;
class Sampler;
struct Camera;

enum class VertexKind : uint8_t { Camera, Light, Surface };

struct PathVertex {
    VertexKind kind = VertexKind::Surface;
    TransportMode mode = TransportMode::Radiance;
    bool delta = false;     // scattered by a delta lobe: no strategy can join the path at it
    bool infinite = false;  // on an infinite light: `dir` is its direction, there is no position
    // Throughput of the subpath up to and including this vertex; for a light endpoint, Le over the density
    // of choosing the light and the point (its direction factor is scatter()'s).
    Color beta{1.f};
    float pdf_fwd = 0, pdf_rev = 0;
    Vec3 p, n;              // position; geometric normal (zero for the camera and point lights)
    Vec3 dir;               // infinite vertices: unit direction from the scene toward the light
    // Surface vertices: the hit, wi toward the previous vertex of this subpath. Light endpoints on an area
    // light: p, n, the shading frame and uv, for evaluating the emission.
    SurfaceInteraction si;
    const Light *light = nullptr;  // light endpoints; surface vertices on an emitter: their area light

    bool on_surface() const { return n.x != 0.f || n.y != 0.f || n.z != 0.f; }
    // Whether a strategy may connect to this vertex: a delta BSDF (mirror, glass) has no density to
    // evaluate, a vertex on an infinite light has no position to aim a connection at, and a light at a
    // point is seen by no camera.
    bool connectible() const;
    // Emits (a light endpoint, or a surface vertex on an area light).
    bool is_light() const { return kind == VertexKind::Light || (kind == VertexKind::Surface && light); }
    bool is_delta_light() const { return kind == VertexKind::Light && light && light->is_delta(); }
};

// What the density and connection functions need to know of the scene: the camera, the light-choice
// distribution of light subpaths (which an emitter hit by a camera path must be weighed with), and the
// scene's bounding sphere (which infinite lights emit from).
struct BidirContext {
    const Scene *scene = nullptr;
    const Camera *camera = nullptr;
    const LightSampler *lights = nullptr;  // context-free: light subpaths choose their light before any point
    float disk_pdf = 0;                    // 1 / (pi r^2) of the scene's bounding sphere
};

// Unit direction from a to b (to b's light, if b is on an infinite one; from a's light if a is).
Vec3 direction_between(const PathVertex &a, const PathVertex &b);
// A solid-angle density at `from` toward `to` as a density of `to` (area measure; unchanged for a vertex
// on an infinite light).
float solid_angle_to_area(float pdf, const PathVertex &from, const PathVertex &to);
// f·|cos| at v toward direction w (world): the BSDF for surface vertices (with Veach's shading-normal
// correction on light subpaths); for light endpoints the emission's direction factor (|cos| on the
// emitting side of an area light), Le being in beta. Only connectible vertices are asked: a light at a
// point or at infinity gets zero.
Color scatter(const PathVertex &v, const Vec3 &w);
// Radiance a camera-path vertex on an emitter sends toward the previous vertex (the s = 0 strategy).
Color emitted_toward(const BidirContext &ctx, const PathVertex &v, const PathVertex &prev);
// Density (area measure at next) with which v, reached from prev, samples next; prev is unused for
// cameras and lights.
float pdf_next(const BidirContext &ctx, const PathVertex &v, const PathVertex *prev, const PathVertex &next);
// For an emitting vertex v: the density of an emitted ray from it reaching next (pdf_light), and that of
// a light subpath starting at v (pdf_light_origin: light choice times position density; for infinite
// lights, the direction density summed over them).
float pdf_light(const BidirContext &ctx, const PathVertex &v, const PathVertex &next);
float pdf_light_origin(const BidirContext &ctx, const PathVertex &v, const PathVertex &next);

struct WalkOptions {
    int max_vertices = 0;  // the subpath's vertex count at most, endpoint included
    int rr_depth = 5;
};

// Extends `path` (holding its endpoint) by tracing `ray` and sampling BSDFs, with throughput `beta` and
// the ray's direction density `pdf_dir`. Light subpaths (importance) count their queries as light_rays.
void random_walk(const BidirContext &ctx, Ray ray, Color beta, float pdf_dir, TransportMode mode,
                 const WalkOptions &options, Sampler &sampler, std::vector<PathVertex> &path, RenderCounters &counters);

// The camera subpath of a camera ray, and a light subpath (its light chosen by ctx.lights).
void camera_subpath(const BidirContext &ctx, const Ray &ray, const WalkOptions &options, Sampler &sampler,
                    std::vector<PathVertex> &path, RenderCounters &counters);
void light_subpath(const BidirContext &ctx, const WalkOptions &options, Sampler &sampler,
                   std::vector<PathVertex> &path, RenderCounters &counters);

}  // namespace neepp
