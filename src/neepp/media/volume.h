// Mitsuba 3's volumes, which give a medium's coefficients at a point: `constvolume` (one value everywhere)
// and `gridvolume` (a .vol grid over the unit cube, placed by to_world, looked up trilinearly or at the
// nearest texel, with Mitsuba's wrap modes). A volume holds 1 channel (grey), 3 (RGB) or 6: a symmetric
// 3x3 matrix at each point, which is what the sggx phase function reads its S from.
#pragma once
#include <memory>
#include <string>
#include "neepp/io/volume_grid_reader.h"
#include "neepp/math/symmetric_matrix.h"
#include "neepp/math/transform.h"

namespace neepp {

class Volume {
public:
    virtual ~Volume() = default;
    virtual int channels() const = 0;  // 1, 3 or 6
    // The value at p of a 1- or 3-channel volume (a grey one's in every channel). The loader gives each
    // use the channel count it reads (a 6-channel volume's eval would be its diagonal).
    virtual Color eval(const Vec3 &p) const = 0;
    // The value at p of a 6-channel volume, interpolated as the others' (each entry alike).
    virtual SymmetricMatrix3 eval_matrix(const Vec3 &p) const = 0;
    // The largest value of any channel anywhere (a heterogeneous medium's majorant comes from it); of a
    // 6-channel volume, the largest eigenvalue of its matrices anywhere (bounding sqrt(wᵀ S w), sggx's
    // projected area, over every direction).
    virtual float max() const = 0;
    // Where it is defined, in world space: as Mitsuba's, the unit cube placed by to_world (a heterogeneous
    // medium is vacuum outside its sigma_t volume's bounds, even a constant one's).
    virtual BBox bounds() const = 0;
};

// The unit cube's box after to_world.
BBox unit_cube_bounds(const Transform &to_world);

// Why a 6-channel value is no SGGX matrix (not finite, or not positive semi-definite beyond rounding), or
// empty when it is one.
std::string symmetric_matrix_problem(const SymmetricMatrix3 &s);

class ConstantVolume final : public Volume {
public:
    explicit ConstantVolume(Color value, const Transform &to_world = Transform())
        : value_(value), bounds_(unit_cube_bounds(to_world)) {}
    // Six values (neepp's: Mitsuba 3's constvolume has no 6-channel lookup). Throws std::invalid_argument
    // where symmetric_matrix_problem finds one.
    explicit ConstantVolume(const SymmetricMatrix3 &value, const Transform &to_world = Transform());
    int channels() const override { return channels_; }
    Color eval(const Vec3 &) const override { return value_; }
    SymmetricMatrix3 eval_matrix(const Vec3 &) const override { return matrix_; }
    float max() const override { return max_; }
    BBox bounds() const override { return bounds_; }

private:
    Color value_;
    SymmetricMatrix3 matrix_;
    int channels_ = 3;
    float max_ = max_component(value_);
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
    // Throws std::invalid_argument, saying what is wrong and where, when the grid has other than 1, 3 or 6
    // channels, a value that is not finite or (1 or 3 channels) is negative, a matrix (6 channels) that is
    // not positive semi-definite, a max_value below its largest value, or (with use_grid_bbox) stored
    // bounds that are not a finite box.
    GridVolume(VolumeGrid grid, const GridVolumeOptions &options);
    int channels() const override { return int(grid_.channels); }
    Color eval(const Vec3 &p) const override;
    SymmetricMatrix3 eval_matrix(const Vec3 &p) const override;
    float max() const override { return max_; }
    BBox bounds() const override { return bounds_; }
    // Whether every grid point holds the same value (then so does every lookup).
    bool uniform() const { return uniform_; }

private:
    template <class Value, class Fetch> Value interpolate(const Vec3 &p, Fetch texel) const;
    Color texel(int64_t x, int64_t y, int64_t z) const;
    SymmetricMatrix3 texel_matrix(int64_t x, int64_t y, int64_t z) const;
    int64_t wrap(int64_t i, uint32_t n) const;

    VolumeGrid grid_;
    GridVolumeOptions options_;
    Transform to_local_;  // world to the unit cube
    float max_ = 0;
    bool uniform_ = false;
    BBox bounds_;
};

}  // namespace neepp
