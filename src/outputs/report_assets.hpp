#pragma once
// Files embedded into the library for report.html (src/io/CMakeLists.txt, cmake/embed_files.cmake).
#include <string_view>

namespace kartograf::io::detail {

std::string_view three_js();           // three.js r111, Debian's libjs-three (MIT licence)
std::string_view orbit_controls_js();  // its examples/js/controls/OrbitControls.js
std::string_view map_viewer_js();      // report/map_viewer.js: the 3-D view
std::string_view report_checks_js();   // report/report_checks.js: the page's self-checks
std::string_view report_css();         // report/report.css

}  // namespace kartograf::io::detail
