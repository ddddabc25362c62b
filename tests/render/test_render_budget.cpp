// The render's pacing: how many samples per pixel each pass takes, alone (render_budget.h).
#include <gtest/gtest.h>
#include <algorithm>
#include "neepp/render/render_budget.h"

using namespace neepp;

TEST(PassSize, FirstPassIsOneSampleThenFullPassesOrGrowingOnesForALearner) {
    EXPECT_EQ(pass_size({.done = 0, .target = 256}), 1);
    EXPECT_EQ(pass_size({.done = 1, .target = 256, .seconds_per_spp = 0.01}), 32);
    EXPECT_EQ(pass_size({.done = 1, .target = 256, .seconds_per_spp = 0.01, .learns = true}), 1);
    EXPECT_EQ(pass_size({.done = 8, .target = 256, .seconds_per_spp = 0.01, .learns = true}), 8);
    EXPECT_EQ(pass_size({.done = 100, .target = 256, .seconds_per_spp = 0.01, .learns = true}), 32);
    EXPECT_EQ(pass_size({.done = 250, .target = 256, .seconds_per_spp = 0.01}), 6);  // the target's rest
    EXPECT_EQ(pass_size({.done = 256, .target = 256, .seconds_per_spp = 0.01}), 0);  // done
    // An interactive view's cap, and never below one sample.
    EXPECT_EQ(pass_size({.done = 1, .target = 256, .seconds_per_spp = 0.01, .max_pass_s = 0.05}), 5);
    EXPECT_EQ(pass_size({.done = 1, .target = 256, .seconds_per_spp = 1.0, .max_pass_s = 0.05}), 1);
}

// Under a time limit every pass started at the last pass's speed ends before the limit, and one that the
// machine slows down twofold under still ends before the overrun cut (kOverrunFactor x the limit), which
// would throw it away whole; near the end a pass fills the time left.
TEST(PassSize, TimedPassesFitTheTimeLeftAndSurviveATwofoldSlowdown) {
    const double limit = 1.5;
    for (double s : {0.001, 0.0125, 0.04, 0.1}) {         // seconds per sample per pixel
        for (double elapsed = 0.05; elapsed < limit; elapsed += 0.01) {
            const double remaining = limit - elapsed;
            const int n = pass_size({.done = 1, .seconds_per_spp = s, .time_limit_s = limit, .remaining_s = remaining});
            ASSERT_GE(n, 0);
            EXPECT_LE(n, 32);
            EXPECT_LE(elapsed + n * s, limit) << "s " << s << " elapsed " << elapsed;
            EXPECT_LE(elapsed + 2 * n * s, kOverrunFactor * limit) << "s " << s << " elapsed " << elapsed;
            // Not needlessly small: the pass is as large as both bounds allow, so the time left is used.
            const double bound = std::min({32 * s, 0.95 * remaining, 0.5 * (remaining + (kOverrunFactor - 1) * limit)});
            EXPECT_GT((n + 1) * s, bound) << "s " << s << " elapsed " << elapsed;
        }
    }
    // The render that lost its second pass (test_compare.py, PSSMLT at 0.6 s): 32 spp at 0.0125 s/spp after
    // a first pass of 0.045 s, 0.4 s, which a twofold slowdown took past the cut at 0.75 s; now 28.
    const int n = pass_size({.done = 1, .seconds_per_spp = 0.0125, .time_limit_s = 0.6, .remaining_s = 0.555});
    EXPECT_LE(0.045 + 2 * n * 0.0125, kOverrunFactor * 0.6);
    EXPECT_GE(n, 20);
    // With a sample count too, whichever ends first.
    EXPECT_EQ(pass_size({.done = 1, .target = 4, .seconds_per_spp = 0.001, .time_limit_s = 10, .remaining_s = 9}), 3);
    // The time is up.
    EXPECT_EQ(pass_size({.done = 40, .seconds_per_spp = 0.01, .time_limit_s = 1, .remaining_s = 0.005}), 0);
}
