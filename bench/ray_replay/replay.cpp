// neepp_ray_replay: traces a recorded render's rays (see recorder.cpp) again with nothing but Embree,
// to measure what the ray queries alone cost: the floor under the render's time per sample.
//
//   neepp_ray_replay SCENE.xml [-D name=value]... [--reps N] RAYFILE...
//
// The scene is loaded and built exactly as neepp render does (same loader, same Embree build settings).
// Each file is one render thread's calls, replayed in order on a thread of its own, all at once; each
// rep times every way of tracing: as the render's own packets (Scene::trace16/occluded16, the same
// grouping of rays, with the coherent flag where the render gave it), and one ray at a time
// (rtcIntersect1/rtcOccluded1). Every replayed outcome is
// checked against the one recorded in the render. Prints JSON.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "neepp/loader/scene_loader.h"
#include "neepp/scene/scene.h"
#include "ray_record.h"

namespace {
using namespace neepp;
using namespace neepp::ray_replay;

struct Call {
    Query query;
    bool coherent;     // traced with Embree's coherent flag in the render (camera rays), and so again
    int first, count;  // its rays in Stream::rays
};

struct Stream {
    std::vector<Call> calls;
    std::vector<Ray> rays;
    std::vector<uint8_t> recorded;  // the render's outcome per ray
};

Stream read_stream(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path);
    Stream s;
    CallHeader h;
    while (in.read(reinterpret_cast<char *>(&h), sizeof h)) {
        if ((h.query != Query::Intersect && h.query != Query::Occluded) || h.coherent > 1 || h.rays > 16)
            throw std::runtime_error(path + ": not a ray record file (bad call header)");
        s.calls.push_back({h.query, h.coherent != 0, int(s.rays.size()), int(h.rays)});
        for (uint32_t i = 0; i < h.rays; ++i) {
            RayRecord r;
            if (!in.read(reinterpret_cast<char *>(&r), sizeof r)) throw std::runtime_error(path + ": truncated");
            s.rays.push_back(Ray{Vec3(r.org[0], r.org[1], r.org[2]), Vec3(r.dir[0], r.dir[1], r.dir[2]), r.tnear, r.tfar});
            s.recorded.push_back(uint8_t(r.hit));
        }
    }
    return s;
}

enum class Mode { Packets, Single };

// Replays one stream; returns the outcomes that differ from the recorded ones.
size_t replay(const Scene &scene, const Stream &s, Mode mode, std::vector<uint8_t> &outcome) {
    outcome.assign(s.rays.size(), 0);
    for (const Call &c : s.calls) {
        for (int b = 0; b < c.count; b += 16) {  // a call has at most 16 rays; Scene's queries take 16
            const int m = std::min(16, c.count - b);
            const Ray *rs[16];
            RayHit hits[16];
            RayHit *hs[16];
            bool occluded[16];
            for (int i = 0; i < m; ++i) rs[i] = &s.rays[c.first + b + i], hs[i] = &hits[i];
            uint8_t *o = &outcome[c.first + b];
            if (mode == Mode::Packets) {
                if (c.query == Query::Intersect) {
                    scene.trace16(rs, hs, m, c.coherent);
                    for (int i = 0; i < m; ++i) o[i] = hits[i].valid();
                } else {
                    scene.occluded16(rs, m, occluded, c.coherent);
                    for (int i = 0; i < m; ++i) o[i] = occluded[i];
                }
            } else {
                for (int i = 0; i < m; ++i)
                    o[i] = c.query == Query::Intersect ? scene.trace(*rs[i]).valid() : scene.occluded(*rs[i]);
            }
        }
    }
    size_t differ = 0;
    for (size_t i = 0; i < outcome.size(); ++i) differ += outcome[i] != s.recorded[i];
    return differ;
}

}  // namespace

int main(int argc, char **argv) try {
    std::string scene_path;
    std::map<std::string, std::string> defines;
    std::vector<std::string> files;
    int reps = 3;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-D" && i + 1 < argc) {
            const std::string kv = argv[++i];
            const size_t eq = kv.find('=');
            if (eq == std::string::npos) throw std::runtime_error("-D needs name=value, not " + kv);
            defines[kv.substr(0, eq)] = kv.substr(eq + 1);
        } else if (a == "--reps" && i + 1 < argc) {
            reps = std::max(1, std::stoi(argv[++i]));
        } else if (scene_path.empty()) {
            scene_path = a;
        } else {
            files.push_back(a);
        }
    }
    if (scene_path.empty() || files.empty()) {
        std::fprintf(stderr, "usage: neepp_ray_replay SCENE.xml [-D name=value]... [--reps N] RAYFILE...\n");
        return 2;
    }
    const auto scene = load_scene(scene_path, defines);
    std::vector<Stream> streams;
    size_t counts[2] = {0, 0};
    for (const auto &f : files) {
        streams.push_back(read_stream(f));
        for (const Call &c : streams.back().calls) counts[int(c.query)] += size_t(c.count);
    }
    const char *names[2] = {"packets", "single"};
    std::vector<double> seconds[2];
    size_t mismatches[2] = {0, 0};
    for (int rep = 0; rep < reps; ++rep)
        for (Mode mode : {Mode::Packets, Mode::Single}) {
            std::vector<std::thread> threads;
            std::vector<size_t> differ(streams.size());
            std::vector<std::vector<uint8_t>> outcomes(streams.size());
            const auto t0 = std::chrono::steady_clock::now();
            for (size_t k = 0; k < streams.size(); ++k)
                threads.emplace_back([&, k] { differ[k] = replay(*scene, streams[k], mode, outcomes[k]); });
            for (auto &t : threads) t.join();
            seconds[int(mode)].push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            for (size_t d : differ) mismatches[int(mode)] = std::max(mismatches[int(mode)], d);
        }
    std::printf("{\"threads\": %zu, \"packet_width\": %d, \"intersect_rays\": %zu, \"occluded_rays\": %zu",
                streams.size(), scene->packet_width(), counts[0], counts[1]);
    for (int m = 0; m < 2; ++m) {
        std::sort(seconds[m].begin(), seconds[m].end());
        std::printf(", \"%s\": {\"seconds\": [", names[m]);
        for (size_t i = 0; i < seconds[m].size(); ++i) std::printf("%s%.6f", i ? ", " : "", seconds[m][i]);
        std::printf("], \"mismatches\": %zu}", mismatches[m]);
    }
    std::printf("}\n");
    return 0;
} catch (const std::exception &e) {
    std::fprintf(stderr, "neepp_ray_replay: %s\n", e.what());
    return 1;
}
