// Mitsuba 3's `mesh_attribute` texture: a mesh's per-vertex attribute interpolated over the triangle hit
// (barycentrically), or its per-face attribute, times `scale`; no colour conversion. A one-component
// attribute reads as grey. Names start with "vertex_" or "face_" (e.g. "vertex_color" from a PLY file's
// r, g, b properties).
#pragma once
#include <string>
#include "neepp/base/texture.h"

namespace neepp {

class MeshAttributeTexture final : public Texture {
public:
    // Throws std::invalid_argument when the name has neither prefix.
    explicit MeshAttributeTexture(std::string name, float scale = 1.f);
    Color eval(const SurfaceInteraction &si) const override;
    // Mitsuba has no mean of a mesh attribute (it depends on the shape); what samplers weigh by: 0.5.
    Color mean() const override { return Color(0.5f * scale_); }
    const std::string &name() const { return name_; }

private:
    std::string name_;
    float scale_;
};

}  // namespace neepp
