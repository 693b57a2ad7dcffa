// Rendering: the exact depth and labels agree with the world's planes; each part of the noise
// model does what its equation says; frames are deterministic on any number of threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "kartograf/synth/ray_caster.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf::synth {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
const PinholeIntrinsics kSmall{160, 120, 131.25, 131.25, 79.5, 59.5};

// The camera-frame ray of pixel (u, v), z = 1.
Eigen::Vector3d pixel_ray(const PinholeIntrinsics& k, int u, int v) {
  return {(u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0};
}

class SynthRender : public ::testing::Test {
 protected:
  World world = make_building(5);
  Trajectory tour = robot_tour(world, 300);

  // A few poses around the tour: in rooms, in doorways, crossing the corridor.
  std::vector<Eigen::Isometry3d> poses() const {
    return {tour[0].pose, tour[40].pose, tour[95].pose, tour[170].pose, tour[250].pose};
  }

  static double median(std::vector<double> values) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
  }
};

TEST_F(SynthRender, ExactDepthLiesOnTheGroundTruthPlaneInsideItsPolygon) {
  for (const Eigen::Isometry3d& pose : poses()) {
    const SyntheticFrame f = render(world, kSmall, pose, NoiseModel::none(), 1);
    double worst_quantized = 0, worst_float = 0;
    int outside_polygon = 0;
    for (int v = 0; v < kSmall.height; ++v) {
      for (int u = 0; u < kSmall.width; ++u) {
        const Label id = f.plane_id(u, v);
        ASSERT_NE(id, 0) << "the building is closed: every ray hits a face";
        const Plane& plane = world.plane(id);
        EXPECT_EQ(f.semantic(u, v), plane.semantic);
        ASSERT_GT(f.depth(u, v), 0);
        const Eigen::Vector3d ray = pixel_ray(kSmall, u, v);
        const Eigen::Vector3d p_quantized = pose * (ray * (f.depth(u, v) / kTumDepthUnitsPerMetre));
        const Eigen::Vector3d p_float = pose * (ray * static_cast<double>(f.depth_metres(u, v)));
        worst_quantized = std::max(worst_quantized, std::fabs(plane.signed_distance(p_quantized)));
        worst_float = std::max(worst_float, std::fabs(plane.signed_distance(p_float)));
        // The point lies in one of the plane's rectangles (axis-aligned: their bounding boxes).
        bool inside = false;
        for (const auto& polygon : plane.polygons) {
          Eigen::Vector3d lo = polygon[0], hi = polygon[0];
          for (const auto& q : polygon) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
          inside |= ((p_float - lo).minCoeff() > -1e-5 && (hi - p_float).minCoeff() > -1e-5);
        }
        outside_polygon += inside ? 0 : 1;
      }
    }
    // Depth is rounded to 1/5000 m: at most 0.1 mm along the ray (less across the plane).
    EXPECT_LT(worst_quantized, 1e-3 + 0.5 / kTumDepthUnitsPerMetre);
    EXPECT_LT(worst_quantized,
              0.5 / kTumDepthUnitsPerMetre * 1.8);  // |ray| <= 1.8 at these intrinsics
    EXPECT_LT(worst_float, 1e-5);                   // float rounding of a few metres
    EXPECT_EQ(outside_polygon, 0);
  }
}

TEST_F(SynthRender, RasterizedSurfacesAreWhatRayCastingFinds) {
  // Two independent visibility computations: the renderer's polygon rasterization and the ray
  // caster's grid walk through the boxes. They agree except where a pixel's ray passes exactly
  // through an edge between two surfaces (then both are right).
  const RayCaster caster(world);
  int differ = 0, total = 0;
  for (const Eigen::Isometry3d& pose : poses()) {
    const SyntheticFrame f = render(world, kSmall, pose, NoiseModel::none(), 1);
    for (int v = 0; v < kSmall.height; ++v) {
      for (int u = 0; u < kSmall.width; ++u) {
        const auto hit = caster.cast(pose.translation(), pose.linear() * pixel_ray(kSmall, u, v));
        ASSERT_TRUE(hit.has_value());
        ++total;
        if (hit->plane != f.plane_id(u, v)) {
          ++differ;
          EXPECT_NEAR(hit->t, f.depth_metres(u, v), 1e-6);  // a tie at an edge
          continue;
        }
        EXPECT_NEAR(hit->t, f.depth_metres(u, v), 1e-6 * hit->t);
      }
    }
  }
  EXPECT_LE(differ, total / 10000);
}

