#include "python/engine/engine_error.hpp"

#include <string>

namespace py = pybind11;

namespace galpha::python {
namespace {

// The exception type, owned by the module (which keeps a reference as an attribute); a raw pointer
// so that no destructor runs at interpreter shutdown after Python is gone.
PyObject* engine_error_type = nullptr;

void RaiseEngineError(const absl::Status& status) {
  const std::string message(status.message());
  py::object type = py::reinterpret_borrow<py::object>(engine_error_type);
  py::object error = type(message);
  error.attr("code") = static_cast<int>(status.code());
  error.attr("message") = message;
  PyErr_SetObject(engine_error_type, error.ptr());
}

}  // namespace

void RegisterEngineError(py::module_& module) {
  engine_error_type = PyErr_NewExceptionWithDoc(
      "galpha._engine.EngineError",
      "A failed engine call: `code` is the absl status code number (gRPC's numbers), `message` names the problem.",
      PyExc_Exception, nullptr);
  if (engine_error_type == nullptr) throw py::error_already_set();
  module.attr("EngineError") = py::reinterpret_borrow<py::object>(engine_error_type);
  // pybind11 fixes the signature (ExceptionTranslator takes the pointer by value).
  py::register_exception_translator([](std::exception_ptr thrown) {  // NOLINT(performance-unnecessary-value-param)
    if (!thrown) return;
    try {
      std::rethrow_exception(thrown);
    } catch (const StatusError& e) {
      RaiseEngineError(e.status());
    }
  });
}

void ThrowIfError(const absl::Status& status) {
  if (!status.ok()) throw StatusError(status);
}

}  // namespace galpha::python
