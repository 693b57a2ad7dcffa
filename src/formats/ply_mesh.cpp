// write_mesh_ply (kartograf/formats/ply.hpp).
#include <string>
#include <vector>

#include "formats/atomic_file.hpp"
#include "formats/byte_order.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/ply.hpp"

namespace kartograf::io {

namespace {

std::string mesh_header(const TriangleMesh& mesh) {
  std::string h = "ply\nformat binary_little_endian 1.0\ncomment written by Kartograf\n";
  h += "element vertex " + std::to_string(mesh.vertices.size()) + "\n";
  h += "property float x\nproperty float y\nproperty float z\n";
  if (!mesh.colors.empty()) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  h += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  h += "property list uchar int vertex_indices\nend_header\n";
  return h;
}

void check(const std::filesystem::path& path, const TriangleMesh& mesh) {
  const std::string where = "cannot write the mesh " + path.string() + ": ";
  require(mesh.colors.empty() || mesh.colors.size() == mesh.vertices.size(),
          where + std::to_string(mesh.colors.size()) + " colours for " +
              std::to_string(mesh.vertices.size()) + " vertices");
  const auto n = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    require(t.minCoeff() >= 0 && t.maxCoeff() < n,
            where + "a triangle names a vertex beyond the " + std::to_string(n) + " vertices");
  }
}

}  // namespace

void write_mesh_ply(const std::filesystem::path& path, const TriangleMesh& mesh) {
  check(path, mesh);
  detail::AtomicFileWriter file(path);
  file.write(mesh_header(mesh));
  std::vector<std::uint8_t> buffer;
  const auto flush = [&](std::size_t above) {
    if (buffer.size() < above) return;
    file.write(buffer.data(), buffer.size());
    buffer.clear();
  };
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) detail::append_little_endian(buffer, mesh.vertices[i][k]);
    if (!mesh.colors.empty()) {
      for (int shift : {0, 8, 16})
        buffer.push_back(static_cast<std::uint8_t>(mesh.colors[i] >> shift));
    }
    flush(1 << 20);
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    buffer.push_back(3);
    for (int k = 0; k < 3; ++k)
      detail::append_little_endian(buffer, static_cast<std::int32_t>(t[k]));
    flush(1 << 20);
  }
  flush(0);
  file.commit();
}

}  // namespace kartograf::io