TEST_F(SynthRender, AxialNoiseHasTheModelsSigma) {
  NoiseModel axial = NoiseModel::none();
  axial.axial = true;
  // Point-to-plane distances normalised by the model's sigma there (sigma_z times |n . ray|, the
  // ray scaled to z = 1): half-normal, median 0.6745. Tolerance: 5 % (about 40000 samples, and
  // the 0.1 mm depth rounding adds < 1 % to sigma >= 1.2 mm).
  std::vector<double> near, far;  // z below / above 2 m
  for (std::size_t i = 0; i < poses().size(); ++i) {
    const Eigen::Isometry3d pose = poses()[i];
    const SyntheticFrame f = render(world, kSmall, pose, axial, 100 + i);
    for (int v = 0; v < kSmall.height; ++v) {
      for (int u = 0; u < kSmall.width; ++u) {
        if (f.depth(u, v) == 0) continue;
        const Plane& plane = world.plane(f.plane_id(u, v));
        const Eigen::Vector3d ray_world = pose.linear() * pixel_ray(kSmall, u, v);
        const Eigen::Vector3d p =
            pose.translation() + ray_world * (f.depth(u, v) / kTumDepthUnitsPerMetre);
        const double z = f.depth_metres(u, v);
        const double cos_incidence = std::fabs(plane.normal.dot(ray_world)) / ray_world.norm();
        const double sigma_perp =
            axial.axial_sigma(z, std::acos(cos_incidence)) * std::fabs(plane.normal.dot(ray_world));
        (z < 2.0 ? near : far).push_back(std::fabs(plane.signed_distance(p)) / sigma_perp);
      }
    }
  }
  ASSERT_GT(near.size(), 10000u);
  ASSERT_GT(far.size(), 10000u);
  EXPECT_NEAR(median(near), 0.6745, 0.05 * 0.6745);
  EXPECT_NEAR(median(far), 0.6745, 0.05 * 0.6745);
  // And sigma itself: Nguyen et al.'s curve.
  EXPECT_NEAR(axial.axial_sigma(0.4, 0), 0.0012, 1e-12);
  EXPECT_NEAR(axial.axial_sigma(3.0, 0), 0.0012 + 0.0019 * 2.6 * 2.6, 1e-12);
}

TEST_F(SynthRender, QuantizationPutsDepthOnTheDisparityLattice) {
  NoiseModel quantized = NoiseModel::none();
  quantized.quantization = true;
  const SyntheticFrame f = render(world, kSmall, tour[40].pose, quantized, 3);
  const double fb = kSmall.fx * quantized.baseline;
  int checked = 0;
  for (int v = 0; v < kSmall.height; ++v) {
    for (int u = 0; u < kSmall.width; ++u) {
      if (f.depth(u, v) == 0) continue;
      const double z = f.depth(u, v) / kTumDepthUnitsPerMetre;
      const double steps = fb / z * quantized.subpixel;  // disparity in 1/8 pixels
      // The 16-bit rounding (<= 0.1 mm) moves it by at most fb * 8 / z^2 * 1e-4.
      EXPECT_NEAR(steps, std::round(steps), fb * quantized.subpixel / (z * z) * 1.01e-4) << z;
      // The true depth's disparity rounds to that lattice point.
      const double true_steps = fb / f.depth_metres(u, v) * quantized.subpixel;
      EXPECT_LE(std::fabs(true_steps - std::round(steps)), 0.5 + 1e-4) << z;
      ++checked;
    }
  }
  EXPECT_GT(checked, 15000);
}

