// Meshes of whole models (clay/occt/model_exchange.hpp): tessellate() and the .glb preview of
// write_model. The faces are meshed by OpenCASCADE's BRepMesh on the shapes write_model builds,
// so each face is meshed inside its loops (holes are holes) and an edge shared by two faces is
// discretized once (no cracks). Only the triangles come from OpenCASCADE: normals are our own
// NURBS's exact normals at the nodes' (u, v), and the deflection is measured on our NURBS.
#include <clay/occt/model_exchange.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "convert.hpp"
#include "model_shapes.hpp"
#include "session.hpp"

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Message_ProgressRange.hxx>
#include <Poly_Triangulation.hxx>
#include <RWGltf_CafWriter.hxx>
#include <TColStd_IndexedDataMapOfStringString.hxx>
#include <TCollection_AsciiString.hxx>
#include <TopLoc_Location.hxx>
#include <XCAFApp_Application.hxx>

namespace clay::brep {
namespace {

namespace fs = std::filesystem;
using internal::shortest;

/// The diagonal of the box of every face's control points (1 for an empty model).
double size_of(const Model& m) {
  Eigen::AlignedBox3d box;
  for (const Face& f : m.faces)
    for (Eigen::Index r = 0; r < f.surface.points.rows(); ++r)
      box.extend(Eigen::Vector3d(f.surface.points.row(r).transpose()));
  const double d = box.isEmpty() ? 0.0 : box.diagonal().norm();
  return d > 0 ? d : 1.0;
}

/// Meshes every body's faces (OpenCASCADE keeps the triangles on the faces' shared TShapes),
/// with the deflection relative to the size of the placed model (`flat`).
void mesh_bodies(const Model& flat, const Shapes& s, const MeshOptions& options) {
  const double deflection = options.relative_deflection * size_of(flat);
  for (const TopoDS_Shape& body : s.bodies)
    BRepMesh_IncrementalMesh(body, deflection, false, options.angular_deflection_rad, false);
}

/// The unit normal S_u × S_v at (u, v). At a pole, where S_u or S_v vanishes, the normal at a
/// point 1e-6 of the domain towards its middle (the limit, to about 1e-6 radians); zero when
/// that vanishes too (the caller then takes the mean of the triangles around the node).
Eigen::Vector3d node_normal(const surface::BSplineSurface& s, double u, double v) {
  const auto [u0, u1] = s.u.domain();
  const auto [v0, v1] = s.v.domain();
  for (double nudge : {0.0, 1e-6}) {
    const double a = u + nudge * (0.5 * (u0 + u1) - u), b = v + nudge * (0.5 * (v0 + v1) - v);
    const surface::SurfaceDerivatives d = surface::derivatives(s, a, b, 1);
    const Eigen::Vector3d n = d.du.cross(d.dv);
    const double scale = d.du.norm() * d.dv.norm();
    if (n.norm() > 1e-9 * scale && scale > 0) return n.normalized();
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace

ModelMesh tessellate(const Model& model, const MeshOptions& options) {
  options.validate();
  const Model m = flattened(model);
  const Shapes shapes = build_shapes(m);
  ModelMesh out;
  out.face_body.assign(m.faces.size(), -1);
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    for (const Shell& shell : m.bodies[b].shells)
      for (int f : shell.faces) out.face_body[static_cast<std::size_t>(f)] = static_cast<int>(b);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const int b = out.face_body[f];
    out.face_colours.push_back(m.faces[f].colour ? m.faces[f].colour
                               : b >= 0          ? m.bodies[static_cast<std::size_t>(b)].colour
                                                 : std::nullopt);
  }
  surface::occt::ExchangeSession session;
  surface::occt::guarded(ErrorCategory::Exchange, "tessellate", [&] {
    mesh_bodies(m, shapes, options);
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      const Face& face = m.faces[f];
      TopLoc_Location location;
      const Handle(Poly_Triangulation) t = BRep_Tool::Triangulation(shapes.faces[f], location);
      if (t.IsNull() || t->NbTriangles() == 0 || !t->HasUVNodes())
        throw Error(ErrorCategory::Exchange,
                    "tessellate: OpenCASCADE's mesher left face " + std::to_string(f) +
                        (face.name.empty() ? "" : " (\"" + face.name + "\")") +
                        " without triangles; check_model says whether the face is valid");
      const gp_Trsf move = location.Transformation();
      const int first = static_cast<int>(out.positions.size());
      const auto [u0, u1] = face.surface.u.domain();
      const auto [v0, v1] = face.surface.v.domain();
      std::vector<Eigen::Vector2d> uv;
      for (int i = 1; i <= t->NbNodes(); ++i) {
        const gp_Pnt p = t->Node(i).Transformed(move);
        const gp_Pnt2d q = t->UVNode(i);
        uv.emplace_back(std::clamp(q.X(), u0, u1), std::clamp(q.Y(), v0, v1));
        out.positions.emplace_back(p.X(), p.Y(), p.Z());
        out.uv.push_back(uv.back());
        out.node_face.push_back(static_cast<int>(f));
        out.normals.push_back((face.reversed ? -1.0 : 1.0) *
                              node_normal(face.surface, uv.back().x(), uv.back().y()));
      }
      // Counter-clockwise seen from outside: the winding whose normals agree with the face's.
      std::vector<std::array<int, 3>> triangles;
      double agree = 0;
      for (int k = 1; k <= t->NbTriangles(); ++k) {
        int a = 0, b = 0, c = 0;
        t->Triangle(k).Get(a, b, c);
        std::array<int, 3> tri{first + a - 1, first + b - 1, first + c - 1};
        const Eigen::Vector3d& pa = out.positions[static_cast<std::size_t>(tri[0])];
        const Eigen::Vector3d n = (out.positions[static_cast<std::size_t>(tri[1])] - pa)
                                      .cross(out.positions[static_cast<std::size_t>(tri[2])] - pa);
        for (int corner : tri) agree += n.dot(out.normals[static_cast<std::size_t>(corner)]);
        triangles.push_back(tri);
      }
      for (std::array<int, 3>& tri : triangles) {
        if (agree < 0) std::swap(tri[1], tri[2]);
        Eigen::Vector2d mean = Eigen::Vector2d::Zero();
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int corner : tri) {
          mean += uv[static_cast<std::size_t>(corner - first)] / 3;
          centroid += out.positions[static_cast<std::size_t>(corner)] / 3;
        }
        out.max_deflection_mm =
            std::max(out.max_deflection_mm,
                     (surface::evaluate(face.surface, mean.x(), mean.y()) - centroid).norm());
        out.triangles.push_back(tri);
        out.triangle_face.push_back(static_cast<int>(f));
      }
      // Poles: the normalized mean of the normals of the triangles around them.
      std::vector<Eigen::Vector3d> mean(uv.size(), Eigen::Vector3d::Zero());
      for (const std::array<int, 3>& tri : triangles) {
        const Eigen::Vector3d& pa = out.positions[static_cast<std::size_t>(tri[0])];
        const Eigen::Vector3d n = (out.positions[static_cast<std::size_t>(tri[1])] - pa)
                                      .cross(out.positions[static_cast<std::size_t>(tri[2])] - pa);
        for (int corner : tri) mean[static_cast<std::size_t>(corner - first)] += n;
      }
      for (std::size_t i = 0; i < uv.size(); ++i) {
        Eigen::Vector3d& n = out.normals[static_cast<std::size_t>(first) + i];
        if (n.isZero(0.0) && mean[i].norm() > 0) n = mean[i].normalized();
      }
    }
  });
  return out;
}

void write_glb(const Model& m, const Shapes& shapes, const fs::path& file,
               const MeshOptions& options, const Handle(TDocStd_Document) & document) {
  constexpr std::string_view caller = "write_model";
  mesh_bodies(m.is_assembly() ? flattened(m) : m, shapes, options);
  surface::occt::write_atomically(file, caller, [&](const fs::path& temp) {
    RWGltf_CafWriter writer(TCollection_AsciiString(temp.string().c_str()), true);
    writer.ChangeCoordinateSystemConverter().SetInputLengthUnit(0.001);  // model in mm
    writer.ChangeCoordinateSystemConverter().SetInputCoordinateSystem(RWMesh_CoordinateSystem_Zup);
    TColStd_IndexedDataMapOfStringString info;
    info.Add("generator", "Clayform");
    if (!writer.Perform(document, info, Message_ProgressRange()))
      throw Error(ErrorCategory::Io, "write_model: OpenCASCADE's glTF writer failed to write " +
                                         surface::occt::quoted(temp));
    std::error_code ec;
    if (!fs::is_regular_file(temp, ec) || fs::file_size(temp, ec) == 0)
      throw Error(ErrorCategory::Io,
                  "write_model: no data was written to " + surface::occt::quoted(temp));
  });
}

}  // namespace clay::brep
