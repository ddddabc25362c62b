#include "neepp/scene/camera.h"

#include <stdexcept>

namespace neepp {

void PerspectiveCamera::finalize() {
    if (width <= 0 || height <= 0) throw std::invalid_argument("film size must be positive");
    if (!(fov > 0 && fov < 180)) throw std::invalid_argument("fov must be in (0, 180) degrees");
    float t = std::tan(0.5f * fov * kPi / 180.f);
    float w = float(width), h = float(height), aspect = w / h;
    std::string axis = fov_axis;
    if (axis == "smaller") axis = width <= height ? "x" : "y";
    else if (axis == "larger") axis = width >= height ? "x" : "y";
    if (axis == "x") { tan_x_ = t; tan_y_ = t / aspect; }
    else if (axis == "y") { tan_y_ = t; tan_x_ = t * aspect; }
    else if (axis == "diagonal") {
        float d = std::sqrt(w * w + h * h);
        tan_x_ = t * w / d;
        tan_y_ = t * h / d;
    } else {
        throw std::invalid_argument("unknown fov_axis '" + fov_axis + "' (x, y, diagonal, smaller, larger)");
    }
    origin_ = to_world.point(Vec3(0.f));
    axis_x_ = to_world.vector(Vec3(1, 0, 0));
    axis_y_ = to_world.vector(Vec3(0, 1, 0));
    axis_z_ = to_world.vector(Vec3(0, 0, 1));
}

Ray PerspectiveCamera::generate_ray(Vec2 film) const {
    float x = (1.f - 2.f * film.x) * tan_x_, y = (1.f - 2.f * film.y) * tan_y_;
    Vec3 d_cam(x, y, 1.f);
    Vec3 d = axis_x_ * d_cam.x + axis_y_ * d_cam.y + axis_z_ * d_cam.z;
    float len = norm(d);
    d = d / len;
    // Start at the near plane (Mitsuba's near_clip is measured along the optical axis).
    float inv_z = len / norm(axis_z_);
    return Ray{origin_, d, near_clip * inv_z, far_clip * inv_z};
}

}  // namespace neepp
