// Errors cross into Python as exceptions with the CLI's messages: a scene problem is neepp.SceneError
// (a ValueError) carrying file, line and problem; std::invalid_argument (a bad option) is ValueError and
// any other std::runtime_error (an unreadable file) RuntimeError, as nanobind translates them.
#include "bindings.h"
#include "neepp/io/scene_error.h"

namespace neepp::python {

void bind_errors(nb::module_ &m) {
    static PyObject *scene_error = PyErr_NewExceptionWithDoc(
        "neepp._neepp.SceneError",
        "A scene file, or a file it names, is malformed, missing or unsupported. str() reads "
        "'FILE:LINE: problem'; the attributes file, line (0 when no single line applies) and problem hold its parts.",
        PyExc_ValueError, nullptr);
    m.attr("SceneError") = nb::borrow(scene_error);
    nb::register_exception_translator(
        [](const std::exception_ptr &p, void *) {
            try {
                std::rethrow_exception(p);
            } catch (const SceneError &e) {
                nb::object error = nb::borrow(scene_error)(nb::str(e.what()));
                error.attr("file") = nb::str(e.file.c_str());
                error.attr("line") = e.line;
                error.attr("problem") = nb::str(e.problem.c_str());
                PyErr_SetObject(scene_error, error.ptr());
            }
        },
        nullptr);
}

}  // namespace neepp::python
