#pragma once
// The parts of the extension module kartograf._kartograf, one per library area (module.cpp joins
// them). Each binds the C++ API as it is; the Python package (python/kartograf) adds the
// dataclasses that make results plain, picklable values.
#include <nanobind/nanobind.h>

namespace kartograf::python {

void bind_compute(nanobind::module_& m);   // contexts, backends, intrinsics, errors
void bind_sequence(nanobind::module_& m);  // sequence folders, synthetic data sets
void bind_odometry(nanobind::module_& m);  // frame-by-frame odometry, odometry runs
void bind_mapping(nanobind::module_& m);   // SLAM
void bind_mapper(nanobind::module_& m);    // the online mapper, its mesh, grids and ESDF
void bind_eval(nanobind::module_& m);      // trajectory metrics
void bind_scene(nanobind::module_& m);     // planes of frames, rooms of 2-D maps

}  // namespace kartograf::python
