// How long a render may go on (its sample count or time limit) and how many samples per pixel each pass
// takes: the render loop's pacing, apart from the loop so that it can be tested alone.
#pragma once
#include <chrono>
#include "neepp/render/render_loop.h"

namespace neepp {

// A time-limited pass is cut short (and its samples thrown away) only once the render runs this far past
// its limit: before that, a pass sized to fit is finished even when the machine slows down under it.
constexpr double kOverrunFactor = 1.25;

// What the next pass's size depends on.
struct PassPacing {
    int done = 0;                // samples per pixel so far
    int target = 0;              // samples per pixel to reach; 0 = as many as the time limit allows
    double seconds_per_spp = 0;  // the last pass's speed; 0 = not measured yet
    double time_limit_s = 0;     // 0 = none
    double remaining_s = 0;      // of the time limit
    bool learns = false;         // the integrator learns between passes (NEE++'s map)
    double max_pass_s = 0;       // an interactive view's cap on a pass; 0 = none
};

// Samples per pixel in the next pass (0: the render is done). See render_budget.cpp.
int pass_size(const PassPacing &p);

class RenderBudget {
public:
    explicit RenderBudget(const RenderJob &job);
    bool timed() const { return job_.time_limit_s > 0; }
    // Seconds of rendering, a resumed render's earlier ones included.
    double elapsed() const;
    double remaining() const { return timed() ? job_.time_limit_s - elapsed() : 0; }
    bool spp_reached(int spp) const { return job_.spp > 0 && spp >= job_.spp; }
    int next_pass_size(int done, double seconds_per_spp, bool learns) const;
    // A time limit cuts a pass short only when it overruns badly: the first pass, whose speed was unknown,
    // at the limit; a later one, sized to fit, at kOverrunFactor times it.
    bool overrun(int passes_done) const;
    // The fraction done, for the progress bar: of the sample range, or of the time.
    double fraction(double spp_done) const;

private:
    using Clock = std::chrono::steady_clock;
    const RenderJob &job_;
    const Clock::time_point start_;
    const double time_before_;
};

}  // namespace neepp
