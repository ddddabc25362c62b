// Curve files (Mitsuba's linearcurve and bsplinecurve): control points, curves split at blank lines,
// segments per basis, and every malformed file refused naming its path and line.
#include <gtest/gtest.h>

#include "neepp/io/curve_reader.h"
#include "neepp/io/scene_error.h"
#include "common/temp_dir.h"

using namespace neepp;
using neepp::testing::TempDir;

namespace {

// Expects a SceneError whose message starts with "path:line:" (or "path:" for line 0) and contains needle.
void expect_error(const std::string &path, CurveBasis basis, int line, const std::string &needle) {
    try {
        read_curves(path, basis);
        ADD_FAILURE() << "expected a SceneError containing \"" << needle << "\"";
    } catch (const SceneError &e) {
        const std::string msg = e.what();
        EXPECT_EQ(e.line, line) << msg;
        EXPECT_EQ(msg.rfind(path + (line > 0 ? ":" + std::to_string(line) + ": " : ": "), 0), 0u) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
}

TEST(CurveReader, CurvesSplitAtBlankLinesWithSegmentsPerBasis) {
    TempDir tmp;
    // Two curves: 5 points, then (after a line of blanks, CRLF endings and a trailing comment) 4 points.
    const std::string path = tmp.write("curves.txt",
                                       "-1 0.1 0.1 0.5\n"
                                       "  -0.3 1.2 1.0 0.5\n"
                                       "0.3 0.3 1.1 0.5\n"
                                       "1 1.4 1.2 0.5\n"
                                       "2e0 +1 -1 0\n"
                                       " \t \r\n"
                                       "\n"
                                       "-1 5 2.2 1\r\n"
                                       "-2.3 4 2.3 2 anything after four numbers is ignored, as Mitsuba ignores it\r\n"
                                       "3.3 3 2.2 3\r\n"
                                       "4 2 2.3 4");
    const CurveData b = read_curves(path, CurveBasis::BSpline);
    ASSERT_EQ(b.points.size(), 9u);
    ASSERT_EQ(b.radii.size(), 9u);
    EXPECT_EQ(b.points[1], Vec3(-0.3f, 1.2f, 1.0f));
    EXPECT_EQ(b.points[4], Vec3(2, 1, -1));
    EXPECT_EQ(b.radii[4], 0.f);
    EXPECT_EQ(b.points[8], Vec3(4, 2, 2.3f));
    EXPECT_EQ(b.radii[6], 2.f);
    // B-spline: n - 3 segments per curve (2 and 1), none straddling the two curves.
    EXPECT_EQ(b.segments, (std::vector<uint32_t>{0, 1, 5}));
    const CurveData l = read_curves(path, CurveBasis::Linear);
    EXPECT_EQ(l.points.size(), 9u);
    EXPECT_EQ(l.segments, (std::vector<uint32_t>{0, 1, 2, 3, 5, 6, 7}));
}

TEST(CurveReader, MalformedFilesNameTheirLine) {
    TempDir tmp;
    expect_error((tmp.dir / "missing.txt").string(), CurveBasis::Linear, 0, "cannot open curve file");
    expect_error(tmp.write("empty.txt", ""), CurveBasis::Linear, 0, "no control points");
    expect_error(tmp.write("blank.txt", "\n  \n\r\n"), CurveBasis::BSpline, 0, "no control points");
    expect_error(tmp.write("three.txt", "0 0 0 1\n1 2 3\n"), CurveBasis::Linear, 2, "expected four numbers");
    expect_error(tmp.write("word.txt", "0 0 0 1\n1 1 1 1\n\n# a comment\n"), CurveBasis::Linear, 4, "\"# a comment\"");
    expect_error(tmp.write("nan.txt", "0 0 0 1\n1 nan 0 1\n"), CurveBasis::Linear, 2, "NaN or infinite) control point position");
    expect_error(tmp.write("inf.txt", "0 0 0 1\n1 0 0 inf\n"), CurveBasis::Linear, 2, "NaN or infinite) control point radius");
    expect_error(tmp.write("huge.txt", "0 0 0 1\n1e40 0 0 1\n"), CurveBasis::Linear, 2, "position");
    expect_error(tmp.write("negative.txt", "0 0 0 1\n1 0 0 -0.5\n"), CurveBasis::Linear, 2, "negative control point radius");
    // A curve too short for the basis is named by its first line.
    expect_error(tmp.write("short_linear.txt", "0 0 0 1\n1 0 0 1\n\n\n2 0 0 1\n"), CurveBasis::Linear, 5,
                 "a linear curve needs at least 2 control points; the one starting here has 1");
    const std::string three = tmp.write("short_bspline.txt", "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n\n4 0 0 1\n5 0 0 1\n6 0 0 1\n");
    expect_error(three, CurveBasis::BSpline, 6, "a B-spline curve needs at least 4 control points; the one starting here has 3");
    EXPECT_EQ(read_curves(three, CurveBasis::Linear).segments.size(), 5u);  // 3 + 2: enough for lines
    // Binary junk is quoted printably.
    expect_error(tmp.write("binary.txt", std::string("0 0 0 1\n\x01\x02\xff", 11)), CurveBasis::Linear, 2, "\"???\"");
}

}  // namespace
