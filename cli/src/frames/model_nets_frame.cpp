// A model's faces as nets, one studio frame (frames.hpp).
#include "frame_header.hpp"
#include "frames.hpp"

#include <nlohmann/json.hpp>

#include <cstring>

namespace clay::recipe {

using frames::frame_with_header;
using Json = nlohmann::json;

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

}  // namespace clay::recipe
