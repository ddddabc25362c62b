// What the render loop tells integrators after each pass, so adaptive methods can tune themselves. Every
// field is computed deterministically from the samples (no timings), keeping renders reproducible.
#pragma once

namespace neepp {

struct PassStatistics {
    int pass_index = 0;
    int spp = 0;                   // samples per pixel completed so far, this pass included
    // Per-sample variance of a pixel estimate (luminance), averaged over pixels: the pass's mean squared
    // sample luminance minus the mean squared pixel value of the image so far.
    double sample_variance = 0;
};

}  // namespace neepp
