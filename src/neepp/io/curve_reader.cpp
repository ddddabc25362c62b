#include "neepp/io/curve_reader.h"

#include <cmath>
#include <cstring>
#include "neepp/io/mesh_data.h"

namespace neepp {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The first characters of a line, for messages (a line may be long, or binary).
std::string excerpt(const char *p, const char *eol) {
    std::string s(p, std::min<size_t>(size_t(eol - p), 60));
    for (char &c : s)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    return size_t(eol - p) > s.size() ? s + "..." : s;
}

}  // namespace

CurveData read_curves(const std::string &path, CurveBasis basis) {
    const std::string text = mesh_detail::read_file(path, "curve file");
    const size_t needed = size_t(points_per_segment(basis));
    const char *basis_name = basis == CurveBasis::Linear ? "a linear curve" : "a B-spline curve";
    CurveData c;
    size_t curve_start = 0;  // index of the open curve's first point
    int curve_line = 0;      // and its line; 0 while no curve is open
    auto close_curve = [&] {
        if (curve_line == 0) return;
        const size_t n = c.points.size() - curve_start;
        if (n < needed)
            throw SceneError(path, curve_line, std::string(basis_name) + " needs at least " + std::to_string(needed) +
                                                   " control points; the one starting here has " + std::to_string(n));
        for (size_t i = curve_start; i + needed <= c.points.size(); ++i) c.segments.push_back(uint32_t(i));
        curve_line = 0;
    };

    const char *p = text.data(), *end = p + text.size();
    for (int line = 1; p < end; ++line) {
        const char *eol = static_cast<const char *>(std::memchr(p, '\n', size_t(end - p)));
        if (!eol) eol = end;
        const char *q = p;
        while (q < eol && is_blank(*q)) ++q;
        if (q == eol) {
            close_curve();
        } else {
            float v[4];
            for (float &x : v) {
                while (q < eol && is_blank(*q)) ++q;
                double d;
                if (!mesh_detail::parse_real(q, eol, d))
                    throw SceneError(path, line, "expected four numbers (x y z radius), got \"" + excerpt(p, eol) + "\"");
                x = float(d);
            }
            const Vec3 point(v[0], v[1], v[2]);
            if (!is_finite(point)) throw SceneError(path, line, "invalid (NaN or infinite) control point position");
            if (!std::isfinite(v[3])) throw SceneError(path, line, "invalid (NaN or infinite) control point radius");
            if (v[3] < 0) throw SceneError(path, line, "negative control point radius " + std::to_string(v[3]));
            if (curve_line == 0) curve_start = c.points.size(), curve_line = line;
            if (c.points.size() >= UINT32_MAX) throw SceneError(path, line, "too many control points");
            c.points.push_back(point);
            c.radii.push_back(v[3]);
        }
        p = eol + 1;
    }
    close_curve();
    if (c.points.empty()) throw SceneError(path, "no control points (an empty curve file)");
    return c;
}

}  // namespace neepp
