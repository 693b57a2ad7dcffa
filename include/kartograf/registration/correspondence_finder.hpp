#pragma once
// The swappable correspondence step of the ICP engine (icp.hpp), and the cloud view it works on.
//
// Each iteration the engine asks a CorrespondenceFinder for pairs at the current estimate; the
// finder writes, on the device, one entry per source point into CorrespondenceBuffers:
//   target_index[i] = j >= 0   source i pairs with target point j,
//                     kNoMatch  source i was looked at and has no partner (lowers fitness),
//                     kNotSelected   source i was left out by point selection;
//   weights[i] (optional)       a per-source weight, 0 rejects the pair (e.g. a colour gate).
// The reduction (icp_sums.hpp) then re-checks validity and max_distance, applies the robust kernel
// and sums the pairs; only those sums cross to the host.
//
// Plugging in a new finder (a k-d tree or voxel hash for unorganized clouds, a colour gate):
//   class KdTreeFinder : public CorrespondenceFinder {
//     void prepare(const CloudView& target, int level) override;   // build the tree of `target`
//     void find(const CloudView& source, const CloudView& target, const Eigen::Isometry3d& T,
//               const AssociationParams& params, CorrespondenceBuffers& out) override;
//   };
//   IcpEngine engine(context, params, std::make_unique<KdTreeFinder>(...));
// Honour params.subsample with is_selected() so that every finder selects the same points. A
// filter (the colour gate) wraps another finder: call the inner find(), then reject pairs by
// writing kNoMatch or a 0 weight. Finders keep their own device scratch (no allocation per call).
// A small virtual interface rather than a template policy: the finder is chosen at run time
// (command-line options), filters wrap finders, and the loop that calls it lives in a .cpp.
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/registration/icp_sums.hpp"

namespace kartograf::registration {

// One cloud as ICP sees it: device buffers, organized (with the camera of its pixel grid) or not.
struct CloudView {
  const compute::Buffer<Point4f>* points = nullptr;        // required
  const compute::Buffer<Point4f>* normals = nullptr;       // point-to-plane targets, normal gate
  const compute::Buffer<std::uint32_t>* colors = nullptr;  // packed RGB (color.hpp pack_rgb)
  std::optional<PinholeIntrinsics> camera;                 // organized: points are w x h pixels
  std::size_t size() const { return points ? points->size() : 0; }
};

// The gates one iteration applies; coarse pyramid levels get larger distances.
struct AssociationParams {
  double max_distance = 0.1;         // metres, |T p - q|
  double max_normal_angle_deg = 30;  // between R n_p and n_q; >= 180 disables the normal gate
  int subsample = 1;                 // uniform 1-in-k selection of source points
  // Organized targets: also look at the pixels within this radius of the projected one and take
  // the closest compatible point. 0 suits point-to-plane; point-to-point needs the closest point
  // (1-2): the projected pixel alone gives residuals along viewing rays, not towards the surface.
  int search_radius = 0;
};

// Uniform 1-in-k selection: point i of a cloud whose rows are `width` points long (0: unorganized)
// is selected when (i + row) % k == 0, so an organized frame gets a diagonal lattice rather than
// every k-th column. Shared by every finder: the rule is kernels/correspondence/selection.h.
bool is_selected(std::uint32_t i, std::uint32_t width, std::uint32_t k);

struct CorrespondenceBuffers {
  compute::Buffer<std::int32_t> target_index;
  compute::Buffer<float> weights;  // empty: no weights
};

class CorrespondenceFinder {
 public:
  virtual ~CorrespondenceFinder() = default;
  // Called once per align() for each pyramid level before the first find() on it.
  virtual void prepare(const CloudView& target, int level) {
    (void)target;
    (void)level;
  }
  // Fills out.target_index (sized source.size(), on the finder's context) and optionally
  // out.weights, for the pose `source_to_target`. Throws Error when the views lack what it needs.
  virtual void find(const CloudView& source, const CloudView& target,
                    const Eigen::Isometry3d& source_to_target, const AssociationParams& params,
                    CorrespondenceBuffers& out) = 0;
};

}  // namespace kartograf::registration
