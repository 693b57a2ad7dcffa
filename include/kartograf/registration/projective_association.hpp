#pragma once
// Projective data association for organized frames: each source point is moved by the current
// estimate and projected into the target camera; the target point at that pixel is its partner.
// O(1) per point and no search structure, so it suits GPUs and frame-to-frame odometry, where
// the motion between frames is small.
//
// Rules, identical on every backend, for source point i (see correspondence_finder.hpp for the
// entry codes): not is_selected(i, source width, k) -> kNotSelected; otherwise p must be valid
// and p' = R p + t (double) have p'.z > 0; (u, v) = (floor(fx p'.x / p'.z + cx + 0.5),
// floor(fy p'.y / p'.z + cy + 0.5)) with the target camera. Candidates are the target pixels
// within search_radius of (u, v) (row-major order) inside the image whose point q is valid and,
// with the normal gate on (max_normal_angle_deg < 180), whose normal n_q is valid with
// (R n_p) . n_q >= cos(max_normal_angle_deg) (n_p valid too). The first candidate with the
// smallest |p' - q| is the partner if |p' - q| <= max_distance; else kNoMatch.
// All of it in float (GPUs are fast at it; ~1e-4 pixel, ~1 um at 5 m), each sum and product in a
// fixed order without fused multiply-adds; division may differ by an ulp between drivers, so a
// projection within an ulp of half-way between two pixels, or two equally far candidates, may
// resolve differently on different backends (the tests allow for that).
#include "kartograf/compute/buffer.hpp"
#include "kartograf/registration/correspondence_finder.hpp"

namespace kartograf::registration {

class ProjectiveAssociation : public CorrespondenceFinder {
 public:
  explicit ProjectiveAssociation(const compute::Context& context);

  // Needs target.camera with target.points of its size, and both normal buffers when the normal
  // gate is on; throws Error otherwise.
  void find(const CloudView& source, const CloudView& target,
            const Eigen::Isometry3d& source_to_target, const AssociationParams& params,
            CorrespondenceBuffers& out) override;

 private:
  const compute::Context* context_;
  compute::Buffer<float> frame_;  // R, t, intrinsics, gates: what the kernel reads
};

}  // namespace kartograf::registration
