#include "neepp/scene/scene.h"

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "neepp/math/transpose.h"

namespace neepp {
namespace {

// Embree calls this from C code, so it must not throw; build() checks the device error afterwards.
void embree_error(void *, RTCError code, const char *message) {
    std::fprintf(stderr, "Embree error %d: %s\n", int(code), message ? message : "");
}

// Embree's ray for ours: no motion time, the mask of the surfaces it sees (every bit: all), no flags.
void to_embree(const Ray &ray, RTCRay &r, uint32_t mask = 0xFFFFFFFFu) {
    r.org_x = ray.o.x; r.org_y = ray.o.y; r.org_z = ray.o.z;
    r.dir_x = ray.d.x; r.dir_y = ray.d.y; r.dir_z = ray.d.z;
    r.tnear = ray.tmin; r.tfar = ray.tmax;
    r.time = 0; r.mask = mask; r.id = 0; r.flags = 0;
}

// Embree's packet types and calls for a packet width W (4, 8 or 16 lanes).
template <int W> struct Packet;
template <> struct Packet<4> {
    using Rays = RTCRay4;
    using Hits = RTCRayHit4;
    static void intersect(const int *v, RTCScene s, RTCIntersectContext *c, Hits *h) { rtcIntersect4(v, s, c, h); }
    static void occluded(const int *v, RTCScene s, RTCIntersectContext *c, Rays *r) { rtcOccluded4(v, s, c, r); }
};
template <> struct Packet<8> {
    using Rays = RTCRay8;
    using Hits = RTCRayHit8;
    static void intersect(const int *v, RTCScene s, RTCIntersectContext *c, Hits *h) { rtcIntersect8(v, s, c, h); }
    static void occluded(const int *v, RTCScene s, RTCIntersectContext *c, Rays *r) { rtcOccluded8(v, s, c, r); }
};
template <> struct Packet<16> {
    using Rays = RTCRay16;
    using Hits = RTCRayHit16;
    static void intersect(const int *v, RTCScene s, RTCIntersectContext *c, Hits *h) { rtcIntersect16(v, s, c, h); }
    static void occluded(const int *v, RTCScene s, RTCIntersectContext *c, Rays *r) { rtcOccluded16(v, s, c, r); }
};

// A packet of rays[0..n), n <= W; the lanes beyond n repeat ray 0 and are marked invalid. The fields that
// are the same in every lane are written whole (whole-vector stores), the rays lane by lane.
template <int W, typename RaysW>
void to_embree_packet(const Ray *const *rays, int n, RaysW &r, int *valid) {
    std::fill_n(r.time, W, 0.f);
    std::fill_n(r.mask, W, 0xFFFFFFFFu);
    std::fill_n(r.id, W, 0u);
    std::fill_n(r.flags, W, 0u);
    for (int i = 0; i < W; ++i) valid[i] = i < n ? -1 : 0;
#if defined(__AVX__)
    // A ray is 8 floats in the order of 8 of the packet's arrays: eight rays are one transpose.
    if constexpr (W % 8 == 0) {
        static_assert(sizeof(Ray) == 32 && offsetof(Ray, d) == 12 && offsetof(Ray, tmin) == 24);
        float *const fields[8] = {r.org_x, r.org_y, r.org_z, r.dir_x, r.dir_y, r.dir_z, r.tnear, r.tfar};
        for (int b = 0; b < W; b += 8) {
            __m256 v[8];
            for (int i = 0; i < 8; ++i)
                v[i] = _mm256_loadu_ps(reinterpret_cast<const float *>(rays[b + i < n ? b + i : 0]));
            transpose8(v);
            for (int k = 0; k < 8; ++k) _mm256_store_ps(fields[k] + b, v[k]);
        }
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        const Ray &ray = *rays[i < n ? i : 0];
        r.org_x[i] = ray.o.x; r.org_y[i] = ray.o.y; r.org_z[i] = ray.o.z;
        r.dir_x[i] = ray.d.x; r.dir_y[i] = ray.d.y; r.dir_z[i] = ray.d.z;
        r.tnear[i] = ray.tmin; r.tfar[i] = ray.tmax;
    }
}

// A query context; coherent asks for Embree's traversal for rays that leave one pixel or a few neighbours.
RTCIntersectContext intersect_context(bool coherent) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    if (coherent) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return ctx;
}

// Up to 16 rays as packets of W.
template <int W>
void intersect_packets(RTCScene scene, const Ray *const *rays, RayHit *const *hits, int n, bool coherent) {
    RTCIntersectContext ctx = intersect_context(coherent);
    for (int b = 0; b < n; b += W) {
        const int m = std::min(W, n - b);
        alignas(64) int valid[W];
        alignas(64) typename Packet<W>::Hits rh;
        to_embree_packet<W>(rays + b, m, rh.ray, valid);
        std::fill_n(rh.hit.geomID, W, RTC_INVALID_GEOMETRY_ID);
        std::fill_n(rh.hit.instID[0], W, RTC_INVALID_GEOMETRY_ID);
        Packet<W>::intersect(valid, scene, &ctx, &rh);
        for (int i = 0; i < m; ++i) {
            RayHit &hit = *hits[b + i];
            hit = RayHit();
            if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
            hit.t = rh.ray.tfar[i], hit.u = rh.hit.u[i], hit.v = rh.hit.v[i];
            hit.geom = rh.hit.geomID[i], hit.prim = rh.hit.primID[i];
        }
    }
}

template <int W>
void occluded_packets(RTCScene scene, const Ray *const *rays, int n, bool *occluded, bool coherent) {
    RTCIntersectContext ctx = intersect_context(coherent);
    for (int b = 0; b < n; b += W) {
        const int m = std::min(W, n - b);
        alignas(64) int valid[W];
        alignas(64) typename Packet<W>::Rays r;
        to_embree_packet<W>(rays + b, m, r, valid);
        Packet<W>::occluded(valid, scene, &ctx, &r);
        for (int i = 0; i < m; ++i) occluded[b + i] = r.tfar[i] < 0;  // Embree sets tfar to -inf on a hit
    }
}

// f(std::integral_constant<int, W>{}) for the packet width W (16, 8, else 4): one switch for both queries.
template <typename F>
void with_packet_width(int width, F &&f) {
    switch (width) {
    case 16: return f(std::integral_constant<int, 16>{});
    case 8: return f(std::integral_constant<int, 8>{});
    default: return f(std::integral_constant<int, 4>{});
    }
}

}  // namespace

