// neepp._neepp: the renderer's library as a Python extension (nanobind). The Python package `neepp`
// (python/neepp/) wraps it; each file here binds one concept.
#include <nanobind/nanobind.h>
#include "bindings.h"

NB_MODULE(_neepp, m) {
    m.doc() = "neepp's renderer library (wrapped by the `neepp` package; use that)";
    neepp::python::bind_errors(m);
    neepp::python::bind_images(m);
    neepp::python::bind_scene(m);
    neepp::python::bind_render(m);
    neepp::python::bind_visibility(m);
    neepp::python::bind_live_render(m);
    neepp::python::bind_checkpoint(m);
}
