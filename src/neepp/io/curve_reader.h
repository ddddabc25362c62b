// Curve files as Mitsuba 3's `bsplinecurve` and `linearcurve` shapes read them: a text file of control
// points, one a line (x y z radius), a blank line starting the next curve.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "neepp/math/vec.h"

namespace neepp {

// How a curve runs through its control points: straight from one to the next (each segment two points),
// or as a uniform cubic B-spline (each segment four consecutive points, the curve passing near, not
// through, them).
enum class CurveBasis { Linear, BSpline };

// Control points a segment of the basis reads: 2 (linear) or 4 (B-spline); a curve needs at least this many.
inline int points_per_segment(CurveBasis basis) { return basis == CurveBasis::Linear ? 2 : 4; }

struct CurveData {
    std::vector<Vec3> points;  // every curve's control points, in file order
    std::vector<float> radii;  // one per point
    // The first control point of each segment: a curve of n points has n - points_per_segment + 1
    // segments, numbered in file order (Mitsuba's v coordinate runs over all of them).
    std::vector<uint32_t> segments;
};

// Reads the file as Mitsuba does: blank lines (or blanks only) separate curves; each other line starts
// with four numbers, the point and its radius (anything after them is ignored, as Mitsuba ignores it).
// Throws SceneError naming the path and line for a missing file, a line that does not start with four
// numbers, a NaN or infinite value, a negative radius, a curve with too few points for the basis, or a
// file with no point at all.
CurveData read_curves(const std::string &path, CurveBasis basis);

}  // namespace neepp
