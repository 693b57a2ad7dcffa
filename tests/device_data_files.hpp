#pragma once
// The real files (under testing::data_dir()) that the device tests read, and their export for
// kartograf_device_tests, which reads no image format: kartograf_export_device_data writes each
// image as a raw copy at the same relative path plus ".raw" (raw_image_file.hpp) and copies each
// text file as it is. A file read by a device test but missing here fails
// DeviceTests.bundle_data_only.
#include <array>
#include <filesystem>
#include <string_view>

namespace kartograf::testing {

enum class DeviceDataKind { depth, color, occupancy_map, text };

struct DeviceDataFile {
  std::string_view path;  // relative to the data folder
  DeviceDataKind kind;
};

inline constexpr std::array kDeviceDataFiles{
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000000.depth.png", DeviceDataKind::depth},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000010.depth.png", DeviceDataKind::depth},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000100.depth.png", DeviceDataKind::depth},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000105.depth.png", DeviceDataKind::depth},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000150.depth.png", DeviceDataKind::depth},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000299.depth.png", DeviceDataKind::depth},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000100.color.jpg", DeviceDataKind::color},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000000.color.jpg", DeviceDataKind::color},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000010.color.jpg", DeviceDataKind::color},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000000.pose.txt", DeviceDataKind::text},
    DeviceDataFile{"7scenes_redkitchen/frames/frame-000010.pose.txt", DeviceDataKind::text},
    DeviceDataFile{"ipa_room_maps/test_maps/office_e.png", DeviceDataKind::occupancy_map},
};

// Writes every file of kDeviceDataFiles from `data_dir` under `out_dir` (created if needed).
// Needs kartograf_io (device_data_export.cpp); errors name the file.
void export_device_data(const std::filesystem::path& data_dir,
                        const std::filesystem::path& out_dir);

// Frames 0 .. count-1 of 7scenes_redkitchen (depth and colour raw copies, poses): the sequence
// kartograf_gpu_check times the odometry on (scripts/gpu-check.sh).
void export_sequence_frames(const std::filesystem::path& data_dir,
                            const std::filesystem::path& out_dir, int count);

// Where the raw copy of `original` is: the same path plus ".raw".
inline std::filesystem::path raw_copy_path(const std::filesystem::path& original) {
  std::filesystem::path raw = original;
  raw += ".raw";
  return raw;
}

}  // namespace kartograf::testing
