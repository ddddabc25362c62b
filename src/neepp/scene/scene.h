// The scene: shapes in an Embree BVH, lights, camera and the render settings read from the scene file.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>
#include <embree3/rtcore.h>
#include "neepp/base/light.h"
#include "neepp/base/medium.h"
#include "neepp/scene/camera.h"
#include "neepp/base/shape.h"
#include "neepp/shapes/hit_lanes.h"
#include "neepp/shapes/triangle_mesh.h"

namespace neepp {

// Settings a Mitsuba scene file carries besides geometry (integrator, sampler, film, filter).
struct RenderSettings {
    std::string integrator = "path";
    std::map<std::string, std::string> integrator_options;  // as written in the file, e.g. max_depth=17
    std::string sampler = "independent";
    int spp = 16;
    uint64_t seed = 0;
    std::string rfilter = "gaussian";  // Mitsuba's hdrfilm default
    float rfilter_radius = 2.f;        // box 0.5, tent 1, gaussian 4 * stddev (0.5)
    float rfilter_stddev = 0.5f;
};

// What Embree reports for a ray before the hit record is filled in. Kept apart so that a batch of paths
// can trace all its rays first and fill their hit records after the triangle data those need has been
// prefetched (TriangleMesh::prefetch).
struct RayHit {
    static constexpr uint32_t kNone = ~0u;
    float t = kInfinity, u = 0, v = 0;
    uint32_t geom = kNone, prim = 0;
    bool valid() const { return geom != kNone; }
};

class Scene {
public:
    Scene();
    ~Scene();
    Scene(const Scene &) = delete;
    Scene &operator=(const Scene &) = delete;

    void add_shape(std::unique_ptr<Shape> shape);
    // Takes ownership of a light; area lights should be added through add_area_light.
    const Light *add_light(LightPtr light);
    // Finalizes shapes, builds the Embree scene and tells lights the scene bounds. Throws on an empty scene.
    void build();

    // Which surfaces a query sees: all of them, or only those that stop shadow rays (opaque) or only those
    // that may let them through (passable: a BSDF with BSDFNull). Shadow rays through media ask first
    // whether an opaque surface blocks them, and walk the passable ones only if none does.
    enum class Surfaces : uint32_t { All = 0xFFFFFFFFu, Opaque = 1u, Passable = 2u };
    bool intersect(const Ray &ray, SurfaceInteraction &si, Surfaces seen = Surfaces::All) const;  // trace + fill
    RayHit trace(const Ray &ray, Surfaces seen = Surfaces::All) const;
    // trace() of up to 16 rays at once, as Embree packets of packet_width(); coherent: the rays start
    // close together in similar directions (camera rays of a few neighbouring pixels), so Embree may use
    // its coherent traversal (it saves work for camera rays; for shadow rays toward lights it costs more).
    void trace16(const Ray *const *rays, RayHit *const *hits, int n, bool coherent = false) const;
    // Prefetches what fill() will read for hit (its triangle's record). A hint: no effect on results.
    void prefetch(const RayHit &hit) const {
        if (!hit.valid()) return;
        if (const TriangleMesh *mesh = meshes_[hit.geom]) mesh->prefetch(hit.prim);
    }
    void fill(const RayHit &hit, const Ray &ray, SurfaceInteraction &si) const {
        if (const TriangleMesh *mesh = meshes_[hit.geom]) mesh->fill_interaction(hit.prim, hit.u, hit.v, ray, hit.t, si);
        else shapes_[hit.geom]->fill_interaction(hit.prim, hit.u, hit.v, ray, hit.t, si);
        si.wi = si.to_local(-ray.d);
    }
    // fill(), or, for a hit that can be, queued in lanes to be filled with seven others (HitLanes):
    // si is complete after the eighth, or fill_lanes.
    void fill_in_lanes(HitLanes &lanes, const RayHit &hit, const Ray &ray, SurfaceInteraction &si) const {
        const TriangleMesh *mesh = meshes_[hit.geom];
        if (mesh && mesh->fills_in_lanes()) add_lane(lanes, *mesh, hit.prim, hit.u, hit.v, hit.t, ray.d, si);
        else fill(hit, ray, si);
    }
    bool occluded(const Ray &ray, Surfaces seen = Surfaces::All) const;
    // Up to 16 rays, as packets; coherent as for trace16. The path tracer does not set it: even the shadow
    // rays of the first hits, which leave one pixel, trace slower with it (bench/ray_replay).
    void occluded16(const Ray *const *rays, int n, bool *occluded, bool coherent = false) const;
    // The lanes of the packets trace16 and occluded16 give Embree: the widest this CPU traces natively
    // (16 with AVX-512, 8 with AVX2, else 4). Settable (4, 8, 16) for tests and measurements.
    int packet_width() const { return packet_width_; }
    void set_packet_width(int width);

    // Keeps a medium that shapes and the camera point to.
    const Medium *add_medium(std::shared_ptr<const Medium> medium);
    bool has_media() const { return !media_.empty(); }
    const std::vector<std::shared_ptr<const Medium>> &media() const { return media_; }
    // Whether some surface lets a shadow ray through (a null, thin dielectric or mask BSDF: BSDFNull).
    bool has_passable_surfaces() const { return passable_surfaces_; }
    const std::vector<std::unique_ptr<Shape>> &shapes() const { return shapes_; }
    const std::vector<LightPtr> &lights() const { return lights_; }
    std::vector<const Light *> light_pointers() const;
    const std::vector<const Light *> &infinite_lights() const { return infinite_lights_; }
    const BBox &bounds() const { return bounds_; }
    size_t triangle_count() const;

    Camera camera;
    RenderSettings settings;
    std::string source_path;  // scene file it came from, for messages and statistics

private:
    RTCDevice device_ = nullptr;
    RTCScene rtc_scene_ = nullptr;
    int packet_width_ = 16;
    std::vector<std::unique_ptr<Shape>> shapes_;
    // shapes_[i] where it is a triangle mesh, else null: the fast form's hits on meshes (most hits) are
    // prefetched, filled in lanes and filled without a virtual call.
    std::vector<const TriangleMesh *> meshes_;
    std::vector<LightPtr> lights_;
    std::vector<std::shared_ptr<const Medium>> media_;
    bool passable_surfaces_ = false;
    std::vector<const Light *> infinite_lights_;
    BBox bounds_;
};

}  // namespace neepp
