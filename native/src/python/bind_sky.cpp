// The Sky Texture node's precomputation for micropoly._native
// (sky/sky_nishita.h): the texture and the sun disc's values that
// the add-on's node compiler writes into the world's program.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstring>
#include <string>

#include "micropoly/error.h"
#include "sky/sky_nishita.h"

namespace py = pybind11;

namespace {

mp::SkyModel sky_model(const std::string& name) {
  if (name == "NISHITA") return mp::SkyModel::Nishita;
  if (name == "SINGLE_SCATTERING") return mp::SkyModel::SingleScattering;
  if (name == "MULTIPLE_SCATTERING") return mp::SkyModel::MultipleScattering;
  throw mp::Error("sky model '" + name + "' is not one of NISHITA, SINGLE_SCATTERING, MULTIPLE_SCATTERING");
}

mp::SkyParameters sky_parameters(const std::string& model, bool sun_disc, float sun_size, float sun_intensity,
                                 float sun_elevation, float sun_rotation, float altitude, float air, float dust,
                                 float ozone) {
  mp::SkyParameters p;
  p.model = sky_model(model);
  p.sun_disc = sun_disc;
  p.sun_size = sun_size;
  p.sun_intensity = sun_intensity;
  p.sun_elevation = sun_elevation;
  p.sun_rotation = sun_rotation;
  p.altitude = altitude;
  p.air = air;
  p.dust = dust;
  p.ozone = ozone;
  return p;
}

py::tuple vec3(const glm::vec3& v) { return py::make_tuple(v.x, v.y, v.z); }

py::dict sun_dict(const mp::SkyLookup& s) {
  py::dict d;
  d["sun_bottom"] = vec3(s.sun_bottom);
  d["sun_top"] = vec3(s.sun_top);
  d["sun_flux"] = vec3(s.sun_flux);
  d["sun_elevation"] = s.sun_elevation;
  d["sun_rotation"] = s.sun_rotation;
  d["sun_diameter"] = s.sun_diameter;
  d["sun_intensity"] = s.sun_intensity;
  d["earth_angle"] = s.earth_angle;
  d["spread"] = s.spread;
  d["layout"] = s.layout;
  return d;
}

}  // namespace

// What both functions take, appended to their docstrings.
#define MP_SKY_ARGS_DOC                                                                                          \
  " model: the node's sky_type (NISHITA, SINGLE_SCATTERING or MULTIPLE_SCATTERING); the other settings as the " \
  "node holds them (radians, metres); dust is 5.0's aerosol_density. spread: the angle over which the sun "     \
  "disc's light is spread for a world baked into a map (0: the exact disc; kernels/textures/mp_tex_sky.h)."

void bind_sky(py::module_& m) {
  m.def(
      "nishita_sky_sun",
      [](const std::string& model, bool sun_disc, float sun_size, float sun_intensity, float sun_elevation,
         float sun_rotation, float altitude, float air, float dust, float ozone, float spread) {
        mp::SkyParameters p = sky_parameters(model, sun_disc, sun_size, sun_intensity, sun_elevation, sun_rotation,
                                             altitude, air, dust, ozone);
        mp::SkyLookup s;
        {
          py::gil_scoped_release release;
          s = mp::sky_lookup_parameters(p, spread);
        }
        return sun_dict(s);
      },
      py::arg("model") = "NISHITA", py::arg("sun_disc") = true, py::arg("sun_size") = 0.009512f,
      py::arg("sun_intensity") = 1.0f, py::arg("sun_elevation") = 0.2617994f, py::arg("sun_rotation") = 0.0f,
      py::arg("altitude") = 0.0f, py::arg("air") = 1.0f, py::arg("dust") = 1.0f, py::arg("ozone") = 1.0f,
      py::arg("spread") = 0.0f,
      "The Sky Texture's lookup values (sun disc radiance at its lowest and highest points and its integral, CIE "
      "XYZ; the sun's position in Cycles' form; layout) as a dict." MP_SKY_ARGS_DOC);
  m.def(
      "nishita_sky_texture",
      [](const std::string& model, bool sun_disc, float sun_size, float sun_intensity, float sun_elevation,
         float sun_rotation, float altitude, float air, float dust, float ozone, float spread) {
        mp::SkyParameters p = sky_parameters(model, sun_disc, sun_size, sun_intensity, sun_elevation, sun_rotation,
                                             altitude, air, dust, ozone);
        mp::SkyTexture t;
        mp::SkyLookup s;
        {
          py::gil_scoped_release release;
          t = mp::sky_texture(p);
          s = mp::sky_lookup_parameters(p, spread);
        }
        py::array_t<float> rgba({py::ssize_t(t.height), py::ssize_t(t.width), py::ssize_t(4)});
        std::memcpy(rgba.mutable_data(), t.texels.data(), t.texels.size() * sizeof(glm::vec4));
        return py::make_tuple(rgba, sun_dict(s));
      },
      py::arg("model") = "NISHITA", py::arg("sun_disc") = true, py::arg("sun_size") = 0.009512f,
      py::arg("sun_intensity") = 1.0f, py::arg("sun_elevation") = 0.2617994f, py::arg("sun_rotation") = 0.0f,
      py::arg("altitude") = 0.0f, py::arg("air") = 1.0f, py::arg("dust") = 1.0f, py::arg("ozone") = 1.0f,
      py::arg("spread") = 0.0f,
      "(texture, sun): the Sky Texture's precomputed texture as a float32 (height, width, 4) array (CIE XYZ "
      "radiance in rgb, rows bottom to top, Cycles' size and layout) and the dict nishita_sky_sun() gives."
      MP_SKY_ARGS_DOC);
}
