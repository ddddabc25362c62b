// Pinhole perspective camera with Mitsuba 3's conventions: camera space looks down +z with +y up and +x
// toward the left of the image; film coordinates run from (0,0) at the top-left to (1,1) bottom-right.
#pragma once
#include <string>
#include "neepp/math/transform.h"
#include "neepp/scene/interaction.h"

namespace neepp {

// A point of the scene seen from the camera, for light paths (light tracing, BDPT's t = 1 strategies).
struct CameraConnection {
    Vec2 raster;         // where on the film it lands, in pixels ((0,0) top-left, as film samples)
    Vec3 d;              // unit direction from the reference point toward the camera
    float dist = 0;
    // We · cos(theta_camera) / dist²: what a light path ending at the reference point is multiplied by
    // (besides its BSDF term there), the camera's half of the geometry term included.
    float weight = 0;
    bool valid() const { return weight > 0; }
};

struct PerspectiveCamera {
    Transform to_world;
    int width = 768, height = 576;
    float fov = 39.3077f;          // degrees, along fov_axis (the loader sets Mitsuba 3's default when a scene gives none)
    std::string fov_axis = "x";    // x, y, diagonal, smaller, larger
    float near_clip = 1e-2f, far_clip = 1e4f;

    // Precomputes the image-plane extent; call after changing the fields above. Throws on bad values.
    void finalize();
    // Primary ray through continuous film position (fx, fy) in [0,1)^2.
    Ray generate_ray(Vec2 film) const;
    Vec3 position() const { return to_world.point(Vec3(0.f)); }

    // The camera's importance, for paths traced from the lights. We is normalized as pbrt's is: over the
    // image plane at distance 1 (area A = 4 tan_x tan_y), We = 1 / (A cos^4 theta) inside the film, so
    // that a camera ray's We · cos / pdf is 1 (pdf_direction is 1 / (A cos^3 theta)) and a light path
    // splatted with connect()'s weight, into one pixel of W·H, estimates radiance when the splats of
    // W·H light paths are summed. (The to_world of a camera is a rigid motion, as Mitsuba's are.)
    float importance(const Vec3 &w) const;
    float pdf_direction(const Vec3 &w) const;
    // The camera seen from ref: invalid when ref is behind it, outside the film or nearer than near_clip.
    CameraConnection connect(const Vec3 &ref) const;

private:
    // Camera-space direction (not normalized) of world direction w, and the film position it meets (false
    // outside the film or behind the camera).
    bool film_of(const Vec3 &local, Vec2 &film) const;
    float tan_x_ = 0, tan_y_ = 0, inv_plane_area_ = 0;
    Vec3 origin_, axis_x_, axis_y_, axis_z_;
};

}  // namespace neepp
