// The unorganized-cloud operations on every available backend, for clouds of 20k and 300k points
// (a 4 x 3 x 2.5 m room with furniture, randomly sampled, coloured by surface):
//   color_gate/<backend>/<n>            HSI colour gate over n correspondences
//   voxel_downsample/<backend>/<n>      5 cm voxels, with normals and colours
//   nn_voxel_hash/<backend>/<n>/query   nearest neighbours within 5 cm, grid already built
//   nn_voxel_hash/<backend>/<n>/build+query   the same plus building and uploading the grid
//   nn_kdtree/cpu/<n>/query, .../build+query  the k-d tree finder (CPU only)
// Each: inputs resident on the device, one call + finish (median of 3 repetitions, wall clock),
// after a warm-up call; the source is the room sampled again and moved by 2 cm / 1 degree.
// KARTOGRAF_BENCH_BACKENDS=cpu,vulkan,opencl restricts the backends (default: all available).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "bench_support.hpp"
#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/geometry/voxel_downsample.hpp"
#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kartograf/registration/voxel_hash_correspondences.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;

struct Box {
  Eigen::Vector3f low, high;
  std::uint32_t color;
};

// Surfaces of the room: the inside of its box, and the outside of each piece of furniture.
const std::vector<Box>& room() {
  static const std::vector<Box> boxes = {
      {{0, 0, 0}, {4, 3, 2.5f}, 0xb4c8d2},               // walls, floor, ceiling
      {{0.5f, 0.5f, 0}, {1.7f, 1.3f, 0.75f}, 0x3c64a0},  // table
      {{3.2f, 0.2f, 0}, {3.8f, 2.0f, 1.9f}, 0x8c5a32},   // shelf
      {{1.5f, 2.2f, 0}, {2.5f, 2.9f, 0.45f}, 0x50a050},  // sofa
  };
  return boxes;
}

struct HostCloud {
  std::vector<Point4f> points, normals;
  std::vector<std::uint32_t> colors;
};

// n points uniformly on the room's box faces (area-weighted), with normals and noisy colours.
HostCloud sample_room(std::size_t n, std::uint64_t seed, const Eigen::Isometry3d& pose) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> noise(0.0f, 8.0f);
  struct Face {
    const Box* box;
    int axis;
    bool high;
    float area;
  };
  std::vector<Face> faces;
  float total = 0;
  for (const Box& box : room()) {
    const Eigen::Vector3f size = box.high - box.low;
    for (int axis = 0; axis < 3; ++axis) {
      for (bool high : {false, true}) {
        const float area = size((axis + 1) % 3) * size((axis + 2) % 3);
        faces.push_back({&box, axis, high, area});
        total += area;
      }
    }
  }
  const Eigen::Isometry3d inverse = pose.inverse();
  HostCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    float pick = unit(rng) * total;
    const Face* face = &faces.back();
    for (const Face& f : faces) {
      if ((pick -= f.area) <= 0) {
        face = &f;
        break;
      }
    }
    Eigen::Vector3f p;
    for (int a = 0; a < 3; ++a)
      p(a) = face->box->low(a) + unit(rng) * (face->box->high(a) - face->box->low(a));
    p(face->axis) = face->high ? face->box->high(face->axis) : face->box->low(face->axis);
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    normal(face->axis) = face->high ? 1 : -1;
    const Eigen::Vector3d moved = inverse * p.cast<double>();
    const Eigen::Vector3d turned = inverse.linear() * normal;
    cloud.points.emplace_back(moved.x(), moved.y(), moved.z(), 1.0f);
    cloud.normals.emplace_back(turned.x(), turned.y(), turned.z(), 0.0f);
    std::uint32_t color = 0;
    for (int c = 0; c < 3; ++c) {
      const float channel = static_cast<float>((face->box->color >> (8 * c)) & 0xff) + noise(rng);
      color |= static_cast<std::uint32_t>(std::clamp(std::lround(channel), 0L, 255L)) << (8 * c);
    }
    cloud.colors.push_back(color);
  }
  return cloud;
}

Eigen::Isometry3d sensor_motion() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.rotate(Eigen::AngleAxisd(std::numbers::pi / 180, Eigen::Vector3d::UnitZ()));
  pose.pretranslate(Eigen::Vector3d(0.02, -0.01, 0.0));
  return pose;
}

const HostCloud& host_cloud(std::size_t n, bool source) {
  static std::map<std::pair<std::size_t, bool>, HostCloud> clouds;
  auto [entry, inserted] = clouds.try_emplace({n, source});
  if (inserted) {
    entry->second =
        sample_room(n, source ? 2 : 1, source ? sensor_motion() : Eigen::Isometry3d::Identity());
  }
  return entry->second;
}

