// RIB reading and writing for micropoly._native.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "rib/rib_reader.h"
#include "rib/rib_writer.h"

namespace py = pybind11;

void bind_rib(py::module_& m) {
  m.def(
      "read_rib",
      [](const std::string& path, const std::vector<std::string>& allowed_roots, bool allow_any_path) {
        mp::RibReadOptions options;
        options.allowed_roots = allowed_roots;
        options.allow_any_path = allow_any_path;
        return mp::read_rib_file(path, options).scene;
      },
      py::arg("path"), py::arg("allowed_roots") = std::vector<std::string>(), py::arg("allow_any_path") = false,
      "Reads a RIB file into a Scene. The scene may read archives and textures only inside its own folder and "
      "the folders in allowed_roots (after resolving '..' and symbolic links), and its material programs may not "
      "include files or use inline assembly; allow_any_path trusts the file and lifts both rules. Raises Error on "
      "malformed input, a file outside those folders or a refused program.");

  auto write = [](const mp::Scene& scene, const std::string& path, const std::string& display) {
    py::gil_scoped_release release;  // large meshes take a while to format
    mp::write_rib_file(scene, path, display);
  };
  const char* doc =
      "Writes the scene as a RIB file that read_rib() (and micropoly-render) turns back into the same "
      "scene. display: optional output image name for a Display request. Raises Error if the scene is "
      "invalid or the file cannot be written.";
  m.def("write_rib", write, py::arg("scene"), py::arg("path"), py::arg("display") = "", doc);

  // Also as a method, Scene.write_rib(path): the class is registered in
  // module.cpp, so the method is attached to it here the way class_::def does.
  py::object scene_class = m.attr("Scene");
  scene_class.attr("write_rib") = py::cpp_function(
      write, py::name("write_rib"), py::is_method(scene_class),
      py::sibling(py::getattr(scene_class, "write_rib", py::none())), py::arg("path"),
      py::arg("display") = "", doc);
}
