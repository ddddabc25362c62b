// Mitsuba 3's volumes, which give a medium's coefficients at a point: `constvolume` (one value everywhere)
// and `gridvolume` (a .vol grid over the unit cube, placed by to_world, looked up trilinearly or at the
// nearest texel, with Mitsuba's wrap modes).
#pragma once
#include <memory>
#include "neepp/io/volume_grid_reader.h"
#include "neepp/math/transform.h"

namespace neepp {

class Volume {
public:
    virtual ~Volume() = default;
    virtual Color eval(const Vec3 &p) const = 0;
    // The largest value of any channel anywhere (a heterogeneous medium's majorant comes from it).
    virtual float max() const = 0;
    // Where it is defined, in world space: as Mitsuba's, the unit cube placed by to_world (a heterogeneous
    // medium is vacuum outside its sigma_t volume's bounds, even a constant one's).
    virtual BBox bounds() const = 0;
};

// The unit cube's box after to_world.
BBox unit_cube_bounds(const Transform &to_world);

class ConstantVolume final : public Volume {
public:
    explicit ConstantVolume(Color value, const Transform &to_world = Transform())
        : value_(value), bounds_(unit_cube_bounds(to_world)) {}
    Color eval(const Vec3 &) const override { return value_; }
    float max() const override { return max_component(value_); }
    BBox bounds() const override { return bounds_; }

private:
    Color value_;
    BBox bounds_;
};

struct GridVolumeOptions {
    enum class Filter { Trilinear, Nearest } filter = Filter::Trilinear;
    enum class Wrap { Clamp, Repeat, Mirror } wrap = Wrap::Clamp;
    Transform to_world;
    bool use_grid_bbox = false;  // the file's bounds (not the unit cube) are what to_world places
    float max_value = -1;        // > 0: the max() Mitsuba's `max_value` declares instead of the data's
};

class GridVolume final : public Volume {
public:
    // Throws std::invalid_argument, saying what is wrong and where, when the grid has other than 1 or 3
    // channels, a value that is not finite or is negative, a max_value below its largest value, or (with
    // use_grid_bbox) stored bounds that are not a finite box.
    GridVolume(VolumeGrid grid, const GridVolumeOptions &options);
    Color eval(const Vec3 &p) const override;
    float max() const override { return max_; }
    BBox bounds() const override { return bounds_; }

private:
    Color texel(int64_t x, int64_t y, int64_t z) const;
    int64_t wrap(int64_t i, uint32_t n) const;

    VolumeGrid grid_;
    GridVolumeOptions options_;
    Transform to_local_;  // world to the unit cube
    float max_ = 0;
    BBox bounds_;
};

}  // namespace neepp
