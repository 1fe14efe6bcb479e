// gssm.Error and its subclasses: every C++ gssm exception arrives in Python
// as the matching class with the C++ message unchanged.
#include "bindings.h"

#include "gssm/core/error.h"

namespace gssm::python {

void bindErrors(py::module_& m) {
  // Registered base first: pybind11 tries the most recent translator first,
  // so each subclass is caught as itself.
  auto& error = py::register_exception<Error>(m, "Error", PyExc_RuntimeError);
  py::register_exception<InvalidArgument>(m, "InvalidArgument", error.ptr());
  py::register_exception<InputError>(m, "InputError", error.ptr());
  py::register_exception<NumericalError>(m, "NumericalError", error.ptr());
  py::register_exception<CheckpointError>(m, "CheckpointError", error.ptr());
}

}  // namespace gssm::python
