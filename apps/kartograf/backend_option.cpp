#include "backend_option.hpp"

#include <cstdlib>

namespace kartograf::cli {

void add_backend_option(CLI::App& command, std::string& backend, std::string& source,
                        const std::string& purpose) {
  if (const char* env_backend = std::getenv("KARTOGRAF_BACKEND"); env_backend && *env_backend) {
    backend = env_backend;
    source = "KARTOGRAF_BACKEND";
  }
  command
      .add_option("--backend", backend,
                  purpose + "auto|cpu|vulkan|opencl (default: $KARTOGRAF_BACKEND, else auto)")
      ->each([&source](const std::string&) { source = "--backend"; });
}

compute::Context backend_context(const std::string& backend, const std::string& source) {
  compute::ContextParams options;
  options.backend = compute::parse_backend_choice(backend, source);
  options.read_device_environment();  // KARTOGRAF_DEVICE on every command, not only `demo`
  return compute::Context(options);
}

}  // namespace kartograf::cli