TEST_F(SynthRender, RangeGrazingAndDarkDropouts) {
  NoiseModel range = NoiseModel::none();
  range.min_range = 0.4;
  range.max_range = 3.0;
  NoiseModel grazing = NoiseModel::none();
  grazing.grazing_dropout = true;
  int grazing_pixels = 0;
  for (const Eigen::Isometry3d& pose : poses()) {
    const SyntheticFrame a = render(world, kSmall, pose, range, 1);
    const SyntheticFrame b = render(world, kSmall, pose, grazing, 1);
    for (int v = 0; v < kSmall.height; ++v) {
      for (int u = 0; u < kSmall.width; ++u) {
        const double z = a.depth_metres(u, v);
        EXPECT_EQ(a.depth(u, v) > 0, z >= 0.4 && z <= 3.0) << z;
        const Eigen::Vector3d ray = pose.linear() * pixel_ray(kSmall, u, v);
        const double angle =
            std::acos(std::fabs(world.plane(b.plane_id(u, v)).normal.dot(ray)) / ray.norm()) /
            kDegree;
        if (angle > 78.0 + 1e-6) {
          EXPECT_EQ(b.depth(u, v), 0) << angle;
        }
        if (angle < 70.0 - 1e-6) {
          EXPECT_GT(b.depth(u, v), 0) << angle;
        }
        grazing_pixels += angle > 74.0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(grazing_pixels, 20);  // walls along the view and the floor far ahead

  const Eigen::Isometry3d pose = tour[95].pose;
  // Dark surfaces: paint everything with albedo 0.03 (dark_albedo 0.1): 70 % of returns drop.
  World dark = world;
  for (Material& m : dark.materials) {
    m.pattern = Pattern::solid;
    m.color_a = Eigen::Vector3d::Constant(0.03);
    m.noise_amplitude = 0;
  }
  NoiseModel dark_model = NoiseModel::none();
  dark_model.dark_dropout = true;
  const SyntheticFrame d = render(dark, kSmall, pose, dark_model, 9);
  const double missing =
      static_cast<double>(std::count(d.depth.pixels().begin(), d.depth.pixels().end(), 0)) /
      d.depth.size();
  EXPECT_NEAR(missing, 0.7, 0.02);
}

TEST_F(SynthRender, FlyingPixelsLieBetweenForeAndBackground) {
  NoiseModel flying = NoiseModel::none();
  flying.flying_pixels = true;
  flying.flying_fraction = 1.0;
  int flying_pixels = 0;
  for (const Eigen::Isometry3d& pose : poses()) {
    const SyntheticFrame f = render(world, kSmall, pose, flying, 4);
    for (int v = 1; v + 1 < kSmall.height; ++v) {
      for (int u = 1; u + 1 < kSmall.width; ++u) {
        const double z = f.depth(u, v) / kTumDepthUnitsPerMetre;
        const double zt = f.depth_metres(u, v);
        double lo = zt, hi = zt;
        for (auto [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const double zn = f.depth_metres(u + du, v + dv);
          if (std::fabs(zn - zt) > flying.flying_min_jump)
            lo = std::min(lo, zn), hi = std::max(hi, zn);
        }
        if (lo == hi) {
          EXPECT_NEAR(z, zt, 1.01e-4);  // no edge: exact (to the 0.2 mm depth unit)
        } else {
          EXPECT_GE(z, lo - 1e-4);
          EXPECT_LE(z, hi + 1e-4);
          flying_pixels += std::fabs(z - zt) > 1e-3 ? 1 : 0;
        }
      }
    }
  }
  EXPECT_GT(flying_pixels, 100);
}

TEST_F(SynthRender, DeterministicOnAnyThreadCountAndSeededPerFrame) {
  const SyntheticFrame a = render(world, kSmall, tour[40].pose, NoiseModel::kinect(), 77, {1});
  const SyntheticFrame b = render(world, kSmall, tour[40].pose, NoiseModel::kinect(), 77, {3});
  const SyntheticFrame c = render(world, kSmall, tour[40].pose, NoiseModel::kinect(), 78, {2});
  EXPECT_TRUE(
      std::equal(a.depth.pixels().begin(), a.depth.pixels().end(), b.depth.pixels().begin()));
  EXPECT_TRUE(
      std::equal(a.color.pixels().begin(), a.color.pixels().end(), b.color.pixels().begin()));
  EXPECT_TRUE(std::equal(a.plane_id.pixels().begin(), a.plane_id.pixels().end(),
                         b.plane_id.pixels().begin()));
  EXPECT_FALSE(
      std::equal(a.depth.pixels().begin(), a.depth.pixels().end(), c.depth.pixels().begin()));
  EXPECT_TRUE(std::equal(a.plane_id.pixels().begin(), a.plane_id.pixels().end(),
                         c.plane_id.pixels().begin()));
  // The Kinect model loses some returns, but not most.
  const double missing =
      static_cast<double>(std::count(a.depth.pixels().begin(), a.depth.pixels().end(), 0)) /
      a.depth.size();
  EXPECT_GT(missing, 0.0);
  EXPECT_LT(missing, 0.5);
}

TEST_F(SynthRender, ColourIsTexturedAndViewIndependent) {
  // Two cameras looking exactly at the same surface points through their principal points
  // (integer cx, cy: the pixel centre's ray is the optical axis) see the same colour.
  const PinholeIntrinsics k{41, 41, 60.0, 60.0, 20.0, 20.0};
  const SyntheticFrame first = render(world, kSmall, tour[95].pose, NoiseModel::none(), 1);
  int compared = 0;
  for (int v = 10; v < kSmall.height; v += 25) {
    for (int u = 10; u < kSmall.width; u += 35) {
      const Eigen::Vector3d target =
          tour[95].pose * (pixel_ray(kSmall, u, v) * static_cast<double>(first.depth_metres(u, v)));
      for (const Eigen::Vector3d& offset :
           {Eigen::Vector3d(0.3, -0.2, 0.25), Eigen::Vector3d(-0.25, 0.3, -0.2)}) {
        const Eigen::Vector3d eye = tour[95].pose.translation() + offset;
        const Eigen::Vector3d forward = (target - eye).normalized();
        Eigen::Isometry3d pose =
            camera_pose(eye, std::atan2(forward.y(), forward.x()), std::asin(-forward.z()));
        const SyntheticFrame second = render(world, k, pose, NoiseModel::none(), 1);
        if (second.plane_id(20, 20) != first.plane_id(u, v)) continue;  // occluded from there
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(second.color(20, 20)[c], first.color(u, v)[c], 1);
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 10);
  // Textures give colour gradients: plenty of neighbouring pixels differ on the same plane.
  int gradients = 0;
  for (int v = 0; v < kSmall.height; ++v) {
    for (int u = 1; u < kSmall.width; ++u) {
      if (first.plane_id(u, v) != first.plane_id(u - 1, v)) continue;
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(first.color(u, v)[c] - first.color(u - 1, v)[c]);
      gradients += diff >= 3 ? 1 : 0;
    }
  }
  EXPECT_GT(gradients, static_cast<int>(kSmall.width * kSmall.height / 20));
}

}  // namespace
}  // namespace kartograf::synth
