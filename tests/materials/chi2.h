// Chi-square goodness-of-fit test of BSDF::sample against BSDF::pdf, after Mitsuba's python/chi2.py:
// outgoing directions are binned over (phi, cos theta) — an equal-area parameterization, so the pdf
// integrates over each bin without a Jacobian — the pdf is integrated per bin with Simpson's rule, bins
// with a low expected count are pooled, and the statistic's p-value comes from the regularized
// incomplete gamma function.
#pragma once
#include <cstdint>
#include <string>
#include "neepp/materials/bsdf.h"

namespace neepp::test {

struct Chi2Config {
    int res = 101;                    // cos theta bins; phi gets twice as many
    int ires = 4;                     // Simpson subintervals per bin and dimension (even)
    uint64_t sample_count = 1000000;
    uint64_t seed = 1;
    double min_expected = 5.0;        // bins expecting fewer samples are pooled
    TransportMode mode = TransportMode::Radiance;
};

struct Chi2Result {
    double statistic = 0, p_value = 0;
    int dof = 0;
    double pdf_integral = 0;          // integral of pdf over the sphere (<= 1)
    double valid_fraction = 0;        // fraction of samples that were valid and not from a delta lobe
    std::string error;                // set when the test cannot be run or fails outright
    std::string describe() const;
};

// Samples wi's outgoing directions and compares them with the pdf. Delta-lobe samples are skipped:
// pdf() does not include them, so the pdf integral and the binned histogram both cover the rest.
Chi2Result chi2_test(const BSDF &bsdf, const Vec3 &wi, const Chi2Config &cfg = {});

// Upper tail probability of the chi-square distribution: 1 - P(dof / 2, statistic / 2).
double chi2_p_value(double statistic, int dof);
// Regularized lower incomplete gamma P(a, x) and its complement Q = 1 - P.
double regularized_gamma_p(double a, double x);
double regularized_gamma_q(double a, double x);

}  // namespace neepp::test
