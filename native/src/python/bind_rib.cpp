// RIB reading (and writing) for micropoly._native.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "rib/rib_reader.h"

namespace py = pybind11;

void bind_rib(py::module_& m) {
  m.def(
      "read_rib", [](const std::string& path) { return mp::read_rib_file(path).scene; }, py::arg("path"),
      "Reads a RIB file into a Scene.");
}
