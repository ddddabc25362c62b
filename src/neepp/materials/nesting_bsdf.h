// Base of BSDFs made of other BSDFs (twosided, blendbsdf, mask): their flags and whether they read the
// tangent are those of the BSDFs they hold, read once, when built. Asked at every call instead, each
// asking its nested BSDFs (one object twice, when a twosided's back is its front or a blend's two are
// one), a chain of them would take 2^depth calls.
#pragma once
#include <initializer_list>
#include "neepp/base/bsdf.h"

namespace neepp {

class NestingBSDF : public BSDF {
public:
    uint32_t flags() const final { return flags_; }
    bool needs_tangents() const final { return tangents_; }

protected:
    // The flags of all of nested, with extra_flags (a mask's null lobe).
    explicit NestingBSDF(std::initializer_list<const BSDF *> nested, uint32_t extra_flags = 0) : flags_(extra_flags) {
        for (const BSDF *b : nested) {
            flags_ |= b->flags();
            tangents_ = tangents_ || b->needs_tangents();
        }
    }

private:
    uint32_t flags_;
    bool tangents_ = false;
};

}  // namespace neepp
