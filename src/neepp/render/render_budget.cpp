#include "neepp/render/render_budget.h"

#include <algorithm>
#include <cmath>

namespace neepp {

// The first pass is one sample per pixel: a whole image early (what Ctrl-C leaves if it comes soon) and a
// first measure of the speed. An integrator that learns between passes (NEE++'s map) then gets small
// passes, so that it learns early, growing geometrically (capped) so per-pass overhead stays negligible.
// One that does not gets full passes at once: a pixel's samples in a pass are consecutive, so each packet
// of 16 rays the path tracer traces then starts from one pixel, and coherent rays are cheaper to trace.
// An interactive view (max_pass_s) caps a pass at what the last one's speed renders in that time.
//
// Under a time limit a pass is all or nothing, so it is sized twice over. It fits the time left at the
// last pass's speed, with a 5% margin. And it is finished even if the machine slows down twofold under it
// (another process, a loaded CI worker): twice its time ends before the overrun cut at kOverrunFactor
// times the limit. Sized to fit alone, a 32-spp pass of a short render on a machine that slowed down was
// cut and lost whole, most of the render's time; the second bound splits the time left into passes of at
// most about half of it until the end is near, a few more passes for a bounded loss.
int pass_size(const PassPacing &p) {
    constexpr int kMaxPass = 32;
    int size = p.done == 0 ? 1 : p.learns ? std::min(p.done, kMaxPass) : kMaxPass;
    if (p.max_pass_s > 0 && p.seconds_per_spp > 0)
        size = int(std::clamp(std::floor(p.max_pass_s / p.seconds_per_spp), 1.0, double(size)));
    if (p.target > 0) size = std::min(size, p.target - p.done);
    if (p.time_limit_s > 0 && p.seconds_per_spp > 0) {
        const double fits = 0.95 * p.remaining_s;
        const double survives_slowdown = 0.5 * (p.remaining_s + (kOverrunFactor - 1) * p.time_limit_s);
        size = int(std::min<double>(size, std::floor(std::min(fits, survives_slowdown) / p.seconds_per_spp)));
    }
    return size;
}

RenderBudget::RenderBudget(const RenderJob &job)
    : job_(job), start_(Clock::now()), time_before_(job.resume ? job.resume->render_time_s : 0.0) {}

double RenderBudget::elapsed() const {
    return time_before_ + std::chrono::duration<double>(Clock::now() - start_).count();
}

int RenderBudget::next_pass_size(int done, double seconds_per_spp, bool learns) const {
    return pass_size({done, job_.spp, seconds_per_spp, job_.time_limit_s, remaining(), learns, job_.max_pass_s});
}

bool RenderBudget::overrun(int passes_done) const {
    return timed() && elapsed() > (passes_done == 0 ? 1.0 : kOverrunFactor) * job_.time_limit_s;
}

double RenderBudget::fraction(double spp_done) const {
    if (timed() && job_.spp <= 0) return elapsed() / job_.time_limit_s;
    const int first = job_.resume ? 0 : job_.first_sample;
    const double f = (spp_done - first) / double(job_.spp - first);
    return timed() ? std::max(f, elapsed() / job_.time_limit_s) : f;
}

}  // namespace neepp
