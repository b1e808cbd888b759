// The studio's binary geometry frames (studio_frames.hpp, clay/studio.hpp's net_frame).
#include "studio_frames.hpp"

#include <clay/studio.hpp>
#include <clay/surface/evaluate.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <utility>

namespace clay::recipe {

using Json = nlohmann::json;

namespace {

/// A frame of `body_bytes` after its prefix: the 4-byte little-endian length of the JSON header,
/// the header, zero padding to a multiple of 8. Returns the frame and where the body starts.
/// (Sized once and filled with memcpy: GCC 12 misreads insert() of chars into bytes as an
/// overflow at -O3.)
std::pair<std::vector<std::uint8_t>, std::size_t> frame_with_header(const std::string& header_json,
                                                                    std::size_t body_bytes) {
  const std::size_t padded = (4 + header_json.size() + 7) / 8 * 8;
  std::vector<std::uint8_t> out(padded + body_bytes, 0);
  const auto length = static_cast<std::uint32_t>(header_json.size());
  for (int k = 0; k < 4; ++k)
    out[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(length >> (8 * k));
  std::memcpy(out.data() + 4, header_json.data(), header_json.size());
  return {std::move(out), padded};
}

}  // namespace

std::vector<std::uint8_t> net_frame(const std::string& header_json,
                                    const std::vector<double>& points,
                                    const std::vector<double>& weights) {
  auto [out, at] =
      frame_with_header(header_json, (points.size() + weights.size()) * sizeof(double));
  // x86-64: little-endian; an empty list (a deviation map has no weights) copies nothing (memcpy
  // may not be handed its null data)
  if (!points.empty()) std::memcpy(out.data() + at, points.data(), points.size() * sizeof(double));
  if (!weights.empty())
    std::memcpy(out.data() + at + points.size() * sizeof(double), weights.data(),
                weights.size() * sizeof(double));
  return out;
}

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

/// A model's faces as nets, one frame: the header {"kind": "model_nets", "name", "faces": [{
/// "degrees", "counts", "knots_u", "knots_v", "rational", "reversed"}, ...]}, then each face's
/// points (3 float64 each) and weights in turn. Sent instead of a mesh when the model's topology
/// is that of the mesh the page holds: the page evaluates each node at its (u, v).
std::vector<std::uint8_t> model_nets_frame(const std::string& name, const brep::Model& model) {
  Json faces = Json::array();
  std::size_t doubles = 0;
  for (const brep::Face& f : model.faces) {
    const surface::BSplineSurface& s = f.surface;
    faces.push_back({{"degrees", {s.u.degree, s.v.degree}},
                     {"counts", {s.u.count(), s.v.count()}},
                     {"knots_u", s.u.knots},
                     {"knots_v", s.v.knots},
                     {"rational", s.is_rational()},
                     {"reversed", f.reversed}});
    doubles += static_cast<std::size_t>(s.points.size() + s.weights.size());
  }
  const Json header = {{"kind", "model_nets"}, {"name", name}, {"faces", faces}};
  auto [out, start] = frame_with_header(header.dump(), doubles * sizeof(double));
  std::uint8_t* at = out.data() + start;
  for (const brep::Face& f : model.faces) {
    const surface::BSplineSurface& s = f.surface;
    std::memcpy(at, s.points.data(), static_cast<std::size_t>(s.points.size()) * sizeof(double));
    at += static_cast<std::size_t>(s.points.size()) * sizeof(double);
    std::memcpy(at, s.weights.data(), static_cast<std::size_t>(s.weights.size()) * sizeof(double));
    at += static_cast<std::size_t>(s.weights.size()) * sizeof(double);
  }
  return out;
}

/// The viewer's deviation map (docs/viewer.md) of a surface: on a rows x cols grid evenly over
/// its domain, the distance from the surface to its last stage's pointwise deformation of the
/// surface before it, at the same fractions of that surface's domain (exact composition: rounding;
/// a refit: its error). A frame {"kind": "deviation", "name", "step", "rows", "cols", "max"}
/// then rows * cols float64, row (u) by row.
std::vector<std::uint8_t> deviation_frame(const std::string& name, const surface::BSplineSurface& s,
                                          const Stage& stage, int rows, int cols) {
  // The same fractions of both domains, the last one each domain's end exactly.
  auto fractions = [](const surface::BSplineBasis& basis, int n) {
    const auto [first, last] = basis.domain();
    std::vector<double> t(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k)
      t[static_cast<std::size_t>(k)] = k == n - 1 ? last : first + (last - first) * k / (n - 1);
    return t;
  };
  const surface::Points3 after =
      surface::evaluate_grid(s, fractions(s.u, rows), fractions(s.v, cols));
  const surface::Points3 before = surface::evaluate_grid(
      stage.before, fractions(stage.before.u, rows), fractions(stage.before.v, cols));
  std::vector<double> values(static_cast<std::size_t>(after.rows()));
  double worst = 0;
  for (Eigen::Index k = 0; k < after.rows(); ++k) {
    const Eigen::Vector3d q = stage.map(before.row(k).transpose());
    const double d = (after.row(k).transpose() - q).norm();
    values[static_cast<std::size_t>(k)] = d;
    worst = std::max(worst, d);
  }
  const Json header = {{"kind", "deviation"}, {"name", name}, {"step", stage.step},
                       {"rows", rows},        {"cols", cols}, {"max", worst}};
  return net_frame(header.dump(), values, {});
}

/// What a model's mesh depends on besides its faces' control points: the faces, their domains,
/// sides and loops (edges used, senses, pcurves bit for bit). Exact composition keeps (u, v), so
/// a deformed model keeps its key and its mesh's nodes stay at their (u, v) (FNV-1a, 64 bits).
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
