// Small scenes with hard visibility for the NEE++ tests, written inline as Mitsuba XML.
#pragma once
#include <string>
#include "neepp/visibility/neepp_shadow_rays.h"
#include "test_scenes.h"

namespace neepp::testing {

// Two rooms side by side (x < 0: the camera's room, x > 0: the lit room) separated by a wall with a door
// opening; the only light is on the ceiling of the far room. Most shadow rays from the camera's room are
// blocked by the wall: the case NEE++ is for. `door_closed` fills the opening with a panel. The shapes
// alone, for a scene that opens differently; `in_room` is added inside the rooms' box (a medium it bounds).
inline std::string two_rooms_shapes_xml(bool door_closed = false, const std::string &in_room = "") {
    std::string xml = R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></bsdf>
  <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.2,0.2"/></bsdf></bsdf>
  <shape type="cube"><transform name="to_world"><scale x="2" y="1" z="1"/><translate y="1"/></transform><ref id="white"/>)" +
                      in_room + R"(</shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="1" z="0.35"/><translate y="1" z="-0.65"/></transform><ref id="red"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="1" z="0.35"/><translate y="1" z="0.65"/></transform><ref id="red"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="0.3" z="0.3"/><translate y="1.7"/></transform><ref id="red"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.4" y="0.4"/><rotate x="1" angle="90"/><translate x="1.2" y="1.99"/></transform>
    <ref id="white"/><emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
)";
    if (door_closed)
        xml += R"(  <shape type="cube"><transform name="to_world"><scale x="0.04" y="0.7" z="0.3"/><translate y="0.7"/></transform><ref id="white"/></shape>
)";
    return xml;
}

inline std::string two_rooms_xml(bool door_closed = false, int width = 24, int height = 18) {
    return scene_header_xml(5, 75, "-1.9,1.2,0.7", "0,0.7,-0.1", width, height) + two_rooms_shapes_xml(door_closed) +
           "</scene>\n";
}

// Wrong maps for the NEE++ unbiasedness tests: every pair claimed "never visible" with maximal
// confidence (Ṽ ≈ 1.5e-5, so q = q_min everywhere, the visible pairs included), or the map that tester's
// options seed on another scene (the door closed), given to tester as its own.
inline void plant_map_claiming_everything_occluded(NeeppShadowRays &tester, const Scene &scene) {
    VoxelGrid grid(scene.bounds(), tester.options().voxels);
    VisibilityMap map(grid.cell_count());
    for (uint64_t p = 0; p < map.pair_count(); ++p) map.set(p, PairCounts{0, 65535});
    tester.adopt_map(grid, std::move(map));
}

inline void plant_map_seeded_on(NeeppShadowRays &tester, const Scene &other) {
    NeeppOptions seeding = tester.options();
    seeding.defer_seeding = false;  // seeded by prepare(), not after a first pass
    NeeppShadowRays seeder(seeding);
    seeder.prepare(other);
    tester.adopt_map(seeder.grid(), seeder.map());
}

// A shadow-ray policy's name as a test name ("neepp-cv": "neepp_cv").
inline std::string policy_test_name(const ::testing::TestParamInfo<std::string> &info) {
    std::string s = info.param;
    for (char &ch : s)
        if (ch == '-') ch = '_';
    return s;
}

// A closed room lit only by a constant environment through a window in one wall.
inline std::string window_room_xml(int width = 24, int height = 18) {
    return scene_header_xml(4, 80, "0.8,1.0,0.8", "-0.5,0.6,-0.6", width, height) + R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
  <emitter type="constant"><rgb name="radiance" value="3"/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="1"/><rotate x="1" angle="-90"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="1"/><rotate x="1" angle="90"/><translate y="2"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="1"/><translate y="1" z="-1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="1"/><rotate y="1" angle="90"/><translate x="-1" y="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="1"/><rotate y="1" angle="-90"/><translate x="1" y="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="0.3"/><translate y="0.3" z="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="0.4"/><translate y="1.6" z="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.5" y="0.6"/><translate x="-0.5" y="0.9" z="1"/></transform><ref id="white"/></shape>
</scene>
)";
}

}  // namespace neepp::testing
