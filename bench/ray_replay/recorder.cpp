// Ray recorder: a library loaded into neepp with LD_PRELOAD that stands between the renderer and Embree.
// Each rtcIntersect{1,4,8,16} and rtcOccluded{1,4,8,16} call goes to Embree unchanged; the rays it
// asked for and their outcomes are appended to $NEEPP_RAY_RECORD_DIR/rays.<thread>.bin, so that
// neepp_ray_replay can trace the same rays in the same order with nothing else running.
// The renderer itself has no recording code: a render that does not preload this is untouched.
#include <embree3/rtcore.h>

#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "ray_record.h"

namespace {
using neepp::ray_replay::CallHeader;
using neepp::ray_replay::Query;
using neepp::ray_replay::RayRecord;

std::atomic<int> next_file{0};

// One file per thread. Each call is written whole with one write(2), unbuffered: the render's worker
// threads may still be alive when the process exits, so a stdio buffer's tail could be lost (it was, on
// about one run in ten), while a write that has returned is in the file.
struct ThreadFile {
    int fd = -1;
    std::vector<char> buffer;
    ThreadFile() {
        const char *dir = std::getenv("NEEPP_RAY_RECORD_DIR");
        const std::string path = std::string(dir ? dir : ".") + "/rays." + std::to_string(next_file++) + ".bin";
        fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0) {
            std::fprintf(stderr, "ray recorder: cannot write %s\n", path.c_str());
            std::abort();
        }
    }
    ~ThreadFile() { ::close(fd); }
    void write(Query query, int width, const RTCIntersectContext *ctx, const std::vector<RayRecord> &rays) {
        const CallHeader h{query, uint8_t(width), uint8_t((ctx->flags & RTC_INTERSECT_CONTEXT_FLAG_COHERENT) != 0), 0,
                           uint32_t(rays.size())};
        buffer.resize(sizeof h + rays.size() * sizeof(RayRecord));
        std::memcpy(buffer.data(), &h, sizeof h);
        std::memcpy(buffer.data() + sizeof h, rays.data(), rays.size() * sizeof(RayRecord));
        for (size_t done = 0; done < buffer.size();) {
            const ssize_t n = ::write(fd, buffer.data() + done, buffer.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                std::fprintf(stderr, "ray recorder: write failed: %s\n", std::strerror(errno));
                std::abort();
            }
            done += size_t(n);
        }
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

// An Embree packet call (rtcIntersectW or rtcOccludedW, on arg: RTCRayHitW or RTCRayW), recorded: the
// valid lanes' rays before the call, their outcomes (outcome(arg, lane)) after it.
template <int W, typename Arg, typename Outcome>
void packet(Query query, const char *name, const int *valid, RTCScene scene, RTCIntersectContext *ctx, Arg *arg,
            Outcome outcome) {
    static const auto call = real<void (*)(const int *, RTCScene, RTCIntersectContext *, Arg *)>(name);
    thread_local std::vector<RayRecord> rays;
    rays.clear();
    for (int i = 0; i < W; ++i)
        if (valid[i]) {
            if constexpr (requires { arg->hit; }) rays.push_back(lane(arg->ray, i));
            else rays.push_back(lane(*arg, i));
        }
    call(valid, scene, ctx, arg);
    for (int i = 0, k = 0; i < W; ++i)
        if (valid[i]) rays[k++].hit = outcome(*arg, i);
    out.write(query, W, ctx, rays);
}
const auto hit_something = [](const auto &rh, int i) { return rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID; };
const auto blocked = [](const auto &r, int i) { return r.tfar[i] < 0; };  // Embree sets tfar to -inf on a hit
}  // namespace

extern "C" {
void rtcIntersect1(RTCScene scene, RTCIntersectContext *ctx, RTCRayHit *rh) {
    static const auto call = real<void (*)(RTCScene, RTCIntersectContext *, RTCRayHit *)>("rtcIntersect1");
    std::vector<RayRecord> rays{single(rh->ray)};
    call(scene, ctx, rh);
    rays[0].hit = rh->hit.geomID != RTC_INVALID_GEOMETRY_ID;
    out.write(Query::Intersect, 1, ctx, rays);
}
void rtcOccluded1(RTCScene scene, RTCIntersectContext *ctx, RTCRay *r) {
    static const auto call = real<void (*)(RTCScene, RTCIntersectContext *, RTCRay *)>("rtcOccluded1");
    std::vector<RayRecord> rays{single(*r)};
    call(scene, ctx, r);
    rays[0].hit = r->tfar < 0;  // as blocked
    out.write(Query::Occluded, 1, ctx, rays);
}
// The packet entry points, one pair per width: exported C symbols, so spelled out by a macro.
#define NEEPP_RECORD_PACKETS(W)                                                                 \
    void rtcIntersect##W(const int *v, RTCScene s, RTCIntersectContext *c, RTCRayHit##W *rh) {   \
        packet<W>(Query::Intersect, "rtcIntersect" #W, v, s, c, rh, hit_something);             \
    }                                                                                           \
    void rtcOccluded##W(const int *v, RTCScene s, RTCIntersectContext *c, RTCRay##W *r) {       \
        packet<W>(Query::Occluded, "rtcOccluded" #W, v, s, c, r, blocked);                      \
    }
NEEPP_RECORD_PACKETS(4)
NEEPP_RECORD_PACKETS(8)
NEEPP_RECORD_PACKETS(16)
}
