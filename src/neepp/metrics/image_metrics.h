// Error metrics between a rendered image and a reference, and heat maps of the error for inspection.
#pragma once
#include "neepp/io/image.h"

namespace neepp {

// Every comparison is over pixels and the three RGB channels: Image::rgb() is used, so alpha is ignored and
// a single-channel image counts as gray. The two images must have equal width and height, else
// std::invalid_argument. Sums are taken in double.

// The paper's rMSE: mean of (I - R)^2 / (R^2 + 0.01).
double rel_mse(const Image &img, const Image &ref);
// Mean of (I - R)^2.
double mse(const Image &img, const Image &ref);
// sqrt(mse).
double rmse(const Image &img, const Image &ref);
// Mean of |I - R| / (|R| + 0.01).
double mean_abs_rel_error(const Image &img, const Image &ref);

// Mean of each RGB channel over the pixels.
Color image_mean(const Image &img);
// Mean over pixels and RGB channels (the average of image_mean's three values).
double image_mean_overall(const Image &img);

// Per-pixel relative squared error, averaged over RGB: a 1-channel image whose mean is rel_mse(img, ref).
Image rel_mse_map(const Image &img, const Image &ref);

// Maps channel 0 of a scalar image to an "inferno"-like heat map (black, purple, orange, pale yellow) for a
// person to look at: value / max_value, clamped to [0, 1]. max_value <= 0 picks the 99th percentile of
// the finite values (or their maximum if that is 0), so a few fireflies do not wash out the map. Non-finite values show as pure green.
// The result is linear RGB, so write_png_srgb shows the intended colors.
Image false_color(const Image &scalar, float max_value = 0.f);

}  // namespace neepp
