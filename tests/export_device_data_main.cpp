// kartograf_export_device_data OUT_DIR: the real files the device tests read, from the data folder
// (KARTOGRAF_DATA_DIR, else ../shared/data), written under OUT_DIR for kartograf_device_tests
// (device_data_files.hpp). Run it with KARTOGRAF_DATA_DIR=OUT_DIR.
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

#include "device_data_files.hpp"

int main(int argc, char** argv) {
  // --sequence N: also frames 0..N-1 of 7-Scenes for kartograf_gpu_check.
  const bool sequence = argc == 4 && std::string(argv[2]) == "--sequence";
  if (argc != 2 && !sequence) {
    std::cerr << "usage: kartograf_export_device_data OUT_DIR [--sequence N]\n";
    return 2;
  }
  const char* configured = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path data_dir = configured ? configured : KARTOGRAF_DEFAULT_DATA_DIR;
  try {
    kartograf::testing::export_device_data(data_dir, argv[1]);
    if (sequence) kartograf::testing::export_sequence_frames(data_dir, argv[1], std::stoi(argv[3]));
  } catch (const std::exception& error) {
    std::cerr << "kartograf_export_device_data: error: " << error.what() << '\n';
    return 1;
  }
  std::cout << "exported " << kartograf::testing::kDeviceDataFiles.size() << " files from "
            << data_dir << " to " << argv[1] << '\n';
  return 0;
}
