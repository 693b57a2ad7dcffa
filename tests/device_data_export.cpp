#include "device_data_files.hpp"

#include <cstdio>
#include <string>

#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "raw_image_file.hpp"

namespace kartograf::testing {

void export_device_data(const std::filesystem::path& data_dir,
                        const std::filesystem::path& out_dir) {
  for (const DeviceDataFile& file : kDeviceDataFiles) {
    const std::filesystem::path from = data_dir / file.path, to = out_dir / file.path;
    std::filesystem::create_directories(to.parent_path());
    switch (file.kind) {
      case DeviceDataKind::depth:
        raw::write_depth(raw_copy_path(to), io::read_depth_png(from));
        break;
      case DeviceDataKind::color:
        raw::write_color(raw_copy_path(to), io::read_color_image(from));
        break;
      case DeviceDataKind::occupancy_map:
        raw::write_occupancy(raw_copy_path(to), io::read_png_map(from).cells);
        break;
      case DeviceDataKind::text:
        // The copy writable (the data folder's files are read-only), so a later export replaces it.
        std::filesystem::remove(to);
        std::filesystem::copy_file(from, to);
        std::filesystem::permissions(to, std::filesystem::perms::owner_write,
                                     std::filesystem::perm_options::add);
        break;
    }
  }
}

void export_sequence_frames(const std::filesystem::path& data_dir,
                            const std::filesystem::path& out_dir, int count) {
  const std::filesystem::path frames = "7scenes_redkitchen/frames";
  std::filesystem::create_directories(out_dir / frames);
  for (int i = 0; i < count; ++i) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "frame-%06d", i);
    const std::filesystem::path depth = frames / (std::string(stem) + ".depth.png");
    const std::filesystem::path color = frames / (std::string(stem) + ".color.jpg");
    raw::write_depth(raw_copy_path(out_dir / depth), io::read_depth_png(data_dir / depth));
    raw::write_color(raw_copy_path(out_dir / color), io::read_color_image(data_dir / color));
  }
}

}  // namespace kartograf::testing