Scene::Scene() {
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("could not create an Embree device");
    rtcSetDeviceErrorFunction(device_, embree_error, nullptr);
    // The widest packet this CPU's Embree kernels trace natively. A wider one is split by Embree's
    // stream path, which traces slower than packets of the native width.
    packet_width_ = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? 16
                    : rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? 8
                                                                                               : 4;
}

void Scene::set_packet_width(int width) {
    if (width != 4 && width != 8 && width != 16)
        throw std::invalid_argument("packet width must be 4, 8 or 16, not " + std::to_string(width));
    packet_width_ = width;
}

Scene::~Scene() {
    if (rtc_scene_) rtcReleaseScene(rtc_scene_);
    if (device_) rtcReleaseDevice(device_);
}

void Scene::add_shape(std::unique_ptr<Shape> shape) { shapes_.push_back(std::move(shape)); }

const Medium *Scene::add_medium(std::shared_ptr<const Medium> medium) {
    for (const auto &m : media_)
        if (m == medium) return m.get();
    media_.push_back(std::move(medium));
    return media_.back().get();
}

const Light *Scene::add_light(LightPtr light) {
    light->index = uint32_t(lights_.size());
    lights_.push_back(std::move(light));
    return lights_.back().get();
}

std::vector<const Light *> Scene::light_pointers() const {
    std::vector<const Light *> r;
    for (const auto &l : lights_) r.push_back(l.get());
    return r;
}

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const auto &s : shapes_) n += s->triangle_count();
    return n;
}

void Scene::build() {
    if (shapes_.empty() && lights_.empty()) throw std::runtime_error("the scene is empty: no shapes and no lights");
    rtc_scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(rtc_scene_, RTC_BUILD_QUALITY_HIGH);
    bounds_ = BBox();
    meshes_.assign(shapes_.size(), nullptr);
    passable_surfaces_ = false;
    for (size_t i = 0; i < shapes_.size(); ++i) {
        Shape &s = *shapes_[i];
        s.finalize();
        passable_surfaces_ |= (s.bsdf_flags & BSDFNull) != 0;
        meshes_[i] = dynamic_cast<const TriangleMesh *>(&s);
        RTCGeometry geom = s.embree_geometry(device_);
        if (!geom) continue;  // nothing to intersect; kept so ids stay stable
        rtcSetGeometryMask(geom, uint32_t((s.bsdf_flags & BSDFNull) ? Surfaces::Passable : Surfaces::Opaque));
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(rtc_scene_, geom, unsigned(i));
        rtcReleaseGeometry(geom);
        bounds_.expand(s.bounds());
    }
    rtcCommitScene(rtc_scene_);
    if (RTCError err = rtcGetDeviceError(device_); err != RTC_ERROR_NONE)
        throw std::runtime_error("Embree failed to build the scene (error " + std::to_string(int(err)) + ")");
    if (!bounds_.valid()) bounds_ = BBox{Vec3(-1.f), Vec3(1.f)};
    infinite_lights_.clear();
    for (auto &l : lights_) {
        l->prepare(bounds_);
        if (l->is_infinite()) infinite_lights_.push_back(l.get());
    }
}

RayHit Scene::trace(const Ray &ray, Surfaces seen) const {
    RTCIntersectContext ctx = intersect_context(false);
    RTCRayHit rh;
    to_embree(ray, rh.ray, uint32_t(seen));
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc_scene_, &ctx, &rh);
    RayHit hit;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    hit.t = rh.ray.tfar, hit.u = rh.hit.u, hit.v = rh.hit.v;
    hit.geom = rh.hit.geomID, hit.prim = rh.hit.primID;
    return hit;
}

void Scene::trace16(const Ray *const *rays, RayHit *const *hits, int n, bool coherent) const {
    with_packet_width(packet_width_, [&](auto w) { intersect_packets<w()>(rtc_scene_, rays, hits, n, coherent); });
}

bool Scene::intersect(const Ray &ray, SurfaceInteraction &si, Surfaces seen) const {
    const RayHit hit = trace(ray, seen);
    if (!hit.valid()) {
        si.shape = nullptr;
        return false;
    }
    fill(hit, ray, si);
    return true;
}

void Scene::occluded16(const Ray *const *rays, int n, bool *occluded, bool coherent) const {
    with_packet_width(packet_width_, [&](auto w) { occluded_packets<w()>(rtc_scene_, rays, n, occluded, coherent); });
}

bool Scene::occluded(const Ray &ray, Surfaces seen) const {
    RTCIntersectContext ctx = intersect_context(false);
    RTCRay r;
    to_embree(ray, r, uint32_t(seen));
    rtcOccluded1(rtc_scene_, &ctx, &r);
    return r.tfar < 0;  // Embree sets tfar to -inf on a hit
}

}  // namespace neepp
