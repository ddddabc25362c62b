// Chi-square goodness-of-fit test of BSDF::sample against BSDF::pdf over the sphere of outgoing
// directions, on the shared harness (common/chi2.h).
#pragma once
#include <string>
#include <cstdint>
#include "common/chi2.h"
#include "neepp/base/bsdf.h"

namespace neepp::test {

struct Chi2Config {
    int res = 101;                    // cos theta bins; phi gets twice as many
    int ires = 4;                     // Simpson subintervals per bin and dimension (even)
    uint64_t sample_count = 1000000;
    uint64_t seed = 1;
    double min_expected = 5.0;        // bins expecting fewer samples are pooled
    TransportMode mode = TransportMode::Radiance;
};

// Samples wi's outgoing directions and compares them with the pdf. Delta-lobe samples are skipped:
// pdf() does not include them, so the pdf integral and the binned histogram both cover the rest.
Chi2Result chi2_test(const BSDF &bsdf, const Vec3 &wi, const Chi2Config &cfg = {});

// One case of a parameterised chi-square suite (400k samples): the test passes at 1 % significance over
// `cases` tests, the pdf integrates to at most 1, and to the fraction of samples that are valid.
void expect_sampling_matches_pdf(const BSDF &bsdf, const Vec3 &wi, int ires, TransportMode mode, uint64_t seed,
                                 size_t cases, const std::string &what);

}  // namespace neepp::test
