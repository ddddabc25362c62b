// The camera, Mitsuba 3's `perspective` (a pinhole), `thinlens` (a perspective camera whose rays start on a
// lens disk) or `orthographic` sensor, with its conventions: camera
// space looks down +z with +y up and +x toward the left of the image; film coordinates run from (0,0) at
// the top-left to (1,1) bottom-right.
#pragma once
#include <string>
#include "neepp/base/interaction.h"
#include "neepp/math/transform.h"

namespace neepp {

// A point of the scene seen from the camera, for light paths (light tracing, BDPT's t = 1 strategies).
class Medium;

struct CameraConnection {
    Vec2 raster;         // where on the film it lands, in pixels ((0,0) top-left, as film samples)
    Vec3 d;              // unit direction from the reference point toward the camera
    float dist = 0;
    // We · cos(theta_camera) / dist²: what a light path ending at the reference point is multiplied by
    // (besides its BSDF term there), the camera's half of the geometry term included.
    float weight = 0;
    bool valid() const { return weight > 0; }
};

enum class Projection : uint8_t {
    Perspective,
    // Parallel rays along camera +z from the near plane, over camera-space x in [-1, 1] and y in
    // [-1/aspect, 1/aspect] (so a to_world scale sets the view's extent). It has no importance function,
    // as Mitsuba's has none: light paths cannot connect to it (bdpt and light tracing refuse it).
    Orthographic,
};

struct Camera {
    Projection projection = Projection::Perspective;
    Transform to_world;
    int width = 768, height = 576;
    float fov = 39.3077f;          // perspective only: degrees, along fov_axis (the loader sets Mitsuba 3's default when a scene gives none)
    std::string fov_axis = "x";    // x, y, diagonal, smaller, larger
    float near_clip = 1e-2f, far_clip = 1e4f;
    // The medium the camera sits in (Mitsuba's sensor <medium>), where camera paths start; null: vacuum.
    const Medium *medium = nullptr;
    // Perspective only: a thin lens (Mitsuba's `thinlens`) of this radius at the camera's position, in
    // focus at focus_distance along the view axis. 0: a pinhole. A camera ray then starts on the lens
    // disk and passes through the point of the focal plane its film position sees through the centre.
    float aperture_radius = 0, focus_distance = 1e4f;
    // A crop window (Mitsuba's hdrfilm crop_offset_x/y, crop_width/height; the CLI's --crop): the image is
    // the width × height pixels at (crop_x, crop_y) of a film_width × film_height film, whose projection
    // it keeps. film_width 0: no crop. Set by crop().
    int crop_x = 0, crop_y = 0, film_width = 0, film_height = 0;

    // Precomputes the image-plane extent; call after changing the fields above. Throws on bad values.
    void finalize();
    // Makes the image the window (x, y, w, h) of the film (whole pixels, inside it); throws
    // std::invalid_argument otherwise. Call finalize() after.
    void crop(int x, int y, int w, int h);
    // Whether camera rays need a lens sample (two more random numbers after the film position's, drawn only
    // then, so that a pinhole's sample streams stay as they were).
    bool has_lens() const { return projection == Projection::Perspective && aperture_radius > 0; }
    // Primary ray through continuous image position (fx, fy) in [0,1)^2 (of the crop window, if any),
    // from the lens point that `lens` in [0,1)^2 maps to (ignored without a lens).
    Ray generate_ray(Vec2 film, Vec2 lens = Vec2(0.5f, 0.5f)) const;
    // Primary ray through image pixel (x, y) at offset jitter in [0,1)^2 within it. The position is
    // computed in film pixels, so that a crop's pixel traces the same ray, to the bit, as the whole film's.
    Ray pixel_ray(int x, int y, Vec2 jitter, Vec2 lens = Vec2(0.5f, 0.5f)) const;
    Vec3 position() const { return to_world.point(Vec3(0.f)); }

    // Whether light paths can reach the camera (connect() and importance() mean something): a pinhole's.
    // A thin lens has an importance too (Mitsuba's ptracer connects to it), but neepp's light paths do
    // not sample its lens yet.
    bool has_importance() const { return projection == Projection::Perspective && !has_lens(); }
    // The camera's importance, for paths traced from the lights (perspective only: zero otherwise). We is normalized as pbrt's is: over the
    // image plane at distance 1 (area A = 4 tan_x tan_y), We = 1 / (A cos^4 theta) inside the film, so
    // that a camera ray's We · cos / pdf is 1 (pdf_direction is 1 / (A cos^3 theta)) and a light path
    // splatted with connect()'s weight, into one pixel of W·H, estimates radiance when the splats of
    // W·H light paths are summed. (The to_world of a camera is a rigid motion, as Mitsuba's are.)
    float importance(const Vec3 &w) const;
    float pdf_direction(const Vec3 &w) const;
    // The camera seen from ref: invalid when ref is behind it, outside the film or nearer than near_clip.
    CameraConnection connect(const Vec3 &ref) const;

private:
    // The film position that camera-space direction `local` (not normalized) meets (false outside the film
    // or behind the camera).
    bool film_of(const Vec3 &local, Vec2 &film) const;
    Ray film_ray(Vec2 film, Vec2 lens) const;  // through film position (whole film, [0,1)^2)
    // Half the film's extent on the plane at distance 1 (perspective) or on the near plane (orthographic).
    float tan_x_ = 0, tan_y_ = 0, inv_plane_area_ = 0;
    Vec2 image_scale_{1.f, 1.f}, image_offset_{0.f, 0.f};  // the image's window in film coordinates
    Vec3 origin_, axis_x_, axis_y_, axis_z_;
};

}  // namespace neepp
