// Chi-square goodness-of-fit testing of samplers against their densities, after Mitsuba's python/chi2.py:
// samples are binned, each bin's expected count is the density's mass in it, bins with a low expected
// count are pooled, and the statistic's p-value comes from the regularized incomplete gamma function.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "neepp/math/frame.h"
#include "neepp/sampling/rng.h"

namespace neepp::test {

struct Chi2Result {
    double statistic = 0, p_value = 0;
    int dof = 0;
    double pdf_integral = 0;          // integral of the pdf over the binned domain (<= 1)
    double valid_fraction = 0;        // fraction of the samples that were valid
    std::string error;                // set when the test cannot be run or fails outright
    std::string describe() const;
};

// Pearson's statistic of observed counts against expected counts (probability mass times the number of
// samples drawn), pooling bins that expect fewer than min_expected samples. Fills statistic, dof and
// p_value, or error when samples land where nothing is expected.
Chi2Result chi2_from_histograms(const std::vector<double> &observed, const std::vector<double> &expected,
                                double min_expected = 5.0);

// Directions are binned over (phi, cos theta) around frame.n — an equal-area parameterization, so the
// pdf integrates over each bin without a Jacobian — and the pdf is integrated per bin with Simpson's
// rule. Restricting the bins to the band cos_min <= cos theta <= cos_max resolves a distribution of small
// support (a distant light); a sample outside the band is an error.
struct SphereChi2Config {
    int res = 101;                    // cos theta bins; phi gets twice as many
    int ires = 4;                     // Simpson subintervals per bin and dimension (even)
    uint64_t sample_count = 1000000;
    uint64_t seed = 1;
    double min_expected = 5.0;        // bins expecting fewer samples are pooled
    Frame frame;                      // world directions are binned in this frame
    double cos_min = -1.0, cos_max = 1.0;
};

// Draws one direction (world space, unit) from the random stream, or nothing for an invalid sample.
using DirectionSampler = std::function<std::optional<Vec3>(PCG32 &rng)>;
// Solid-angle density of a world-space direction.
using DirectionPdf = std::function<double(const Vec3 &)>;

Chi2Result chi2_sphere_test(const DirectionSampler &sample, const DirectionPdf &pdf, const SphereChi2Config &cfg);

// Upper tail probability of the chi-square distribution: 1 - P(dof / 2, statistic / 2).
double chi2_p_value(double statistic, int dof);
// Regularized lower incomplete gamma P(a, x) and its complement Q = 1 - P.
double regularized_gamma_p(double a, double x);
double regularized_gamma_q(double a, double x);

}  // namespace neepp::test
