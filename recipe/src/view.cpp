// The view data of a run: grid meshes with exact normals and curvatures, the refit deviation, and
// the manifest the browser viewer reads (docs/recipe.md "Viewing a run").
#include "report_json.hpp"

#include <clay/error.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/view.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/tessellate.hpp>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <span>
#include <string>
#include <system_error>

namespace clay::recipe {

namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;
using Eigen::Vector3d;

constexpr int curve_samples = 200;

using detail::figure_json;
using detail::figures_json;

Json point_json(const Vector3d& p) { return Json::array({p.x(), p.y(), p.z()}); }

// Nets of more control points than this are left out of the view (null): a dense exact
// composition's net (the sail's has 104,610 points) is a solid mesh of lines on screen and made
// the manifest 6 MB, which the snapshot's page could not load within its minute.
constexpr Eigen::Index view_net_limit = 20000;

Json net_json(const surface::BSplineSurface& s) {
  if (s.points.rows() > view_net_limit) return nullptr;
  Json points = Json::array();
  for (Eigen::Index r = 0; r < s.points.rows(); ++r)
    points.push_back(point_json(s.points.row(r).transpose()));
  return Json{{"rows", s.count_u()}, {"cols", s.count_v()}, {"points", std::move(points)}};
}

Json curve_json(const std::string& name, const surface::BSplineCurve& c) {
  const auto [t0, t1] = c.basis.domain();
  const auto ts = surface::linspace(t0, t1, curve_samples);
  const surface::Points3 p = surface::evaluate_many(c, ts);
  Json points = Json::array();
  for (Eigen::Index r = 0; r < p.rows(); ++r) points.push_back(point_json(p.row(r).transpose()));
  return Json{{"name", name}, {"points", std::move(points)}};
}

const StepReport* step_named(const RunResult& r, const std::string& path) {
  for (const auto& s : r.steps)
    if (s.path == path) return &s;
  return nullptr;
}

/// The step's name from its report message ("deformations.spin[0] 'bulge': ..."), or empty.
std::string step_name(const StepReport* step) {
  if (!step) return {};
  const std::string& m = step->message;
  const auto space = m.find(' ');
  if (space == std::string::npos || space + 1 >= m.size() || m[space + 1] != '\'') return {};
  const auto end = m.find('\'', space + 2);
  if (end == std::string::npos) return {};
  return m.substr(space + 2, end - space - 2);
}

bool is_refit(const StepReport* step) {
  if (!step) return false;
  for (const auto& [name, value] : step->figures)
    if (name == "composition")
      return std::holds_alternative<std::string>(value) && std::get<std::string>(value) == "refit";
  return false;
}

/// Writes a .bin mesh file: the floats, then the triangles' node indices (uint32), both
/// little-endian.
void write_mesh_file(const fs::path& file, std::vector<float> f,
                     const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::uint32_t> index;
  index.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int k : t) index.push_back(static_cast<std::uint32_t>(k));
  if constexpr (std::endian::native == std::endian::big) {
    auto swap = [](std::uint32_t b) {
      return ((b & 0xFFu) << 24) | ((b & 0xFF00u) << 8) | ((b >> 8) & 0xFF00u) | (b >> 24);
    };
    for (float& x : f) {
      std::uint32_t b;
      std::memcpy(&b, &x, 4);
      b = swap(b);
      std::memcpy(&x, &b, 4);
    }
    for (std::uint32_t& k : index) k = swap(k);
  }
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(f.data()),
            static_cast<std::streamsize>(f.size() * sizeof(float)));
  out.write(reinterpret_cast<const char*>(index.data()),
            static_cast<std::streamsize>(index.size() * sizeof(std::uint32_t)));
  if (!out)
    throw Error(ErrorCategory::Io,
                "cannot write \"" + file.string() + "\"; check the space and permissions");
}

}  // namespace

std::vector<double> view_parameters(const surface::BSplineBasis& basis) {
  return surface::tessellation_parameters(basis);  // the glTF preview's grid too
}

