// The file format shared by the ray recorder (an LD_PRELOAD library) and the replay tool: one file per
// render thread, a sequence of Embree calls as they were made, each a header and its rays' records.
#pragma once
#include <cstdint>

namespace neepp::ray_replay {

enum class Query : uint8_t { Intersect = 0, Occluded = 1 };

struct CallHeader {
    Query query;
    uint8_t width;     // 1, 4, 8 or 16: the Embree entry point called (rtcIntersect8, ...)
    uint8_t coherent;  // 1 when the call's context had RTC_INTERSECT_CONTEXT_FLAG_COHERENT
    uint8_t reserved = 0;
    uint32_t rays;     // the call's active rays, in lane order; as many RayRecords follow
};

struct RayRecord {
    float org[3], dir[3], tnear, tfar;
    uint32_t hit;  // the render's outcome: 1 when the ray hit something (Intersect) or was blocked (Occluded)
};

}  // namespace neepp::ray_replay
