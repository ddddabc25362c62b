#include "neepp/base/stats.h"

#include <time.h>
#include <chrono>
#include <thread>
#include <x86intrin.h>

namespace neepp {

// The timestamp counter costs a few nanoseconds per read, cheap enough to time every shadow ray, where
// std::chrono would add tens of nanoseconds to a query that itself takes a few hundred.
uint64_t read_ticks() { return __rdtsc(); }

double cpu_seconds(CpuClock clock) {
    timespec t{};
    clock_gettime(clock == CpuClock::process ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double seconds_per_tick() {
    static const double value = [] {
        auto t0 = std::chrono::steady_clock::now();
        uint64_t c0 = __rdtsc();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        uint64_t c1 = __rdtsc();
        double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return dt / double(c1 - c0);
    }();
    return value;
}

}  // namespace neepp