ViewMesh view_mesh(const surface::BSplineSurface& s) {
  // Positions and normals are the kernel's one tessellator's (surface::tessellate: the same grid,
  // the same limit normal at a pole), so the viewer, the PNG renderer and the glTF preview shade a
  // pole alike. What the viewer adds is curvature.
  const surface::GridMesh grid = surface::tessellate(s);
  ViewMesh m;
  m.us = grid.us;
  m.vs = grid.vs;
  m.rows = grid.rows;
  m.cols = grid.cols;
  const std::size_t n = static_cast<std::size_t>(m.rows) * static_cast<std::size_t>(m.cols);
  m.position.resize(n);
  m.normal.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto r = static_cast<Eigen::Index>(k);
    m.position[k] = grid.positions.row(r).transpose();
    m.normal[k] = grid.normals.row(r).transpose();
  }
  m.gaussian.assign(n, 0.0);
  m.mean.assign(n, 0.0);
  m.deviation.assign(n, 0.0);
  m.degenerate.assign(n, 0);
  const auto at = [&](int i, int j) {
    return static_cast<std::size_t>(i) * static_cast<std::size_t>(m.cols) +
           static_cast<std::size_t>(j);
  };
  const std::vector<surface::SurfaceDerivatives> d = surface::derivatives_grid(s, m.us, m.vs);
  double max_u = 0, max_v = 0;
  for (const auto& x : d) {
    max_u = std::max(max_u, x.du.norm());
    max_v = std::max(max_v, x.dv.norm());
  }
  // Grid lines collapsed to (almost) a point: a pole, a collapsed edge, or the tiny ring a refit
  // leaves of one (about its tolerance across), where the curvature formulas blow up. A line is
  // collapsed when its polyline is shorter than 1e-3 of the longest line of its direction.
  std::vector<double> row_length(static_cast<std::size_t>(m.rows), 0.0),
      col_length(static_cast<std::size_t>(m.cols), 0.0);
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j) {
      if (j + 1 < m.cols)
        row_length[static_cast<std::size_t>(i)] +=
            (m.position[at(i, j + 1)] - m.position[at(i, j)]).norm();
      if (i + 1 < m.rows)
        col_length[static_cast<std::size_t>(j)] +=
            (m.position[at(i + 1, j)] - m.position[at(i, j)]).norm();
    }
  const double longest_row = *std::max_element(row_length.begin(), row_length.end());
  const double longest_col = *std::max_element(col_length.begin(), col_length.end());
  // Degenerate (for curvature): on a collapsed line, a first derivative below 1e-5 of its largest
  // on the grid, or parallel first derivatives.
  const double floor_u = 1e-5 * max_u, floor_v = 1e-5 * max_v;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& x = d[k];
    const Vector3d c = x.du.cross(x.dv);
    const double cn = c.norm(), nu = x.du.norm(), nv = x.dv.norm();
    const bool collapsed = row_length[k / static_cast<std::size_t>(m.cols)] <= 1e-3 * longest_row ||
                           col_length[k % static_cast<std::size_t>(m.cols)] <= 1e-3 * longest_col;
    if (collapsed || !(nu > floor_u && nv > floor_v && cn > 1e-8 * nu * nv) || !std::isfinite(cn)) {
      m.degenerate[k] = 1;
      continue;
    }
    const Vector3d normal = c / cn;  // the exact unit normal, whatever the mesh shows
    const double E = x.du.dot(x.du), F = x.du.dot(x.dv), G = x.dv.dot(x.dv);
    const double L = x.duu.dot(normal), M = x.duv.dot(normal), N = x.dvv.dot(normal);
    const double det = cn * cn;  // EG - F^2 = |S_u x S_v|^2, without the cancellation
    m.gaussian[k] = (L * N - M * M) / det;
    m.mean[k] = (E * N - 2 * F * M + G * L) / (2 * det);
  }
  // Degenerate vertices: the non-degenerate neighbouring vertices' curvatures.
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j) {
      const std::size_t k = at(i, j);
      if (!m.degenerate[k]) continue;
      double K = 0, H = 0;
      int count = 0;
      for (int a = std::max(i - 1, 0); a <= std::min(i + 1, m.rows - 1); ++a)
        for (int b = std::max(j - 1, 0); b <= std::min(j + 1, m.cols - 1); ++b) {
          const std::size_t q = at(a, b);
          if (m.degenerate[q]) continue;
          K += m.gaussian[q];
          H += m.mean[q];
          ++count;
        }
      m.gaussian[k] = count ? K / count : 0.0;
      m.mean[k] = count ? H / count : 0.0;
    }
  return m;
}

