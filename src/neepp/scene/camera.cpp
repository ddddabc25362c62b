#include "neepp/scene/camera.h"

#include <cmath>
#include <stdexcept>

#include "neepp/math/warp.h"

namespace neepp {

void Camera::finalize() {
    if (width <= 0 || height <= 0) throw std::invalid_argument("film size must be positive");
    const bool ortho = projection == Projection::Orthographic;
    if (!ortho && !(fov > 0 && fov < 180)) throw std::invalid_argument("fov must be in (0, 180) degrees");
    if (!(near_clip > 0)) throw std::invalid_argument("near_clip must be greater than zero");
    if (!(near_clip < far_clip)) throw std::invalid_argument("near_clip must be smaller than far_clip");
    if (!(aperture_radius >= 0) || !std::isfinite(aperture_radius))
        throw std::invalid_argument("aperture_radius must be zero or more");
    if (has_lens() && !(focus_distance > 0 && std::isfinite(focus_distance)))
        throw std::invalid_argument("focus_distance must be greater than zero");
    const int fw = film_width > 0 ? film_width : width, fh = film_width > 0 ? film_height : height;
    float t = ortho ? 1.f : std::tan(0.5f * fov * kPi / 180.f);
    float w = float(fw), h = float(fh), aspect = w / h;
    std::string axis = ortho ? "x" : fov_axis;  // the orthographic view spans [-1, 1] in x
    if (axis == "smaller") axis = fw <= fh ? "x" : "y";
    else if (axis == "larger") axis = fw >= fh ? "x" : "y";
    if (axis == "x") { tan_x_ = t; tan_y_ = t / aspect; }
    else if (axis == "y") { tan_y_ = t; tan_x_ = t * aspect; }
    else if (axis == "diagonal") {
        float d = std::sqrt(w * w + h * h);
        tan_x_ = t * w / d;
        tan_y_ = t * h / d;
    } else {
        throw std::invalid_argument("unknown fov_axis '" + fov_axis + "' (x, y, diagonal, smaller, larger)");
    }
    // The image's share of the film plane (at distance 1): the whole film's, or the crop window's.
    inv_plane_area_ = 1.f / (4.f * tan_x_ * tan_y_ * (float(width) / w) * (float(height) / h));
    image_scale_ = Vec2(float(width) / w, float(height) / h);
    image_offset_ = Vec2(float(crop_x) / w, float(crop_y) / h);
    origin_ = to_world.point(Vec3(0.f));
    axis_x_ = to_world.vector(Vec3(1, 0, 0));
    axis_y_ = to_world.vector(Vec3(0, 1, 0));
    axis_z_ = to_world.vector(Vec3(0, 0, 1));
}

void Camera::crop(int x, int y, int w, int h) {
    const int fw = film_width > 0 ? film_width : width, fh = film_width > 0 ? film_height : height;
    const int fx = film_width > 0 ? crop_x : 0, fy = film_width > 0 ? crop_y : 0;
    if (x < 0 || y < 0 || w < 1 || h < 1 || x > width - w || y > height - h)
        throw std::invalid_argument("crop window " + std::to_string(w) + "x" + std::to_string(h) + " at (" +
                                    std::to_string(x) + ", " + std::to_string(y) + ") is not inside the " +
                                    std::to_string(width) + "x" + std::to_string(height) + " image");
    film_width = fw;
    film_height = fh;
    crop_x = fx + x;  // a crop of a crop: offsets add up
    crop_y = fy + y;
    width = w;
    height = h;
}

Ray Camera::generate_ray(Vec2 film, Vec2 lens) const {
    return film_ray(image_offset_ + Vec2(film.x * image_scale_.x, film.y * image_scale_.y), lens);
}

Ray Camera::pixel_ray(int x, int y, Vec2 jitter, Vec2 lens) const {
    const int fw = film_width > 0 ? film_width : width, fh = film_width > 0 ? film_height : height;
    return film_ray({(float(x + crop_x) + jitter.x) / float(fw), (float(y + crop_y) + jitter.y) / float(fh)}, lens);
}

Ray Camera::film_ray(Vec2 film, Vec2 lens) const {
    float x = (1.f - 2.f * film.x) * tan_x_, y = (1.f - 2.f * film.y) * tan_y_;
    if (projection == Projection::Orthographic) {
        // As Mitsuba: from the near plane, in world units along the ray (a to_world scale of z scales where
        // the near plane is, not how far the ray goes).
        return Ray{to_world.point(Vec3(x, y, near_clip)), normalize(axis_z_), 0.f, far_clip - near_clip};
    }
    if (has_lens()) {
        // As Mitsuba's thinlens: the point at depth focus_distance that the film position sees through the
        // lens centre, seen from a uniform point of the lens disk; the ray starts at the near plane.
        const Vec2 a = square_to_uniform_disk_concentric(lens) * aperture_radius;
        const Vec3 lens_p(a.x, a.y, 0.f);
        const Vec3 local = normalize(Vec3(x, y, 1.f) * focus_distance - lens_p);
        const float inv_z = 1.f / local.z;
        return Ray{to_world.point(lens_p), normalize(to_world.vector(local)), near_clip * inv_z, far_clip * inv_z};
    }
    Vec3 d_cam(x, y, 1.f);
    Vec3 d = axis_x_ * d_cam.x + axis_y_ * d_cam.y + axis_z_ * d_cam.z;
    float len = norm(d);
    d = d / len;
    // Start at the near plane (Mitsuba's near_clip is measured along the optical axis).
    float inv_z = len / norm(axis_z_);
    return Ray{origin_, d, near_clip * inv_z, far_clip * inv_z};
}

bool Camera::film_of(const Vec3 &local, Vec2 &film) const {
    if (!(local.z > 0)) return false;
    film = Vec2(0.5f * (1.f - local.x / (local.z * tan_x_)), 0.5f * (1.f - local.y / (local.z * tan_y_)));
    film = Vec2((film.x - image_offset_.x) / image_scale_.x, (film.y - image_offset_.y) / image_scale_.y);  // -> image
    return film.x >= 0.f && film.x < 1.f && film.y >= 0.f && film.y < 1.f;
}

float Camera::importance(const Vec3 &w) const {
    if (!has_importance()) return 0.f;
    const Vec3 local = normalize(to_world.inverse_vector(w));
    Vec2 film;
    if (!film_of(local, film)) return 0.f;
    const float c2 = local.z * local.z;
    return inv_plane_area_ / (c2 * c2);
}

float Camera::pdf_direction(const Vec3 &w) const {
    if (!has_importance()) return 0.f;
    const Vec3 local = normalize(to_world.inverse_vector(w));
    Vec2 film;
    if (!film_of(local, film)) return 0.f;
    return inv_plane_area_ / (local.z * local.z * local.z);
}

CameraConnection Camera::connect(const Vec3 &ref) const {
    CameraConnection c;
    if (!has_importance()) return c;
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
