// Integrators by name: neepp's own (path, bdpt, light, pssmlt) from their options, and those a program
// registers.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include "neepp/base/integrator.h"

namespace neepp {

class ShadowRayTester;
// The shadow-ray component of an integrator, from the options every integrator shares (shadow_rays and
// NEE++'s options): one that keeps a visibility map when the policy reads one or needs_map says the
// integrator does (visibility-aware light selection, BDPT's light-path selection).
std::unique_ptr<ShadowRayTester> make_shadow_ray_tester(const Options &options, bool needs_map, int voxels,
                                                        bool defer_seeding);

// Creates an integrator by name (path, bdpt, light, pssmlt, or one registered) from its options; throws on
// unknown names or unused options.
std::unique_ptr<Integrator> make_integrator(const std::string &name, const Options &options);

// An integrator a program adds (docs/extending.md), built from its options under `name` as make_integrator
// builds its own; a scene file's <integrator type="name"> then selects it too. Throws std::invalid_argument
// for a name make_integrator has already. Register before use, not while another thread makes one.
using IntegratorPlugin = std::function<std::unique_ptr<Integrator>(const Options &)>;
void register_integrator(const std::string &name, IntegratorPlugin make);
bool integrator_registered(const std::string &name);

}  // namespace neepp
