// A many-light scene for the light-selection tests, written inline as Mitsuba XML: a row of rooms along
// +x joined by doorways, each with its own ceiling light of a different radiance (so power, distance and
// visibility each favour different lights), the camera in the first room looking down the row.
#pragma once
#include <string>
#include "test_scenes.h"

namespace neepp::testing {

inline std::string light_rooms_xml(int rooms = 4, bool environment = false, int width = 24, int height = 18) {
    const float length = 2.f * float(rooms);
    std::string xml = scene_header_xml(4, 70, "0.3,1.1,0.6", "3,0.8,0", width, height) + R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
  <shape type="cube"><transform name="to_world"><scale x=")" + std::to_string(length / 2) + R"(" y="1" z="1"/><translate x=")" +
                      std::to_string(length / 2) + R"(" y="1"/></transform><ref id="white"/></shape>
)";
    if (environment) xml += R"(  <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
)";
    const char *radiance[] = {"4", "30", "12", "60", "8", "25"};
    for (int i = 0; i < rooms; ++i) {
        const std::string cx = std::to_string(2.f * float(i) + 1.f);
        xml += R"(  <shape type="rectangle"><transform name="to_world"><scale x="0.6" y="0.6"/><rotate x="1" angle="90"/><translate x=")" +
               cx + R"(" y="1.98"/></transform><ref id="white"/><emitter type="area"><rgb name="radiance" value=")" +
               radiance[i % 6] + R"("/></emitter></shape>
)";
        if (i == 0) continue;
        // The wall at x = 2i, with a doorway at |z| < 0.3, y < 1.4 (alternating sides so that no line of
        // sight runs down the whole row).
        const std::string wx = std::to_string(2.f * float(i));
        const std::string off = (i % 2) ? "0.35" : "-0.35";
        const std::string door_z = (i % 2) ? "-0.66" : "0.66";
        xml += R"(  <shape type="cube"><transform name="to_world"><scale x="0.05" y="1" z="0.675"/><translate x=")" + wx +
               R"(" y="1" z=")" + off + R"("/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="0.3" z="0.345"/><translate x=")" + wx +
               R"(" y="1.7" z=")" + door_z + R"("/></transform><ref id="white"/></shape>
)";
    }
    return xml + "</scene>\n";
}

// A room lit by a textured rectangle light under its ceiling (turned, 1.8 x 0.8) and a small sphere light
// near a wall: the lights that solid-angle sampling takes (light_selection/solid_angle_sampling.h).
inline std::string lamps_xml() {
    return scene_header_xml(5, 75, "0,1,1.4", "0,0.9,0", 24, 18) + R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.65"/></bsdf></bsdf>
  <shape type="cube"><transform name="to_world"><scale x="1.5" y="1" z="1.5"/><translate y="1"/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.3" y="0.5" z="0.3"/><translate x="-0.4" y="0.5" z="-0.3"/></transform>
    <bsdf type="roughplastic"><float name="alpha" value="0.15"/><rgb name="diffuse_reflectance" value="0.3,0.5,0.6"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.5" y="0.3" z="0.2"/><float name="radius" value="0.3"/>
    <bsdf type="roughconductor"><string name="material" value="Cu"/><float name="alpha" value="0.25"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.9" y="0.4"/><rotate x="1" angle="90"/><rotate y="1" angle="20"/><translate y="1.97"/></transform>
    <ref id="white"/><emitter type="area"><texture name="radiance" type="checkerboard">
      <rgb name="color0" value="1,0.9,0.7"/><rgb name="color1" value="0.2,0.4,0.6"/></texture></emitter></shape>
  <shape type="sphere"><point name="center" x="-0.9" y="1.3" z="0.3"/><float name="radius" value="0.15"/>
    <emitter type="area"><rgb name="radiance" value="20,16,10"/></emitter></shape>
</scene>)";
}

}  // namespace neepp::testing