ViewMesh view_mesh(const brep::Model& model) {
  const brep::Model flat = brep::flattened(model);
  const brep::ModelMesh mesh = brep::tessellate(flat);
  ViewMesh m;
  m.triangles = mesh.triangles;
  m.position = mesh.positions;
  m.normal = mesh.normals;
  const std::size_t n = mesh.positions.size();
  m.gaussian.assign(n, 0.0);
  m.mean.assign(n, 0.0);
  m.deviation.assign(n, 0.0);
  m.degenerate.assign(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const surface::BSplineSurface& s =
        flat.faces[static_cast<std::size_t>(mesh.node_face[k])].surface;
    const surface::SurfaceDerivatives x = surface::derivatives(s, mesh.uv[k].x(), mesh.uv[k].y());
    const Vector3d c = x.du.cross(x.dv);
    const double cn = c.norm(), nu = x.du.norm(), nv = x.dv.norm();
    if (!(cn > 1e-8 * nu * nv) || !std::isfinite(cn)) {  // a pole, or S_u parallel to S_v
      m.degenerate[k] = 1;
      continue;
    }
    // The outward normal of the mesh gives the sign of H (it bends towards the normal shown).
    const Vector3d normal = (c.dot(mesh.normals[k]) < 0 ? -1.0 : 1.0) * c / cn;
    const double E = x.du.dot(x.du), F = x.du.dot(x.dv), G = x.dv.dot(x.dv);
    const double L = x.duu.dot(normal), M = x.duv.dot(normal), N = x.dvv.dot(normal);
    const double det = cn * cn;
    m.gaussian[k] = (L * N - M * M) / det;
    m.mean[k] = (E * N - 2 * F * M + G * L) / (2 * det);
  }
  // Degenerate nodes: the mean of their non-degenerate neighbours along the triangles.
  std::vector<double> K(n, 0.0), H(n, 0.0);
  std::vector<int> count(n, 0);
  for (const auto& t : m.triangles)
    for (int a : t)
      for (int b : t) {
        const auto i = static_cast<std::size_t>(a), j = static_cast<std::size_t>(b);
        if (!m.degenerate[i] || m.degenerate[j]) continue;
        K[i] += m.gaussian[j];
        H[i] += m.mean[j];
        ++count[i];
      }
  for (std::size_t k = 0; k < n; ++k)
    if (m.degenerate[k] && count[k] > 0) {
      m.gaussian[k] = K[k] / count[k];
      m.mean[k] = H[k] / count[k];
    }
  return m;
}

void set_deviation(ViewMesh& mesh, const surface::BSplineSurface& before,
                   const std::function<Vector3d(const Vector3d&)>& map) {
  if (!map || mesh.us.empty() || mesh.vs.empty()) return;
  const auto [a0, a1] = before.u.domain();
  const auto [b0, b1] = before.v.domain();
  const double u0 = mesh.us.front(), u1 = mesh.us.back(), v0 = mesh.vs.front(), v1 = mesh.vs.back();
  const auto onto = [](double t, double s0, double s1, double r0, double r1) {
    if (t == s1) return r1;
    return std::clamp(r0 + (t - s0) / (s1 - s0) * (r1 - r0), r0, r1);
  };
  for (int i = 0; i < mesh.rows; ++i)
    for (int j = 0; j < mesh.cols; ++j) {
      const double u = onto(mesh.us[static_cast<std::size_t>(i)], u0, u1, a0, a1);
      const double v = onto(mesh.vs[static_cast<std::size_t>(j)], v0, v1, b0, b1);
      const std::size_t k = static_cast<std::size_t>(i) * static_cast<std::size_t>(mesh.cols) +
                            static_cast<std::size_t>(j);
      mesh.deviation[k] = (mesh.position[k] - map(surface::evaluate(before, u, v))).norm();
    }
}

std::vector<float> view_floats(const ViewMesh& m) {
  const std::size_t n = m.position.size();
  std::vector<float> f;
  f.reserve(9 * n);
  for (const auto& p : m.position)
    for (int c = 0; c < 3; ++c) f.push_back(static_cast<float>(p[c]));
  for (const auto& p : m.normal)
    for (int c = 0; c < 3; ++c) f.push_back(static_cast<float>(p[c]));
  for (double x : m.gaussian) f.push_back(static_cast<float>(x));
  for (double x : m.mean) f.push_back(static_cast<float>(x));
  for (double x : m.deviation) f.push_back(static_cast<float>(x));
  return f;
}

