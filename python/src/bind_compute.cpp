#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>

#include "bindings.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/intrinsics.hpp"

namespace kartograf::python {

namespace nb = nanobind;

namespace {

// "auto" honours KARTOGRAF_BACKEND, as the CLI does; a named backend is that one.
compute::Context make_context(const std::string& backend) {
  if (backend == "auto") return compute::Context::from_environment();
  compute::ContextParams params;
  params.backend = compute::parse_backend_choice(backend, "backend");
  params.read_device_environment();
  return compute::Context(params);
}

nb::dict device_dict(const compute::DeviceInfo& info) {
  nb::dict d;
  d["backend"] = std::string(compute::to_string(info.backend));
  d["name"] = info.name;
  d["type"] = std::string(compute::to_string(info.type));
  d["api_version"] = info.api_version;
  d["driver"] = info.driver;
  d["memory_bytes"] = info.memory_bytes;
  d["usable"] = info.usable;
  return d;
}

nb::list backends() {
  nb::list out;
  for (const compute::BackendStatus& status : compute::probe_backends()) {
    nb::dict d;
    d["backend"] = std::string(compute::to_string(status.backend));
    d["available"] = status.available;
    d["reason"] = status.reason;
    nb::list devices;
    for (const compute::DeviceInfo& info : status.devices) devices.append(device_dict(info));
    d["devices"] = devices;
    out.append(d);
  }
  return out;
}

void bind_intrinsics(nb::module_& m) {
  nb::class_<PinholeIntrinsics>(m, "PinholeIntrinsics")
      .def(nb::init<>())
      .def(
          "__init__",
          [](PinholeIntrinsics* self, int width, int height, double fx, double fy, double cx,
             double cy) {
            new (self) PinholeIntrinsics{width, height, fx, fy, cx, cy};
            self->validate("PinholeIntrinsics");
          },
          nb::arg("width"), nb::arg("height"), nb::arg("fx"), nb::arg("fy"), nb::arg("cx"),
          nb::arg("cy"))
      .def_rw("width", &PinholeIntrinsics::width)
      .def_rw("height", &PinholeIntrinsics::height)
      .def_rw("fx", &PinholeIntrinsics::fx)
      .def_rw("fy", &PinholeIntrinsics::fy)
      .def_rw("cx", &PinholeIntrinsics::cx)
      .def_rw("cy", &PinholeIntrinsics::cy)
      .def_static("kinect_7scenes", &PinholeIntrinsics::kinect_7scenes)
      .def("__eq__", [](const PinholeIntrinsics& a, const PinholeIntrinsics& b) { return a == b; })
      .def("__getstate__",
           [](const PinholeIntrinsics& c) {
             return nb::make_tuple(c.width, c.height, c.fx, c.fy, c.cx, c.cy);
           })
      .def("__setstate__",
           [](PinholeIntrinsics* self, const nb::tuple& t) {
             new (self) PinholeIntrinsics{nb::cast<int>(t[0]),    nb::cast<int>(t[1]),
                                          nb::cast<double>(t[2]), nb::cast<double>(t[3]),
                                          nb::cast<double>(t[4]), nb::cast<double>(t[5])};
           })
      .def("__repr__", [](const PinholeIntrinsics& c) {
        return "PinholeIntrinsics(width=" + std::to_string(c.width) +
               ", height=" + std::to_string(c.height) + ", fx=" + std::to_string(c.fx) +
               ", fy=" + std::to_string(c.fy) + ", cx=" + std::to_string(c.cx) +
               ", cy=" + std::to_string(c.cy) + ")";
      });
}

}  // namespace

void bind_compute(nb::module_& m) {
  nb::class_<compute::Context>(m, "Context")
      .def(
          "__init__",
          [](compute::Context* self, const std::string& backend) {
            new (self) compute::Context(make_context(backend));
          },
          nb::arg("backend") = "auto",
          "A compute context: 'auto' (KARTOGRAF_BACKEND, else the best GPU, else the CPU), "
          "'cpu', 'vulkan' or 'opencl'. A backend that is missing is an Error.")
      .def_prop_ro(
          "backend",
          [](const compute::Context& c) { return std::string(compute::to_string(c.backend())); })
      .def_prop_ro("device", [](const compute::Context& c) { return device_dict(c.device_info()); })
      .def("finish", &compute::Context::finish);
  m.def("backends", &backends, "Every backend: whether it is available, why not, its devices");
  bind_intrinsics(m);
}

}  // namespace kartograf::python
