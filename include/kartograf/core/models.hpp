#pragma once
// Where Kartograf's trained models are (rooms/ and semantic/ classifiers): $KARTOGRAF_MODELS_DIR
// when set (a relocated install: the Python package), else the source tree's models/ when this
// build still sees it, else the installed copy (share/kartograf/models).
#include <filesystem>

namespace kartograf {

std::filesystem::path models_dir();

}  // namespace kartograf
