// A model's trimmed mesh as a studio frame, and the topology key that says when the page's
// mesh still fits the model (frames.hpp).
#include "frame_header.hpp"
#include "frames.hpp"

#include <cstring>

namespace clay::recipe {

using frames::frame_with_header;

/// A model's frame: the length and JSON header as in net_frame ({"kind": "mesh", "name",
/// "vertices": n, "triangles": m, "faces"}), then n * 3 float64 positions, n * 3 float64 unit
/// normals, n * 2 float64 (u, v) on each node's face, m * 3 uint32 node indices and n uint32
/// face indices, little-endian. The (u, v) and faces let the page move the nodes itself when only
/// the faces' control points change (model_nets_frame).
std::vector<std::uint8_t> mesh_frame(const std::string& header_json, const brep::ModelMesh& mesh) {
  const std::size_t n = mesh.positions.size(), m = mesh.triangles.size();
  auto [out, start] = frame_with_header(
      header_json, (2 * n * 3 + 2 * n) * sizeof(double) + (m * 3 + n) * sizeof(std::uint32_t));
  std::uint8_t* at = out.data() + start;
  for (const auto* list : {&mesh.positions, &mesh.normals})
    for (const Eigen::Vector3d& p : *list) {
      std::memcpy(at, p.data(), 3 * sizeof(double));
      at += 3 * sizeof(double);
    }
  for (const Eigen::Vector2d& uv : mesh.uv) {
    std::memcpy(at, uv.data(), 2 * sizeof(double));
    at += 2 * sizeof(double);
  }
  auto put = [&](int index) {
    const auto value = static_cast<std::uint32_t>(index);
    std::memcpy(at, &value, sizeof value);
    at += sizeof value;
  };
  for (const auto& t : mesh.triangles)
    for (int corner : t) put(corner);
  for (int face : mesh.node_face) put(face);
  return out;
}

/// What a model's mesh depends on besides its faces' control points: the faces, their domains,
/// sides and loops (edges used, senses, pcurves bit for bit). Exact composition keeps (u, v), so
/// a deformed model keeps its key and its mesh's nodes stay at their (u, v) (FNV-1a, 64 bits).
std::uint64_t frame_key(const std::vector<std::uint8_t>& frame) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint8_t b : frame) h = (h ^ b) * 1099511628211ull;
  return h;
}

std::uint64_t topology_key(const brep::Model& model) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* data, std::size_t bytes) {
    const auto* b = static_cast<const std::uint8_t*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull;
  };
  auto mix_value = [&](auto x) { mix(&x, sizeof x); };
  mix_value(model.faces.size());
  for (const brep::Face& f : model.faces) {
    const auto [u0, u1] = f.surface.u.domain();
    const auto [v0, v1] = f.surface.v.domain();
    for (double d : {u0, u1, v0, v1}) mix_value(d);
    mix_value(f.reversed);
    mix_value(f.loops.size());
    for (const brep::Loop& loop : f.loops) {
      mix_value(loop.coedges.size());
      for (const brep::Coedge& c : loop.coedges) {
        mix_value(c.edge);
        mix_value(c.same_sense);
        mix(c.pcurve.basis.knots.data(), c.pcurve.basis.knots.size() * sizeof(double));
        mix(c.pcurve.points.data(),
            static_cast<std::size_t>(c.pcurve.points.size()) * sizeof(double));
        mix(c.pcurve.weights.data(),
            static_cast<std::size_t>(c.pcurve.weights.size()) * sizeof(double));
      }
    }
  }
  return h;
}

}  // namespace clay::recipe
