#include "peer_methods.hpp"

#include <cstdlib>
#include <map>
#include <thread>

namespace kartograf::peer {
namespace {

std::string environment_value(const char* name) {
  const char* value = std::getenv(name);
  return value && *value ? value : "";
}

}  // namespace

std::string kartograf_threads() {
  const std::string value = environment_value("KARTOGRAF_CPU_THREADS");
  return "KARTOGRAF_CPU_THREADS=" + (value.empty() ? std::string("1 (unset)") : value);
}

std::string openmp_threads() {
  const std::string value = environment_value("OMP_NUM_THREADS");
  if (!value.empty()) return "OMP_NUM_THREADS=" + value;
  return "OMP_NUM_THREADS unset (" + std::to_string(std::thread::hardware_concurrency()) +
         " cores)";
}

Method odometry_method(std::string name, std::string library, std::string threads,
                       std::string compared_with, OdometryFactory factory, bool both_frames) {
  // One front end per dataset (its camera), made on first use and kept for every pair.
  auto front_ends = std::make_shared<std::map<const Dataset*, std::unique_ptr<OdometryFrontEnd>>>();
  Method method;
  method.name = std::move(name);
  method.library = std::move(library);
  method.input = InputKind::rgbd;
  method.threads = std::move(threads);
  method.compared_with = std::move(compared_with);
  method.prepare = [front_ends, factory = std::move(factory),
                    both_frames](const FramePair& pair) -> std::function<Estimate()> {
    auto& front_end = (*front_ends)[pair.dataset];
    if (!front_end) front_end = factory(*pair.dataset);
    OdometryFrontEnd* odometry = front_end.get();
    if (both_frames) {
      return [odometry, &pair] {
        odometry->set_reference(pair.target);
        return odometry->track(pair.source);
      };
    }
    odometry->set_reference(pair.target);
    return [odometry, &pair] { return odometry->track(pair.source); };
  };
  return method;
}

}  // namespace kartograf::peer
