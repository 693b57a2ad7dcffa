#pragma once
// A fixed-size Eigen vector as a JSON array, for the JSON files the io layer writes.
#include <nlohmann/json.hpp>

namespace kartograf::io::detail {

template <class Vector>
nlohmann::ordered_json json_array(const Vector& v) {
  nlohmann::ordered_json json = nlohmann::ordered_json::array();
  for (int i = 0; i < v.size(); ++i) json.push_back(v[i]);
  return json;
}

}  // namespace kartograf::io::detail
