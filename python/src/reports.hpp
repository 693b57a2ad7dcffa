#pragma once
// Kartograf's reports as Python dicts of plain values (the package turns them into dataclasses).
#include <nanobind/nanobind.h>

#include "kartograf/mapping/slam.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::python {

nanobind::dict registration_dict(const registration::RegistrationReport& report);
nanobind::dict frame_dict(const registration::OdometryFrame& frame);
nanobind::dict odometry_run_dict(const mapping::OdometryRun& run);

}  // namespace kartograf::python
