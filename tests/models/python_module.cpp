// gssm_test_models: loading it registers the test tree's models (their
// static registrations run), which gssm.models then lists.
#include <pybind11/pybind11.h>

PYBIND11_MODULE(gssm_test_models, m) { m.doc() = "Models of gssm's test tree (tests/models), registered on import."; }
