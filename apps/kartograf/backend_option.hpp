#pragma once
// The --backend option of every command that runs on a compute backend: $KARTOGRAF_BACKEND gives
// the default, --backend overrides it, and the context is made from whichever named it (so that an
// unusable backend's error says where the choice came from).
#include <string>

#include <CLI/CLI.hpp>

#include "kartograf/compute/context.hpp"

namespace kartograf::cli {

// `purpose` starts the option's help, e.g. "Where the normals run: " (may be empty).
void add_backend_option(CLI::App& command, std::string& backend, std::string& source,
                        const std::string& purpose = "");

compute::Context backend_context(const std::string& backend, const std::string& source);

}  // namespace kartograf::cli
