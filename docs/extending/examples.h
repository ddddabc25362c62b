// The worked examples of docs/extending.md, each registered by a call before a scene that uses it loads.
#pragma once

namespace example {
void register_orennayar();           // BSDF "orennayar"
void register_downlight();           // emitter "downlight"
void register_torus();               // shape "torus"
void register_ambient_occlusion();   // integrator "ao"
}  // namespace example
