// A rectangle as seen from a point: the spherical rectangle it projects onto the unit sphere around that
// point, its solid angle, and points of the rectangle drawn uniformly in that solid angle, by Ureña, Fajardo
// and King's area-preserving parametrization ("An Area-Preserving Parametrization for Spherical
// Rectangles", EGSR 2013).
//
// Why double precision: the solid angle is the sum of the four internal angles less 2 pi, each near pi / 2
// for a distant rectangle, so in float a solid angle of 1e-3 sr would carry a relative error near 1e-3,
// and with it every density reported (a bias, not noise). In double the same cancellation costs 1e-12.
#pragma once
#include "neepp/math/vec.h"

namespace neepp {

class SphericalRectangle {
public:
    // The rectangle corner + a ex + b ey (a in [0, len_x], b in [0, len_y]; ex, ey unit and orthogonal)
    // seen from o. A point in the rectangle's plane sees a solid angle of 0.
    SphericalRectangle(const Vec3 &o, const Vec3 &corner, const Vec3 &ex, const Vec3 &ey, float len_x, float len_y);

    // The solid angle the rectangle subtends at o, in [0, 2 pi).
    double solid_angle() const { return solid_angle_; }
    // A point of the rectangle, its direction from o uniform within the solid angle (density
    // 1 / solid_angle()), from u in [0, 1)^2; (s, t) receive its coordinates along ex and ey as fractions of
    // the edges, in [0, 1]. Only meaningful for solid_angle() > 0.
    Vec3 sample(Vec2 u, float &s, float &t) const;

private:
    Vec3 corner_, ex_, ey_;
    // The rectangle in a frame at o (ex, ey, and a normal pointing from the plane toward o): [x0, x1] x
    // [y0, y1] at height z0 <= 0.
    double x0_, x1_, y0_, y1_, z0_;
    double b0_, b1_, k_;  // the paper's constants of the inversion
    double solid_angle_ = 0;
};

}  // namespace neepp
