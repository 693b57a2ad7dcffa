// Fuzz target: a 7-Scenes / 3DMatch frame's pose file (frame-N.pose.txt, a 4x4 matrix), read
// with its frame as a sequence reads it. The frame's images are tiny valid PNGs written once.
#include <filesystem>

#include "fuzz_input_file.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/sequence_detect.hpp"

namespace {

std::filesystem::path frame_folder() {
  static const std::filesystem::path folder = [] {
    const auto dir = kartograf::fuzz::scratch_dir() / "frames";
    std::filesystem::create_directories(dir);
    kartograf::DepthImage depth(16, 12, 1500);
    kartograf::io::write_png(dir / "frame-000007.depth.png", depth);
    kartograf::io::write_png(dir / "frame-000007.color.png",
                             kartograf::RgbImage(16, 12, kartograf::Rgb8{90, 120, 150}));
    return dir;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path folder = frame_folder();
  const auto written = kartograf::fuzz::write_input("pose.txt", data, size);
  std::filesystem::rename(written, folder / "frame-000007.pose.txt");
  try {
    kartograf::io::SequenceParams options;
    options.camera = "16,16,8,6";
    const kartograf::io::OpenedSequence opened = kartograf::io::open_sequence(folder, options);
    opened.sequence->frame(0);
  } catch (const kartograf::Error&) {
  }
  return 0;
}
