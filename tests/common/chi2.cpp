#include "common/chi2.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace neepp::test {

namespace {

// Series for P(a, x), convergent for all x but fast for x < a + 1 (Numerical Recipes 6.2).
double gamma_series(double a, double x) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
        ap += 1.0;
        del *= x / ap;
        sum += del;
        if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Continued fraction for Q(a, x) (modified Lentz), fast for x >= a + 1.
double gamma_continued_fraction(double a, double x) {
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (std::abs(del - 1.0) < 1e-15) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double regularized_gamma_p(double a, double x) {
    if (x <= 0) return 0;
    return x < a + 1 ? gamma_series(a, x) : 1.0 - gamma_continued_fraction(a, x);
}

double regularized_gamma_q(double a, double x) {
    if (x <= 0) return 1;
    return x < a + 1 ? 1.0 - gamma_series(a, x) : gamma_continued_fraction(a, x);
}

double chi2_p_value(double statistic, int dof) { return regularized_gamma_q(0.5 * dof, 0.5 * statistic); }

std::string Chi2Result::describe() const {
    std::ostringstream os;
    os << "chi2=" << statistic << " dof=" << dof << " p=" << p_value << " pdf_integral=" << pdf_integral
       << " valid_fraction=" << valid_fraction;
    if (!error.empty()) os << " error: " << error;
    return os.str();
}

Chi2Result chi2_from_histograms(const std::vector<double> &observed, const std::vector<double> &expected,
                                double min_expected) {
    // Pooling of low-expectation bins as mitsuba.math.chi2.
    Chi2Result res;
    double pooled_obs = 0, pooled_exp = 0;
    for (size_t k = 0; k < observed.size(); ++k) {
        if (expected[k] <= 0) {
            if (observed[k] > 0) {
                std::ostringstream os;
                os << observed[k] << " samples in bin " << k << " where the pdf is zero";
                res.error = os.str();
                return res;
            }
        } else if (expected[k] < min_expected) {
            pooled_obs += observed[k];
            pooled_exp += expected[k];
        } else {
            double diff = observed[k] - expected[k];
            res.statistic += diff * diff / expected[k];
            ++res.dof;
        }
    }
    if (pooled_exp > min_expected) {
        double diff = pooled_obs - pooled_exp;
        res.statistic += diff * diff / pooled_exp;
        ++res.dof;
    } else if (pooled_obs > 5.0 * min_expected) {
        // Too little expected mass to form a bin, yet many samples landed there.
        res.error = "many samples in bins the pdf considers negligible";
        return res;
    }
    res.dof -= 1;
    if (res.dof < 1) {
        res.error = "too few degrees of freedom";
        return res;
    }
    res.p_value = chi2_p_value(res.statistic, res.dof);
    return res;
}

Chi2Result chi2_sphere_test(const DirectionSampler &sample, const DirectionPdf &pdf, const SphereChi2Config &cfg) {
    const int n_cos = cfg.res, n_phi = 2 * cfg.res, n_bins = n_cos * n_phi;
    const double d_phi = 2.0 * M_PI / n_phi, d_cos = (cfg.cos_max - cfg.cos_min) / n_cos;

    std::vector<double> observed(n_bins, 0.0), expected(n_bins, 0.0);
    PCG32 rng(cfg.seed, 0x9e3779b97f4a7c15ULL);
    uint64_t valid = 0, outside = 0;
    for (uint64_t s = 0; s < cfg.sample_count; ++s) {
        std::optional<Vec3> w_world = sample(rng);
        if (!w_world) continue;
        ++valid;
        Vec3 w = cfg.frame.to_local(*w_world);
        if (double(w.z) < cfg.cos_min || double(w.z) > cfg.cos_max) {
            ++outside;
            continue;
        }
        double phi = std::atan2(double(w.y), double(w.x));  // [-pi, pi]
        int i = std::clamp(int((phi + M_PI) / d_phi), 0, n_phi - 1);
        int j = std::clamp(int((double(w.z) - cfg.cos_min) / d_cos), 0, n_cos - 1);
        observed[j * n_phi + i] += 1;
    }

    Chi2Result res;
    double valid_fraction = double(valid) / double(cfg.sample_count);
    // Simpson's rule in (phi, cos theta); the solid-angle measure is dphi dcos. A bin's last node in either
    // coordinate is its neighbour's first (i + m/m is (i + 1) + 0/m, exactly), so the density is evaluated
    // once per node of the whole grid, a row of nodes of constant cos theta at a time, and each bin sums
    // its (m + 1)^2 nodes' values in the order and with the weights it always did: the same expected counts,
    // to the bit, for about 1/8 fewer evaluations of the density and none of the sines and cosines again.
    const int m = cfg.ires;
    auto simpson_weight = [m](int k) { return (k == 0 || k == m) ? 1.0 : (k % 2 ? 4.0 : 2.0); };
    // Node k of a grid of bins of m subintervals each: bin k / m's node k % m (the last, the last bin's m).
    auto node = [m](int k, int bins) {
        const int bin = std::min(k / m, bins - 1);
        return double(bin) + double(k - bin * m) / m;
    };
    const int phi_nodes = n_phi * m + 1;
    std::vector<double> cos_phi(phi_nodes), sin_phi(phi_nodes);
    for (int k = 0; k < phi_nodes; ++k) {
        const double phi = -M_PI + d_phi * node(k, n_phi);
        cos_phi[k] = std::cos(phi);
        sin_phi[k] = std::sin(phi);
    }
    // rows[b][k]: the density at the band's node b in cos theta (of the bins j) and node k in phi.
    std::vector<std::vector<double>> rows(m + 1, std::vector<double>(phi_nodes));
    auto fill_row = [&](std::vector<double> &row, int k_cos) {
        const double cos_t = std::clamp(cfg.cos_min + d_cos * node(k_cos, n_cos), -1.0, 1.0);
        const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
        for (int k = 0; k < phi_nodes; ++k) {
            Vec3 w(float(sin_t * cos_phi[k]), float(sin_t * sin_phi[k]), float(cos_t));
            row[k] = pdf(cfg.frame.to_world(w));
        }
    };
    double pdf_integral = 0;
    for (int j = 0; j < n_cos; ++j) {
        if (j == 0) fill_row(rows[0], 0);
        else std::swap(rows[0], rows[m]);
        for (int b = 1; b <= m; ++b) fill_row(rows[b], j * m + b);
        for (int i = 0; i < n_phi; ++i) {
            double sum = 0;
            for (int b = 0; b <= m; ++b)
                for (int a = 0; a <= m; ++a) sum += simpson_weight(a) * simpson_weight(b) * rows[b][i * m + a];
            double integral = sum * (d_phi / (3.0 * m)) * (d_cos / (3.0 * m));
            expected[j * n_phi + i] = integral * double(cfg.sample_count);
            pdf_integral += integral;
        }
    }

    if (outside > 0) {
        res.error = std::to_string(outside) + " samples outside the binned band";
    } else {
        res = chi2_from_histograms(observed, expected, cfg.min_expected);
    }
    res.pdf_integral = pdf_integral;
    res.valid_fraction = valid_fraction;
    return res;
}

}  // namespace neepp::test
