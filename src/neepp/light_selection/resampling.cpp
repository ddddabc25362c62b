#include "neepp/light_selection/resampling.h"

#include <cmath>

namespace neepp {

int choose_proportional(const float *weights, int n, float u, float &sum) {
    sum = 0.f;
    for (int i = 0; i < n; ++i) sum += weights[i];
    if (!(sum > 0.f) || !std::isfinite(sum)) return -1;
    const float target = u * sum;
    float cdf = 0.f;
    int last = -1;
    for (int i = 0; i < n; ++i) {
        if (!(weights[i] > 0.f)) continue;  // never chosen, even where rounding puts target on its edge
        last = i;
        cdf += weights[i];
        if (target < cdf) return i;
    }
    return last;  // u * sum rounded up to the total
}

}  // namespace neepp
