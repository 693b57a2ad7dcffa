#pragma once
// A trained Haar cascade (haar_cascade.hpp) run on organized views as it was trained, and its
// detections turned into objects of the hybrid map (semantic_grid.hpp: ObjectDetection).
//
// A view's grey normals image is made as for training (training/synthetic_stairs.hpp: absolute encoding,
// 5x5 smoothing); views wider than max_width are halved first (every other pixel), so that a
// 640x480 camera frame looks like the 320x240 training views. Detections are kept when their
// metric size (measure_detection) fits the class; each carries the points of its box's central
// half (the object, not what surrounds it) for placing it on the map.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/semantic/haar_cascade.hpp"
#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic {

struct ObjectDetectorParams {
  DetectionParams detection;
  int normals_smoothing_radius = 2;                // as the training views
  int max_width = 400;                             // wider views are halved until they are not
  SemanticClass label = SemanticClass::furniture;  // the class its objects take on the map
};

struct ViewDetection {
  Detection box;                        // in the view's pixels
  std::vector<Eigen::Vector3d> points;  // its central half's valid points, view frame
};

// Metric sizes a flight of stairs can have as measured by measure_detection on the square box of
// a detection (which also covers some wall or floor around it).
SizeLimits stairs_size_limits();

class ObjectDetector {
 public:
  // Throws Error on an empty cascade or bad limits.
  ObjectDetector(HaarCascade cascade, SizeLimits limits, ObjectDetectorParams params = {});
  // The shipped stairs cascade (semantic/stairs_cascade.yml.gz under core/models.hpp's folder)
  // with stairs_size_limits().
  static ObjectDetector stairs();
  static std::filesystem::path default_stairs_model_path();

  const std::string& object_class() const { return cascade_.object_class; }

  std::vector<ViewDetection> detect(const compute::Context& context,
                                    const PointImage& points) const;

 private:
  HaarCascade cascade_;
  SizeLimits limits_;
  ObjectDetectorParams params_;
};

// The map object of a detection whose points are in the map's frame (z up): footprint the convex
// hull of their xy, heights their z range. Throws Error with fewer than 3 points or a footprint
// without area.
ObjectDetection to_map_detection(const std::vector<Eigen::Vector3d>& points, SemanticClass label,
                                 std::string name);

}  // namespace kartograf::semantic
