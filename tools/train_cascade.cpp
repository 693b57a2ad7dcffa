// Trains the Haar cascade of the M2 object detector (semantic/haar_cascade.hpp) for the synthetic
// "stairs" class on rendered views (semantic/synthetic_stairs.hpp) and writes it:
//
//   train_cascade <model file (.yml.gz)> [object views] [background views] [positives per view]
//
// Defaults: 150 views with stairs (seeds 1..150) times 8 perturbed positives each, 200 views
// without (seeds 100001..); negatives come from both (from views with stairs: windows away from
// them), the CascadeTrainingParams defaults. Held-out test views use seeds from
// 1000000 on, never these. The shipped model, models/semantic/stairs_cascade.yml.gz, was made with
// the defaults.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/semantic/cascade_training.hpp"
#include "kartograf/training/synthetic_stairs.hpp"

using namespace kartograf;

int main(int argc, char** argv) {
  if (argc < 2 || argc > 5) {
    std::fprintf(stderr,
                 "usage: %s <model file (.yml.gz)> [object views=150] [background views=200] "
                 "[positives per view=8]\n",
                 argv[0]);
    return 2;
  }
  try {
    const int object_views = argc > 2 ? std::atoi(argv[2]) : 150;
    const int background_views = argc > 3 ? std::atoi(argv[3]) : 200;
    const int per_view = argc > 4 ? std::atoi(argv[4]) : 8;
    require(object_views > 0 && background_views > 0 && per_view > 0,
            "train_cascade: view and positive counts must be positive integers");
    const auto start = std::chrono::steady_clock::now();
    const compute::Context context = compute::Context::cpu();
    std::mt19937_64 rng(7);
    std::vector<GrayImage> positives;
    std::vector<semantic::TrainingBackground> backgrounds;
    for (int i = 0; i < object_views; ++i) {
      const training::StairsView view =
          training::render_stairs_view(context, static_cast<std::uint64_t>(1 + i), true);
      for (GrayImage& p : training::stairs_positives(view, per_view, 20, rng)) {
        positives.push_back(std::move(p));
      }
      // The view itself gives hard negatives: parts of the stairs, neighbouring scales.
      backgrounds.push_back({view.gray, {*view.object}});
    }
    for (int i = 0; i < background_views; ++i) {
      backgrounds.push_back(
          {training::render_stairs_view(context, static_cast<std::uint64_t>(100001 + i), false)
               .gray,
           {}});
    }
    const double render_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("rendered %zu positives, %zu backgrounds in %.1f s\n", positives.size(),
                backgrounds.size(), render_seconds);

    semantic::CascadeTrainingParams params;
    params.object_class = "stairs";
    semantic::CascadeTrainingReport report;
    const semantic::HaarCascade cascade = semantic::train_cascade(
        positives, backgrounds, params, &report,
        [](const std::string& line) { std::printf("%s\n", line.c_str()), std::fflush(stdout); });
    semantic::save_cascade(cascade, argv[1]);
    int stumps = 0;
    for (int s : report.stumps_per_stage) stumps += s;
    std::printf("%zu stages, %d stumps, %zu features (of %d); training %.1f s; written to %s\n",
                cascade.stages.size(), stumps, cascade.features.size(), report.features_considered,
                report.seconds, argv[1]);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "train_cascade: %s\n", e.what());
    return 1;
  }
}
