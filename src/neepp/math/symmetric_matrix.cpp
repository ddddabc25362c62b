#include "neepp/math/symmetric_matrix.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace neepp {

std::array<double, 3> eigenvalues(const SymmetricMatrix3 &s) {
    const double xx = s.xx, yy = s.yy, zz = s.zz, xy = s.xy, xz = s.xz, yz = s.yz;
    const double off = xy * xy + xz * xz + yz * yz;
    const double q = (xx + yy + zz) / 3.0;
    if (off == 0) {  // diagonal: the cubic's closed form would only add rounding
        std::array<double, 3> e = {xx, yy, zz};
        std::sort(e.begin(), e.end());
        return e;
    }
    // S = q I + p B with B of trace 0 and unit Frobenius norm / sqrt(6): det(B) / 2 = cos(3 phi).
    const double p = std::sqrt(((xx - q) * (xx - q) + (yy - q) * (yy - q) + (zz - q) * (zz - q) + 2.0 * off) / 6.0);
    const double bxx = (xx - q) / p, byy = (yy - q) / p, bzz = (zz - q) / p, bxy = xy / p, bxz = xz / p, byz = yz / p;
    const double det_b = bxx * byy * bzz + 2.0 * bxy * bxz * byz - bxx * byz * byz - byy * bxz * bxz - bzz * bxy * bxy;
    const double phi = std::acos(std::clamp(det_b / 2.0, -1.0, 1.0)) / 3.0;
    const double largest = q + 2.0 * p * std::cos(phi);
    const double smallest = q + 2.0 * p * std::cos(phi + 2.0 * std::numbers::pi / 3.0);
    return {smallest, 3.0 * q - largest - smallest, largest};
}

}  // namespace neepp
