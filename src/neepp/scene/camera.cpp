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
    inv_plane_area_ = 1.f / (4.f * tan_x_ * tan_y_);
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

bool PerspectiveCamera::film_of(const Vec3 &local, Vec2 &film) const {
    if (!(local.z > 0)) return false;
    film = Vec2(0.5f * (1.f - local.x / (local.z * tan_x_)), 0.5f * (1.f - local.y / (local.z * tan_y_)));
    return film.x >= 0.f && film.x < 1.f && film.y >= 0.f && film.y < 1.f;
}

float PerspectiveCamera::importance(const Vec3 &w) const {
    const Vec3 local = normalize(to_world.inverse_vector(w));
    Vec2 film;
    if (!film_of(local, film)) return 0.f;
    const float c2 = local.z * local.z;
    return inv_plane_area_ / (c2 * c2);
}

float PerspectiveCamera::pdf_direction(const Vec3 &w) const {
    const Vec3 local = normalize(to_world.inverse_vector(w));
    Vec2 film;
    if (!film_of(local, film)) return 0.f;
    return inv_plane_area_ / (local.z * local.z * local.z);
}

CameraConnection PerspectiveCamera::connect(const Vec3 &ref) const {
    CameraConnection c;
    const Vec3 local = to_world.inverse().point(ref);
    Vec2 film;
    if (!film_of(local, film) || local.z < near_clip || local.z > far_clip) return c;
    const Vec3 to_cam = origin_ - ref;
    c.dist = norm(to_cam);
    if (!(c.dist > 0)) return c;
    c.d = to_cam / c.dist;
    c.raster = Vec2(film.x * float(width), film.y * float(height));
    const float cos_theta = local.z / norm(local);
    const float c2 = cos_theta * cos_theta;
    c.weight = inv_plane_area_ / (c2 * c2) * cos_theta / (c.dist * c.dist);
    return c;
}

}  // namespace neepp
