#pragma once
// Where Kartograf's trained models are (rooms/ and semantic/ classifiers): the source tree's
// models/ when this build still sees it, else the installed copy (share/kartograf/models).
#include <filesystem>

namespace kartograf {

std::filesystem::path models_dir();

}  // namespace kartograf