// Source and target resident on one context, and the finders' outputs.
struct Scene {
  Scene(const compute::Context& context, std::size_t n) {
    const HostCloud& s = host_cloud(n, true);
    const HostCloud& t = host_cloud(n, false);
    source.points = compute::Buffer<Point4f>::from_host(context, s.points);
    source.normals = compute::Buffer<Point4f>::from_host(context, s.normals);
    source.colors = compute::Buffer<std::uint32_t>::from_host(context, s.colors);
    target.points = compute::Buffer<Point4f>::from_host(context, t.points);
    target.normals = compute::Buffer<Point4f>::from_host(context, t.normals);
    target.colors = compute::Buffer<std::uint32_t>::from_host(context, t.colors);
    // Pairs for the colour gate: source i with target i (the same surface mostly), 10% none.
    pristine_pairs.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      pristine_pairs[i] = i % 10 == 3 ? -1 : static_cast<std::int32_t>(i);
    pairs = compute::Buffer<std::int32_t>::from_host(context, pristine_pairs);
  }
  registration::CloudView source_view() const {
    return {&source.points, nullptr, nullptr, std::nullopt};
  }
  registration::CloudView target_view() const {
    return {&target.points, nullptr, nullptr, std::nullopt};
  }

  geometry::DeviceCloud source, target;
  std::vector<std::int32_t> pristine_pairs;
  compute::Buffer<std::int32_t> pairs;
  registration::CorrespondenceBuffers found;
};

constexpr registration::AssociationParams kNearest{0.05, 180, 1, 0};

// What is measured on one context: `run` (holding its gate, finder or scratch), after an
// untimed `reset` of what the previous run changed.
struct Measured {
  std::function<void(Scene&)> run;
  std::function<void(Scene&)> reset = [](Scene&) {};
};
using Factory = std::function<Measured(const compute::Context&)>;

Factory color_gate() {
  return [](const compute::Context& context) {
    auto gate = std::make_shared<registration::ColorGate>(context);
    return Measured{[gate](Scene& s) { gate->apply(s.source.colors, s.target.colors, s.pairs); },
                    [](Scene& s) { s.pairs.upload(s.pristine_pairs); }};  // the gate edits them
  };
}

Factory voxel_downsample() {
  return [](const compute::Context& context) {
    auto downsampler = std::make_shared<geometry::VoxelDownsampler>(context);
    return Measured{
        [downsampler](Scene& s) { benchmark::DoNotOptimize(downsampler->run(s.target, {0.05f})); }};
  };
}

template <class Finder>
Factory nearest(bool rebuild) {
  return [rebuild](const compute::Context& context) {
    auto finder = std::make_shared<Finder>(context);
    return Measured{[finder, rebuild](Scene& s) {
      if (rebuild) finder->prepare(s.target_view(), 0);
      finder->find(s.source_view(), s.target_view(), sensor_motion(), kNearest, s.found);
    }};
  };
}

void run_benchmark(benchmark::State& state, BackendKind backend, const Factory& factory,
                   std::size_t n) {
  const compute::Context context(bench::context_options(backend));
  Scene scene(context, n);
  const Measured measured = factory(context);
  measured.run(scene);  // warm-up: pipelines built, driver JIT done, grids and tables built
  context.finish();
  for (auto _ : state) {
    state.PauseTiming();
    measured.reset(scene);
    context.finish();
    state.ResumeTiming();
    measured.run(scene);
    context.finish();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
  state.SetLabel(context.device_info().name);
}

void register_benchmarks() {
  struct Entry {
    std::string name;
    Factory factory;
    bool cpu_only;
  };
  const std::vector<Entry> entries = {
      {"color_gate", color_gate(), false},
      {"voxel_downsample", voxel_downsample(), false},
      {"nn_voxel_hash/query", nearest<registration::VoxelHashCorrespondences>(false), false},
      {"nn_voxel_hash/build+query", nearest<registration::VoxelHashCorrespondences>(true), false},
      {"nn_kdtree/query", nearest<registration::KdTreeCorrespondences>(false), true},
      {"nn_kdtree/build+query", nearest<registration::KdTreeCorrespondences>(true), true},
  };
  for (const BackendKind backend : bench::backends_to_run()) {
    for (const Entry& entry : entries) {
      if (entry.cpu_only && backend != BackendKind::cpu) continue;
      for (std::size_t n : {std::size_t{20000}, std::size_t{300000}}) {
        const auto slash = entry.name.find('/');
        const std::string op = entry.name.substr(0, slash);
        const std::string variant = slash == std::string::npos ? "" : entry.name.substr(slash);
        const std::string name = bench::case_name(op, backend, std::to_string(n)) + variant;
        bench::repeated(
            benchmark::RegisterBenchmark(name.c_str(), run_benchmark, backend, entry.factory, n), 3)
            ->MinTime(0.2);
      }
    }
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_benchmarks);
}
