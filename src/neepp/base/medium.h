// Participating media and phase functions, as Mitsuba 3 defines them: a medium gives its extinction and
// scattering coefficients at a point and a majorant that bounds the extinction, with which free-flight
// distances are sampled (delta tracking) and transmittance estimated (ratio tracking); a phase function
// says how light scatters at a point of it. Both take the direction of travel too: a medium of oriented
// microflakes (the sggx phase function) is denser to light crossing its flakes than to light grazing them.
// Media fill the insides and outsides of shapes that declare them (Shape::interior, Shape::exterior) and
// the space around a camera that sits in one.
#pragma once
#include <memory>
#include "neepp/math/bbox.h"
#include "neepp/math/vec.h"

namespace neepp {

struct Ray;

// Directions in world space. wi points back along the path (the negated direction of the ray that
// arrived), wo where the light goes next, as at a surface.
struct PhaseSample {
    Vec3 wo;
    float pdf = 0;     // solid-angle density of wo
    float weight = 0;  // value / pdf
};

class PhaseFunction {
public:
    virtual ~PhaseFunction() = default;
    // The phase function's value at the point p for light arriving along -wi and leaving along wo (it
    // integrates to 1 over wo), and the density with which sample() draws wo. Most phase functions are the
    // same everywhere and ignore p; a blend of two takes its weight from a volume at p.
    virtual float eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const = 0;
    virtual float pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const = 0;
    virtual PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const = 0;

    // A microflake phase function's projected area at p seen along w (the same along -w): the medium's
    // extinction there, for light travelling along w, is its density times this, as Mitsuba multiplies it
    // in for phase functions flagged Microflake. 1 for the others (a blendphase too, as in Mitsuba).
    virtual float projected_area(const Vec3 & /*p*/, const Vec3 & /*w*/) const { return 1.f; }
    // A bound on projected_area over every point and direction (a heterogeneous medium's majorant).
    virtual float max_projected_area() const { return 1.f; }
};

// The coefficients at a point: extinction sigma_t = absorption + scattering sigma_s (per unit length).
struct MediumCoefficients {
    Color sigma_t{0.f}, sigma_s{0.f};
};

class Medium {
public:
    virtual ~Medium() = default;
    // The part [t0, t1] of the ray (within its tmin, tmax) where the medium may hold anything: the whole
    // ray for a homogeneous medium, the box of its density grid for a heterogeneous one. False when none.
    virtual bool overlap(const Ray &ray, float &t0, float &t1) const = 0;
    // A bound on sigma_t for light travelling along d everywhere in that part, per channel: free flights
    // are drawn against it and the difference is filled with null collisions (sigma_n = majorant -
    // sigma_t). The same in every direction unless the phase function is a microflake one.
    virtual Color majorant(const Vec3 &d) const = 0;
    // The coefficients at p for light travelling along d (or along -d: the same).
    virtual MediumCoefficients at(const Vec3 &p, const Vec3 &d) const = 0;
    // Whether sigma_t is the same everywhere along any one ray (then it is the majorant, and there are no
    // null collisions).
    virtual bool homogeneous() const = 0;

    // Set by each medium's constructor: its majorant may depend on it (a microflake one's projected area).
    std::shared_ptr<const PhaseFunction> phase;
    // Mitsuba's sample_emitters: whether scattering points in it sample lights (false: only light that a
    // phase-sampled path finds, as in the subsurface scenes whose lights lie outside a dielectric).
    bool sample_emitters = true;
};

}  // namespace neepp
