// Trains the ground texture classifier (semantic/ground_texture.hpp) on synthetic labelled patches
// and writes it:
//
//   train_ground_texture <model file (.yml.gz)> [patches per class = 400] [seed = 1]
//
// The shipped model, models/semantic/ground_texture.yml.gz, was made with the defaults. There is no
// outdoor data with ground truth: the patches come from synthesize_ground_patch (training style).
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/semantic/ground_texture.hpp"

namespace fs = std::filesystem;
using namespace kartograf;

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    std::fprintf(stderr, "usage: %s <model file (.yml.gz)> [patches per class] [seed]\n", argv[0]);
    return 2;
  }
  try {
    const int per_class = argc > 2 ? std::stoi(argv[2]) : 400;
    const auto seed = argc > 3 ? std::stoull(argv[3]) : 1ULL;
    require(per_class >= 1, "patches per class must be >= 1");
    const auto start = std::chrono::steady_clock::now();
    const semantic::GroundSamples samples =
        semantic::synthesize_ground_samples(per_class, semantic::GroundPatchStyle::training, seed);
    const auto generated = std::chrono::steady_clock::now();
    const semantic::GroundTextureClassifier classifier =
        semantic::GroundTextureClassifier::train(samples.features, samples.labels);
    const auto trained = std::chrono::steady_clock::now();
    const fs::path output = argv[1];
    if (output.has_parent_path()) fs::create_directories(output.parent_path());
    classifier.save(output);
    using Seconds = std::chrono::duration<double>;
    std::printf("%zu patches generated in %.2f s, forest trained in %.2f s, wrote %s (%ju bytes)\n",
                samples.labels.size(), Seconds(generated - start).count(),
                Seconds(trained - generated).count(), argv[1],
                static_cast<std::uintmax_t>(fs::file_size(output)));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "train_ground_texture: %s\n", e.what());
    return 1;
  }
}
