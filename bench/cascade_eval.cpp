// Issue 7 experiment (docs/methods.md M2 step 4): the stairs cascade on held-out synthetic views
// (seeds from 1000000, never used in training): recall at IoU >= 0.5 and false positives per image,
// before and after the metric size check.
//   kartograf_cascade_eval models/semantic/stairs_cascade.yml.gz [object views] [empty views]
//       [min_neighbors]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/semantic/haar_cascade.hpp"
#include "kartograf/semantic/object_detector.hpp"
#include "kartograf/training/synthetic_stairs.hpp"

using namespace kartograf;
using namespace kartograf::semantic;
using namespace kartograf::training;

int main(int argc, char** argv) {
  const std::string model = argv[1];
  const int object_views = argc > 2 ? std::atoi(argv[2]) : 100;
  const int empty_views = argc > 3 ? std::atoi(argv[3]) : 50;
  const int min_neighbors = argc > 4 ? std::atoi(argv[4]) : 2;
  const HaarCascade cascade = load_cascade(model);
  const compute::Context context = compute::Context::cpu();
  DetectionParams params;
  params.min_neighbors = min_neighbors;
  const SizeLimits limits = stairs_size_limits();
  int hits_raw = 0, hits = 0, fp_raw = 0, fp = 0, images = 0;
  double detect_seconds = 0;
  double gt_wmin = 1e9, gt_wmax = 0, gt_hmin = 1e9, gt_hmax = 0;
  int gt_rejected = 0;
  int fp_on_object_views = 0;
  for (int i = 0; i < object_views + empty_views; ++i) {
    const bool with = i < object_views;
    const StairsView view = render_stairs_view(context, 1000000 + i, with);
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<Detection> raw = detect_objects(cascade, view.gray, params);
    const std::vector<Detection> verified = verify_metric_size(raw, view.points, limits);
    detect_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++images;
    auto score = [&](const std::vector<Detection>& dets, int& hit, int& false_positives) {
      bool found = false;
      for (const Detection& d : dets) {
        if (with && !found && intersection_over_union(d, *view.object) >= 0.5)
          found = true;
        else
          ++false_positives;
      }
      hit += found;
    };
    score(raw, hits_raw, fp_raw);
    const int before = fp;
    score(verified, hits, fp);
    if (with) fp_on_object_views += fp - before;
    if (with) {
      const auto size = measure_detection(view.points, *view.object);
      if (size) {
        gt_wmin = std::min(gt_wmin, size->width), gt_wmax = std::max(gt_wmax, size->width);
        gt_hmin = std::min(gt_hmin, size->height), gt_hmax = std::max(gt_hmax, size->height);
        if (verify_metric_size({*view.object}, view.points, limits).empty()) ++gt_rejected;
      }
    }
  }
  std::printf("held-out: %d views with stairs, %d without; min_neighbors %d\n", object_views,
              empty_views, min_neighbors);
  std::printf("cascade only:      recall %.3f, false positives/image %.3f\n",
              double(hits_raw) / object_views, double(fp_raw) / images);
  std::printf("+ size verification: recall %.3f, false positives/image %.3f\n",
              double(hits) / object_views, double(fp) / images);
  std::printf("verified false positives on views with stairs: %d, without: %d\n",
              fp_on_object_views, fp - fp_on_object_views);
  std::printf(
      "GT box metric size: width %.2f..%.2f, height %.2f..%.2f; GT boxes rejected by size %d\n",
      gt_wmin, gt_wmax, gt_hmin, gt_hmax, gt_rejected);
  std::printf("detection + verification: %.1f ms/image (320x240)\n",
              1000 * detect_seconds / images);
}
