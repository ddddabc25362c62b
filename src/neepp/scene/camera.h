// Pinhole perspective camera with Mitsuba 3's conventions: camera space looks down +z with +y up and +x
// toward the left of the image; film coordinates run from (0,0) at the top-left to (1,1) bottom-right.
#pragma once
#include <string>
#include "neepp/math/transform.h"
#include "neepp/scene/interaction.h"

namespace neepp {

struct PerspectiveCamera {
    Transform to_world;
    int width = 768, height = 576;
    float fov = 39.3077f;          // degrees, along fov_axis
    std::string fov_axis = "x";    // x, y, diagonal, smaller, larger
    float near_clip = 1e-2f, far_clip = 1e4f;

    // Precomputes the image-plane extent; call after changing the fields above. Throws on bad values.
    void finalize();
    // Primary ray through continuous film position (fx, fy) in [0,1)^2.
    Ray generate_ray(Vec2 film) const;
    Vec3 position() const { return to_world.point(Vec3(0.f)); }

private:
    float tan_x_ = 0, tan_y_ = 0;
    Vec3 origin_, axis_x_, axis_y_, axis_z_;
};

}  // namespace neepp
