// Ray recorder: a library loaded into neepp with LD_PRELOAD that stands between the renderer and Embree.
// Each rtcIntersect{1,4,8,16} and rtcOccluded{1,4,8,16} call goes to Embree unchanged; the rays it
// asked for and their outcomes are appended to $NEEPP_RAY_RECORD_DIR/rays.<thread>.bin, so that
// neepp_ray_replay can trace the same rays in the same order with nothing else running.
// The renderer itself has no recording code: a render that does not preload this is untouched.
#include <embree3/rtcore.h>

#include <dlfcn.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ray_record.h"

namespace {
using neepp::ray_replay::CallHeader;
using neepp::ray_replay::Query;
using neepp::ray_replay::RayRecord;

std::atomic<int> next_file{0};

// One buffered file per thread, flushed when the thread or the process ends.
struct ThreadFile {
    FILE *file = nullptr;
    ThreadFile() {
        const char *dir = std::getenv("NEEPP_RAY_RECORD_DIR");
        const std::string path = std::string(dir ? dir : ".") + "/rays." + std::to_string(next_file++) + ".bin";
        file = std::fopen(path.c_str(), "wb");
        if (!file) {
            std::fprintf(stderr, "ray recorder: cannot write %s\n", path.c_str());
            std::abort();
        }
        std::setvbuf(file, nullptr, _IOFBF, 1 << 20);
    }
    ~ThreadFile() { std::fclose(file); }
    void write(Query query, int width, const std::vector<RayRecord> &rays) {
        const CallHeader h{query, uint8_t(width), uint16_t(rays.size())};
        std::fwrite(&h, sizeof h, 1, file);
        std::fwrite(rays.data(), sizeof(RayRecord), rays.size(), file);
    }
};
thread_local ThreadFile out;

template <typename F>
F real(const char *name) {
    F f = reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
    if (!f) {
        std::fprintf(stderr, "ray recorder: %s not found in Embree\n", name);
        std::abort();
    }
    return f;
}

// Lane i of an Embree ray packet (RTCRay{4,8,16} is a struct of arrays).
template <typename Packet>
RayRecord lane(const Packet &r, int i) {
    return {{r.org_x[i], r.org_y[i], r.org_z[i]}, {r.dir_x[i], r.dir_y[i], r.dir_z[i]}, r.tnear[i], r.tfar[i], 0};
}
RayRecord single(const RTCRay &r) {
    return {{r.org_x, r.org_y, r.org_z}, {r.dir_x, r.dir_y, r.dir_z}, r.tnear, r.tfar, 0};
}

template <int W, typename Hits>
void intersect_packet(const char *name, const int *valid, RTCScene scene, RTCIntersectContext *ctx, Hits *rh) {
    static const auto call = real<void (*)(const int *, RTCScene, RTCIntersectContext *, Hits *)>(name);
    thread_local std::vector<RayRecord> rays;
    rays.clear();
    for (int i = 0; i < W; ++i)
        if (valid[i]) rays.push_back(lane(rh->ray, i));
    call(valid, scene, ctx, rh);
    for (int i = 0, k = 0; i < W; ++i)
        if (valid[i]) rays[k++].hit = rh->hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    out.write(Query::Intersect, W, rays);
}

template <int W, typename Rays>
void occluded_packet(const char *name, const int *valid, RTCScene scene, RTCIntersectContext *ctx, Rays *r) {
    static const auto call = real<void (*)(const int *, RTCScene, RTCIntersectContext *, Rays *)>(name);
    thread_local std::vector<RayRecord> rays;
    rays.clear();
    for (int i = 0; i < W; ++i)
        if (valid[i]) rays.push_back(lane(*r, i));
    call(valid, scene, ctx, r);
    for (int i = 0, k = 0; i < W; ++i)
        if (valid[i]) rays[k++].hit = r->tfar[i] < 0;
    out.write(Query::Occluded, W, rays);
}
}  // namespace

extern "C" {
void rtcIntersect1(RTCScene scene, RTCIntersectContext *ctx, RTCRayHit *rh) {
    static const auto call = real<void (*)(RTCScene, RTCIntersectContext *, RTCRayHit *)>("rtcIntersect1");
    std::vector<RayRecord> rays{single(rh->ray)};
    call(scene, ctx, rh);
    rays[0].hit = rh->hit.geomID != RTC_INVALID_GEOMETRY_ID;
    out.write(Query::Intersect, 1, rays);
}
void rtcOccluded1(RTCScene scene, RTCIntersectContext *ctx, RTCRay *r) {
    static const auto call = real<void (*)(RTCScene, RTCIntersectContext *, RTCRay *)>("rtcOccluded1");
    std::vector<RayRecord> rays{single(*r)};
    call(scene, ctx, r);
    rays[0].hit = r->tfar < 0;
    out.write(Query::Occluded, 1, rays);
}
void rtcIntersect4(const int *v, RTCScene s, RTCIntersectContext *c, RTCRayHit4 *rh) { intersect_packet<4>("rtcIntersect4", v, s, c, rh); }
void rtcIntersect8(const int *v, RTCScene s, RTCIntersectContext *c, RTCRayHit8 *rh) { intersect_packet<8>("rtcIntersect8", v, s, c, rh); }
void rtcIntersect16(const int *v, RTCScene s, RTCIntersectContext *c, RTCRayHit16 *rh) { intersect_packet<16>("rtcIntersect16", v, s, c, rh); }
void rtcOccluded4(const int *v, RTCScene s, RTCIntersectContext *c, RTCRay4 *r) { occluded_packet<4>("rtcOccluded4", v, s, c, r); }
void rtcOccluded8(const int *v, RTCScene s, RTCIntersectContext *c, RTCRay8 *r) { occluded_packet<8>("rtcOccluded8", v, s, c, r); }
void rtcOccluded16(const int *v, RTCScene s, RTCIntersectContext *c, RTCRay16 *r) { occluded_packet<16>("rtcOccluded16", v, s, c, r); }
}
