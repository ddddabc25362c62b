// The uv and partials of Mitsuba's analytic shapes (sphere, disk, cylinder, rectangle) as neepp's hits give
// them: at the world point p(u, v) of the shape's parameterisation, written here from Mitsuba 3's
// definitions, a hit reports that (u, v), dp/du and dp/dv equal to central differences of p, and a shading
// frame whose s is dp/du made orthogonal to the normal (Mitsuba's). A bump map tilts the normal along
// these partials, so their lengths and directions decide how it shades.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include "neepp/math/frame.h"
#include "neepp/scene/scene.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// An anisotropic BSDF: hits then carry dp/du, dp/dv and a frame along dp/du.
const char *kAnisotropic =
    R"(<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.3"/></bsdf>)";

struct Case {
    std::string name, shape_xml;
    std::function<Vec3(float, float)> p;  // Mitsuba's parameterisation, world space
    Vec3 axis_point;                      // a point inside (closed shapes), to aim rays from outside
    bool closed;
    float uv_tol;  // disk and cylinder are traced as 256-gon meshes: their hits lie just inside the circle
};

Vec3 turn(const Vec3 &v) {  // the rotation the sphere's to_world applies: 90° about x, then 30° about y
    const Vec3 a(v.x, -v.z, v.y);
    const float c = std::cos(kPi / 6), s = std::sin(kPi / 6);
    return {c * a.x + s * a.z, a.y, -s * a.x + c * a.z};
}

std::vector<Case> cases() {
    std::vector<Case> out;
    out.push_back({"sphere",
                   R"(<shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0.2" y="-0.1" z="0.3"/>
                      <transform name="to_world"><rotate x="1" angle="90"/><rotate y="1" angle="30"/></transform>)",
                   [](float u, float v) {
                       const float phi = 2 * kPi * u, theta = kPi * v;
                       // Mitsuba's sphere: center and radius inside to_world, so the center turns too.
                       const Vec3 local = Vec3(0.2f, -0.1f, 0.3f) +
                                          Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)) * 0.7f;
                       return turn(local);
                   },
                   turn(Vec3(0.2f, -0.1f, 0.3f)), true, 1e-4f});
    // The disk scaled by 1.5 and turned 90° about x: local (x, y, 0) goes to 1.5 (x, 0, y).
    out.push_back({"disk",
                   R"(<shape type="disk"><transform name="to_world"><scale value="1.5"/><rotate x="1" angle="90"/><translate y="0.4"/></transform>)",
                   [](float u, float v) {
                       const float phi = 2 * kPi * v;
                       return Vec3(1.5f * u * std::cos(phi), 0.4f, 1.5f * u * std::sin(phi));
                   },
                   Vec3(0.f), false, 2e-4f});
    const Vec3 p0(0.1f, 0.f, -0.2f), p1(0.3f, 1.5f, 0.f);
    const float radius = 0.6f;
    const Frame f(normalize(p1 - p0));  // Mitsuba's to_frame of the axis (coordinate_system)
    out.push_back({"cylinder",
                   R"(<shape type="cylinder"><point name="p0" x="0.1" y="0" z="-0.2"/><point name="p1" x="0.3" y="1.5" z="0"/>
                      <float name="radius" value="0.6"/>)",
                   [=](float u, float v) {
                       const float phi = 2 * kPi * u;
                       return p0 + (f.s * std::cos(phi) + f.t * std::sin(phi)) * radius + (p1 - p0) * v;
                   },
                   p0, true, 2e-4f});
    // The rectangle [-1, 1]^2 scaled by (2, 0.5) and turned 90° about x: local (x, y, 0) goes to (2x, 0, 0.5y).
    out.push_back({"rectangle",
                   R"(<shape type="rectangle"><transform name="to_world"><scale x="2" y="0.5" z="1"/><rotate x="1" angle="90"/></transform>)",
                   [](float u, float v) { return Vec3(2.f * (2 * u - 1), 0.f, 0.5f * (2 * v - 1)); }, Vec3(0.f), false, 1e-4f});
    return out;
}

void expect_near(const Vec3 &a, const Vec3 &b, float tol, const std::string &what) {
    EXPECT_LT(norm(a - b), tol) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") against (" << b.x << ", "
                                << b.y << ", " << b.z << ")";
}

TEST(AnalyticShapePartials, UvAndPartialsFollowMitsubasParameterisation) {
    for (const Case &c : cases()) {
        auto scene = load_scene(write_temp_scene(scene_header_xml(2, 40, "0,0,5", "0,0,0", 8, 8) + c.shape_xml +
                                                 kAnisotropic + "</shape>\n<emitter type=\"constant\"/></scene>"));
        const float h = 1e-3f;
        for (float u : {0.13f, 0.37f, 0.62f, 0.88f})
            for (float v : {0.21f, 0.45f, 0.79f}) {
                const std::string at = c.name + " at uv (" + std::to_string(u) + ", " + std::to_string(v) + ")";
                const Vec3 p = c.p(u, v);
                const Vec3 dpdu = (c.p(u + h, v) - c.p(u - h, v)) / (2 * h);
                const Vec3 dpdv = (c.p(u, v + h) - c.p(u, v - h)) / (2 * h);
                Vec3 m = normalize(cross(dpdu, dpdv));
                if (c.closed && dot(m, p - c.axis_point) < 0) m = -m;
                SurfaceInteraction si;
                ASSERT_TRUE(scene->intersect(Ray{p + m * 2.f, -m, 0.f, kInfinity}, si)) << at;
                expect_near(si.p, p, 1e-3f, at + ": p");
                EXPECT_NEAR(si.uv.x, u, c.uv_tol) << at;
                EXPECT_NEAR(si.uv.y, v, c.uv_tol) << at;
                expect_near(si.dpdu, dpdu, 2e-3f * norm(dpdu), at + ": dp/du");
                expect_near(si.dpdv, dpdv, 2e-3f * norm(dpdv), at + ": dp/dv");
                // Mitsuba's frame: s along dp/du, t = n x s, n the analytic surface's normal.
                EXPECT_NEAR(std::abs(dot(si.sh_frame.n, m)), 1.f, 1e-5f) << at;
                const Vec3 s = dpdu - si.sh_frame.n * dot(si.sh_frame.n, dpdu);
                expect_near(si.sh_frame.s, normalize(s), 1e-3f, at + ": s");
                expect_near(si.sh_frame.t, cross(si.sh_frame.n, si.sh_frame.s), 1e-5f, at + ": t");
            }
    }
}

}  // namespace
