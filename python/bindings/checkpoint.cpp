// Render checkpoints for neepp.distributed's driver: it saves the sums and the merged state of its rounds
// in the file format, with the identity and the atomic writing, of the CLI's --checkpoint, so that one
// file format and one identity check (with its messages) serve both, and each refuses the other's.
#include <nanobind/stl/function.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>
#include "bindings.h"
#include "neepp/io/atomic_file.h"
#include "neepp/render/checkpoint_identity.h"

namespace neepp::python {

void bind_checkpoint(nb::module_ &m) {
    m.def("render_identity",
          [](const Scene &scene, const std::string &integrator, const std::map<std::string, std::string> &options,
             uint64_t seed, const std::string &sampler, const std::map<std::string, std::string> &parameters) {
              const std::unique_ptr<Integrator> i = scene_integrator(scene, integrator, options);
              return render_identity(scene, *i, seed, sampler.empty() ? scene.settings.sampler : sampler, parameters).dump();
          },
          nb::arg("scene"), nb::arg("integrator"), nb::arg("options"), nb::arg("seed"), nb::arg("sampler"),
          nb::arg("parameters"),
          "What a checkpoint must match to be resumed (JSON text), as the CLI's --checkpoint records it: scene, "
          "parameters, integrator with its options, seed, sampler, film and filter.");
    m.def("checkpoint_bytes",
          [](const std::string &identity, int spp, int passes, double render_time_s, double seconds_per_spp,
             double light_paths, const Array1D<double> &image_sums, const Array1D<int64_t> &splat_sums,
             const nb::bytes &integrator_state, const std::string &driver) {
              RenderCheckpoint c;
              c.identity = identity;
              c.spp = spp;
              c.passes = passes;
              c.render_time_s = render_time_s;
              c.seconds_per_spp = seconds_per_spp;
              c.light_paths = light_paths;
              c.image_sums = numpy_to_vector<double>(image_sums);
              c.splat_sums = numpy_to_vector<int64_t>(splat_sums);
              c.integrator_state.assign(integrator_state.c_str(), integrator_state.size());
              c.driver = driver;
              const std::string bytes = checkpoint_bytes(c);
              return nb::bytes(bytes.data(), bytes.size());
          },
          nb::arg("identity"), nb::arg("spp"), nb::arg("passes"), nb::arg("render_time_s"), nb::arg("seconds_per_spp"),
          nb::arg("light_paths"), nb::arg("image_sums"), nb::arg("splat_sums"), nb::arg("integrator_state"),
          nb::arg("driver"),
          "A render checkpoint file's bytes (render_range's sums, added up; driver: the distributed driver's JSON).");
    m.def("checkpoint_to_resume",
          [](const std::string &path, const std::string &identity) {
              RenderCheckpoint c = checkpoint_to_resume(path, nlohmann::json::parse(identity));
              nb::dict out;
              out["identity"] = c.identity;
              out["spp"] = c.spp;
              out["passes"] = c.passes;
              out["render_time_s"] = c.render_time_s;
              out["seconds_per_spp"] = c.seconds_per_spp;
              out["light_paths"] = c.light_paths;
              out["image_sums"] = vector_to_numpy(std::move(c.image_sums));
              out["splat_sums"] = vector_to_numpy(std::move(c.splat_sums));
              out["integrator_state"] = nb::bytes(c.integrator_state.data(), c.integrator_state.size());
              out["driver"] = c.driver;
              return out;
          },
          nb::arg("path"), nb::arg("identity"),
          "Reads the checkpoint at path, checked against this render's identity (render_identity's JSON, with "
          "\"distributed\" for a distributed render): RuntimeError naming what differs when it is another render's, "
          "missing or damaged. Returns its fields as a dict.");
    m.def("write_file_atomically",
          [](const std::string &path, const std::function<void(const std::string &)> &write) {
              write_file_atomically(path, write);
          },
          nb::arg("path"), nb::arg("write"),
          "Calls write(temporary) to write a hidden temporary beside path, flushes it to disk and renames it over "
          "path, as the CLI writes its checkpoints: path is always either the old file or the new one.");
    m.def("remove_checkpoint", &remove_checkpoint, nb::arg("path"),
          "Removes a finished render's checkpoint, and the temporaries that saves of it killed half-way left.");
}

}  // namespace neepp::python
