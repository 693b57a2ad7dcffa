// kartograf._kartograf: the C++ library for Python (python/kartograf wraps it).
#include <nanobind/nanobind.h>

#include "bindings.hpp"
#include "kartograf/core/error.hpp"

NB_MODULE(_kartograf, m) {
  m.doc() = "Kartograf's C++ library (use the kartograf package, which wraps this module)";
  // Every kartograf::Error reaches Python as kartograf.Error, with the library's message.
  nanobind::exception<kartograf::Error>(m, "Error", PyExc_RuntimeError);
  kartograf::python::bind_compute(m);
  kartograf::python::bind_sequence(m);
  kartograf::python::bind_odometry(m);
  kartograf::python::bind_mapping(m);
  kartograf::python::bind_eval(m);
  kartograf::python::bind_scene(m);
}
