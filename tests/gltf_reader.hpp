#pragma once
// A small, independent reader of binary glTF (.glb) for tests: the triangles of every mesh
// primitive reachable from the default scene, with node transforms applied, turned back into the
// kernel's frame (millimetres, Z up; glTF is metres, Y up: (x, y, z)_glTF = (X, Z, -Y) / 1000).
// It reads the file itself (nlohmann-json for the JSON chunk), not through OpenCASCADE.
#include <nlohmann/json.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace clay::test {

struct GltfTriangles {
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;  ///< mm, Z up

  double area() const {
    double a = 0;
    for (const auto& t : triangles) a += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
    return a;
  }
  Eigen::AlignedBox3d box() const {
    Eigen::AlignedBox3d b;
    for (const auto& t : triangles)
      for (const auto& p : t) b.extend(p);
    return b;
  }
};

inline GltfTriangles read_glb(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto u32 = [&](std::size_t at) {
    if (at + 4 > bytes.size()) throw std::runtime_error(path + ": truncated");
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0 || u32(4) != 2 ||
      u32(8) != bytes.size())
    throw std::runtime_error(path + ": not a binary glTF 2 file");
  const std::uint32_t json_length = u32(12);
  if (u32(16) != 0x4E4F534Au) throw std::runtime_error(path + ": the first chunk is not JSON");
  const nlohmann::json j = nlohmann::json::parse(bytes.substr(20, json_length));
  const std::size_t bin_at = 20 + json_length;
  if (u32(bin_at + 4) != 0x004E4942u) throw std::runtime_error(path + ": no BIN chunk");
  const std::size_t bin = bin_at + 8;

  auto view_of = [&](const nlohmann::json& accessor, std::size_t element) {
    const auto& view = j.at("bufferViews").at(accessor.at("bufferView").get<std::size_t>());
    const std::size_t offset = bin + view.value("byteOffset", std::size_t{0}) +
                               accessor.value("byteOffset", std::size_t{0});
    const std::size_t stride = view.value("byteStride", element);
    return std::pair<std::size_t, std::size_t>{offset, stride};
  };
  auto positions = [&](std::size_t index) {
    const auto& a = j.at("accessors").at(index);
    if (a.at("componentType") != 5126 || a.at("type") != "VEC3")
      throw std::runtime_error(path + ": positions not float VEC3");
    const auto [offset, stride] = view_of(a, 12);
    std::vector<Eigen::Vector3d> out;
    for (std::size_t k = 0; k < a.at("count").get<std::size_t>(); ++k) {
      float f[3];
      std::memcpy(f, bytes.data() + offset + k * stride, 12);
      out.emplace_back(f[0], f[1], f[2]);
    }
    return out;
  };
  auto indices = [&](std::size_t index) {
    const auto& a = j.at("accessors").at(index);
    const int type = a.at("componentType");
    const std::size_t size = type == 5125 ? 4 : type == 5123 ? 2 : 1;
    const auto [offset, stride] = view_of(a, size);
    std::vector<std::uint32_t> out;
    for (std::size_t k = 0; k < a.at("count").get<std::size_t>(); ++k) {
      std::uint32_t v = 0;
      std::memcpy(&v, bytes.data() + offset + k * stride, size);
      out.push_back(v);
    }
    return out;
  };
  auto local = [](const nlohmann::json& node) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (node.contains("matrix")) {
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m(r, c) = node["matrix"][static_cast<std::size_t>(4 * c + r)];
      return m;
    }
    Eigen::Affine3d a = Eigen::Affine3d::Identity();
    if (node.contains("translation"))
      a.translate(
          Eigen::Vector3d(node["translation"][0], node["translation"][1], node["translation"][2]));
    if (node.contains("rotation"))
      a.rotate(Eigen::Quaterniond(node["rotation"][3], node["rotation"][0], node["rotation"][1],
                                  node["rotation"][2]));
    if (node.contains("scale"))
      a.scale(Eigen::Vector3d(node["scale"][0], node["scale"][1], node["scale"][2]));
    return Eigen::Matrix4d(a.matrix());
  };

  GltfTriangles out;
  std::function<void(std::size_t, const Eigen::Matrix4d&)> visit =
      [&](std::size_t n, const Eigen::Matrix4d& parent) {
        const auto& node = j.at("nodes").at(n);
        const Eigen::Matrix4d m = parent * local(node);
        if (node.contains("mesh"))
          for (const auto& prim :
               j.at("meshes").at(node["mesh"].get<std::size_t>()).at("primitives")) {
            if (prim.value("mode", 4) != 4)
              throw std::runtime_error(path + ": a primitive is not triangles");
            const auto p = positions(prim.at("attributes").at("POSITION"));
            const auto idx = indices(prim.at("indices"));
            for (std::size_t k = 0; k + 2 < idx.size(); k += 3) {
              std::array<Eigen::Vector3d, 3> t;
              for (int c = 0; c < 3; ++c) {
                const Eigen::Vector3d g =
                    (m * p.at(idx[k + static_cast<std::size_t>(c)]).homogeneous()).head<3>();
                t[static_cast<std::size_t>(c)] = 1000.0 * Eigen::Vector3d(g.x(), -g.z(), g.y());
              }
              out.triangles.push_back(t);
            }
          }
        if (node.contains("children"))
          for (const auto& c : node["children"]) visit(c.get<std::size_t>(), m);
      };
  const std::size_t scene = j.value("scene", std::size_t{0});
  for (const auto& n : j.at("scenes").at(scene).at("nodes"))
    visit(n.get<std::size_t>(), Eigen::Matrix4d::Identity());
  return out;
}

}  // namespace clay::test