void write_view_data(const RunResult& result, const fs::path& dir) {
  const fs::path view = dir / "view";
  std::error_code ec;
  fs::create_directories(view, ec);
  if (ec)
    throw Error(ErrorCategory::Io,
                "cannot create the folder \"" + view.string() + "\": " + ec.message());

  // Meshes, shared between identical surfaces with the same deviation (source -1: none, else the
  // refitted stage's index).
  struct Written {
    const surface::BSplineSurface* surface;
    int source;
    std::string file;
    int rows, cols;
    Vector3d lo, hi;  // of the mesh's vertices
  };
  std::vector<Written> written;
  std::size_t models_written = 0;
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  const auto mesh = [&](const surface::BSplineSurface& s, int source, bool boxed) -> Json {
    for (const auto& w : written)
      if (w.source == source && surface::identical(*w.surface, s)) {
        if (boxed) {
          lo = lo.cwiseMin(w.lo);
          hi = hi.cwiseMax(w.hi);
        }
        return Json{{"file", w.file}, {"rows", w.rows}, {"cols", w.cols}};
      }
    ViewMesh m = view_mesh(s);
    if (source >= 0) {
      const Stage& stage = result.stages[static_cast<std::size_t>(source)];
      set_deviation(m, stage.before, stage.map);
    }
    Vector3d mlo = Vector3d::Constant(std::numeric_limits<double>::infinity()), mhi = -mlo;
    for (const auto& p : m.position) {
      mlo = mlo.cwiseMin(p);
      mhi = mhi.cwiseMax(p);
    }
    if (boxed) {
      lo = lo.cwiseMin(mlo);
      hi = hi.cwiseMax(mhi);
    }
    char name[32];
    std::snprintf(name, sizeof name, "%03zu.bin", written.size());
    write_mesh_file(view / name, view_floats(m), {});
    written.push_back({&s, source, name, m.rows, m.cols, mlo, mhi});
    return Json{{"file", name}, {"rows", m.rows}, {"cols", m.cols}};
  };

  Json surfaces = Json::array();
  for (const auto& e : result.exports)
    for (std::size_t k = 0; k < e.surfaces.size() && k < e.surface_names.size(); ++k) {
      const std::string& name = e.surface_names[k];
      const surface::BSplineSurface& s = e.surfaces[k];
      std::vector<std::size_t> own;
      for (std::size_t q = 0; q < result.stages.size(); ++q)
        if (result.stages[q].surface == name) own.push_back(q);
      Json stages = Json::array();
      for (std::size_t q : own) {
        const Stage& st = result.stages[q];
        const StepReport* rep = step_named(result, st.step);
        const bool refit = st.map && is_refit(rep);
        const std::string step = step_name(rep);
        Json curves = Json::array();
        for (const auto& c : st.curves)
          for (const auto& [n, curve] : result.curves)
            if (n == c) {
              curves.push_back(curve_json(n, curve));
              break;
            }
        Json x = Json::object();
        x["step"] = st.step;
        x["kind"] = st.kind;
        x["label"] = st.kind + (step.empty() ? "" : " '" + step + "'");
        x["before"] = mesh(st.before, -1, false);
        x["after"] = mesh(st.after, refit ? static_cast<int>(q) : -1, false);
        x["net_before"] = net_json(st.before);
        x["net_after"] = net_json(st.after);
        x["curves"] = std::move(curves);
        x["figures"] = figures_json(rep);
        x["refit"] = refit;
        stages.push_back(std::move(x));
      }
      // The final mesh: the last stage's `after` (with its deviation) when it is this surface.
      int source = -1;
      if (!own.empty()) {
        const Stage& last = result.stages[own.back()];
        if (surface::identical(last.after, s) && last.map &&
            is_refit(step_named(result, last.step)))
          source = static_cast<int>(own.back());
      }
      const StepReport* made = own.empty() ? step_named(result, "surfaces." + name)
                                           : step_named(result, result.stages[own.back()].step);
      Json x = Json::object();
      x["name"] = name;
      x["export"] = e.name;
      x["figures"] = figures_json(made);
      x["mesh"] = mesh(s, source, true);
      x["net"] = net_json(s);
      x["stages"] = std::move(stages);
      surfaces.push_back(std::move(x));
    }

  // Whole models: one triangle mesh each, all faces trimmed (holes are holes).
  for (const auto& model : result.models) {
    const ViewMesh m = view_mesh(model.model);
    for (const auto& p : m.position) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    char name[32];
    std::snprintf(name, sizeof name, "%03zu.bin", written.size() + models_written++);
    write_mesh_file(view / name, view_floats(m), m.triangles);
    Json figures = Json::object();
    for (const auto& step : result.steps)
      if (step.path == "models." + model.name)
        for (const auto& [n, value] : step.figures) figures[n] = figure_json(value);
    Json x = Json::object();
    x["name"] = model.name;
    x["export"] = model.name;
    x["kind"] = "model";
    x["figures"] = std::move(figures);
    x["mesh"] =
        Json{{"file", name}, {"vertices", m.position.size()}, {"triangles", m.triangles.size()}};
    x["net"] = nullptr;
    x["stages"] = Json::array();
    x["continuity"] =
        detail::continuity_json(model.report.continuity_before, model.report.continuity_after);
    surfaces.push_back(std::move(x));
  }

  Json j = Json::object();
  j["format"] = "clayform.view";
  j["version"] = 1;
  j["recipe"] = result.recipe;
  j["report"] = "../report.json";
  j["surfaces"] = std::move(surfaces);
  if (!std::isfinite(lo.x())) lo = hi = Vector3d::Zero();
  j["box"] = Json{{"min", point_json(lo)}, {"max", point_json(hi)}};
  std::ofstream out(view / "manifest.json", std::ios::binary);
  out << j.dump() << "\n";  // compact: the nets are thousands of points
  if (!out)
    throw Error(ErrorCategory::Io, "cannot write \"" + (view / "manifest.json").string() + "\"");
}

}  // namespace clay::recipe
