// The isolated read's answer: see model_wire.hpp.
#include "model_wire.hpp"

#include <clay/occt/model_exchange.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "convert.hpp"
#include "exchange_precheck.hpp"
#include "session.hpp"

namespace clay::brep::detail {

namespace {

using internal::shortest;

// ---- the isolated read's answer ---------------------------------------------------------------

using surface::occt::put;
using surface::occt::put_doubles;
using surface::occt::Unpacker;

void put_string(std::string& out, const std::string& text) {
  put(out, static_cast<std::uint64_t>(text.size()));
  out += text;
}

std::string take_string(Unpacker& in) {
  const auto n = in.take<std::uint64_t>();
  std::string text;
  text.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(n, 1u << 20)));
  for (std::uint64_t i = 0; i < n; ++i) text += in.take<char>();
  return text;
}

void put_curve(std::string& out, const surface::BSplineCurve& c) {
  put(out, static_cast<std::int32_t>(c.basis.degree));
  put_doubles(out, c.basis.knots.data(), c.basis.knots.size());
  put_doubles(out, c.points.data(), static_cast<std::size_t>(c.points.size()));
  put_doubles(out, c.weights.data(), static_cast<std::size_t>(c.weights.size()));
}

surface::BSplineCurve take_curve(Unpacker& in) {
  surface::BSplineCurve c;
  c.basis.degree = in.take<std::int32_t>();
  c.basis.knots = in.doubles();
  const std::vector<double> points = in.doubles(), weights = in.doubles();
  c.points = Eigen::Map<const surface::Points3>(points.data(),
                                                static_cast<Eigen::Index>(points.size() / 3), 3);
  c.weights =
      Eigen::Map<const Eigen::VectorXd>(weights.data(), static_cast<Eigen::Index>(weights.size()));
  return c;
}

void put_colour(std::string& out, const std::optional<Colour>& c) {
  put(out, static_cast<std::int8_t>(c.has_value()));
  if (c) {
    put(out, c->r);
    put(out, c->g);
    put(out, c->b);
  }
}

std::optional<Colour> take_colour(Unpacker& in) {
  if (!in.take<std::int8_t>()) return std::nullopt;
  Colour c;
  c.r = in.take<double>();
  c.g = in.take<double>();
  c.b = in.take<double>();
  return c;
}

void put_instance(std::string& out, const Instance& i) {
  put(out, static_cast<std::int32_t>(i.part));
  put_doubles(out, i.placement.matrix().data(), 16);
  put_string(out, i.name);
}

Instance take_instance(Unpacker& in) {
  Instance i;
  i.part = in.take<std::int32_t>();
  const std::vector<double> m = in.doubles();
  if (m.size() == 16) i.placement.matrix() = Eigen::Map<const Eigen::Matrix4d>(m.data());
  i.name = take_string(in);
  return i;
}

void put_ints(std::string& out, const std::vector<int>& list) {
  put(out, static_cast<std::uint64_t>(list.size()));
  for (int x : list) put(out, static_cast<std::int32_t>(x));
}

std::vector<int> take_ints(Unpacker& in) {
  const auto n = in.take<std::uint64_t>();
  std::vector<int> out;
  for (std::uint64_t i = 0; i < n; ++i) out.push_back(in.take<std::int32_t>());
  return out;
}

}  // namespace

/// Everything read_model returns, as bytes (native layout: one build on both ends of the pipe).
std::string serialize(const ImportedModel& x) {
  const Model& m = x.model;
  std::string out;
  put(out, static_cast<std::uint64_t>(m.vertices.size()));
  for (const Vertex& v : m.vertices) {
    put_doubles(out, v.point.data(), 3);
    put(out, v.tolerance_mm);
  }
  put(out, static_cast<std::uint64_t>(m.edges.size()));
  for (const Edge& e : m.edges) {
    put(out, static_cast<std::int8_t>(e.degenerate));
    if (!e.degenerate) put_curve(out, e.curve);
    put(out, e.t0);
    put(out, e.t1);
    put(out, e.tolerance_mm);
    put(out, static_cast<std::int32_t>(e.start));
    put(out, static_cast<std::int32_t>(e.end));
  }
  put(out, static_cast<std::uint64_t>(m.faces.size()));
  for (const Face& f : m.faces) {
    put(out, static_cast<std::int32_t>(f.surface.u.degree));
    put(out, static_cast<std::int32_t>(f.surface.v.degree));
    put_doubles(out, f.surface.u.knots.data(), f.surface.u.knots.size());
    put_doubles(out, f.surface.v.knots.data(), f.surface.v.knots.size());
    put_doubles(out, f.surface.points.data(), static_cast<std::size_t>(f.surface.points.size()));
    put_doubles(out, f.surface.weights.data(), static_cast<std::size_t>(f.surface.weights.size()));
    put(out, static_cast<std::int8_t>(f.reversed));
    put(out, static_cast<std::uint64_t>(f.loops.size()));
    for (const Loop& l : f.loops) {
      put(out, static_cast<std::uint64_t>(l.coedges.size()));
      for (const Coedge& c : l.coedges) {
        put(out, static_cast<std::int32_t>(c.edge));
        put(out, static_cast<std::int8_t>(c.same_sense));
        put_curve(out, c.pcurve);
      }
    }
    put_string(out, f.name);
    put_colour(out, f.colour);
    put(out, static_cast<std::int8_t>(f.elementary.has_value()));
    if (f.elementary) {
      const Elementary& e = *f.elementary;
      put(out, static_cast<std::int32_t>(e.kind));
      for (const Eigen::Vector3d* v : {&e.origin, &e.x_axis, &e.y_axis, &e.z_axis})
        put_doubles(out, v->data(), 3);
      put(out, e.radius);
      put(out, e.minor_radius);
      put(out, e.semi_angle);
    }
  }
  put(out, static_cast<std::uint64_t>(m.bodies.size()));
  for (const Body& b : m.bodies) {
    put(out, static_cast<std::int32_t>(b.kind));
    put(out, static_cast<std::uint64_t>(b.shells.size()));
    for (const Shell& s : b.shells) put_ints(out, s.faces);
    put_ints(out, b.edges);
    put_string(out, b.name);
    put_colour(out, b.colour);
  }
  put(out, static_cast<std::uint64_t>(m.parts.size()));
  for (const Part& p : m.parts) {
    put_string(out, p.name);
    put_ints(out, p.bodies);
    put(out, static_cast<std::uint64_t>(p.components.size()));
    for (const Instance& i : p.components) put_instance(out, i);
    put_colour(out, p.colour);
  }
  put(out, static_cast<std::uint64_t>(m.roots.size()));
  for (const Instance& i : m.roots) put_instance(out, i);
  const ModelReadReport& r = x.report;
  put(out, r.size_mm);
  for (int v : {r.faces_bspline, r.faces_affine, r.faces_angular, r.faces_approximated,
                r.pcurves_kept, r.pcurves_exact, r.pcurves_fitted})
    put(out, static_cast<std::int32_t>(v));
  put(out, r.max_approximation_error_mm);
  put(out, r.max_rederivation_error_mm);
  put(out, r.max_edge_tolerance_mm);
  put(out, static_cast<std::uint64_t>(r.healing.size()));
  for (const auto& h : r.healing) put_string(out, h);
  put(out, static_cast<std::uint64_t>(r.ignored.size()));
  for (const auto& h : r.ignored) put_string(out, h);
  put(out, static_cast<std::uint64_t>(r.skipped.size()));
  for (const auto& h : r.skipped) put_string(out, h);
  put(out, static_cast<std::uint64_t>(r.left_out.size()));
  for (const auto& h : r.left_out) put_string(out, h);
  return out;
}

/// Reads back what serialize wrote; counts, gaps and problems are computed again here, from the
/// model as it arrived.
ImportedModel deserialize(const std::string& bytes) {
  Unpacker in(bytes);
  ImportedModel x;
  Model& m = x.model;
  m.vertices.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (Vertex& v : m.vertices) {
    const std::vector<double> p = in.doubles();
    if (p.size() == 3) v.point = {p[0], p[1], p[2]};
    v.tolerance_mm = in.take<double>();
  }
  m.edges.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (Edge& e : m.edges) {
    e.degenerate = in.take<std::int8_t>() != 0;
    if (!e.degenerate) e.curve = take_curve(in);
    e.t0 = in.take<double>();
    e.t1 = in.take<double>();
    e.tolerance_mm = in.take<double>();
    e.start = in.take<std::int32_t>();
    e.end = in.take<std::int32_t>();
  }
  m.faces.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (Face& f : m.faces) {
    f.surface.u.degree = in.take<std::int32_t>();
    f.surface.v.degree = in.take<std::int32_t>();
    f.surface.u.knots = in.doubles();
    f.surface.v.knots = in.doubles();
    const std::vector<double> points = in.doubles(), weights = in.doubles();
    f.surface.points = Eigen::Map<const surface::Points3>(
        points.data(), static_cast<Eigen::Index>(points.size() / 3), 3);
    f.surface.weights = Eigen::Map<const Eigen::VectorXd>(
        weights.data(), static_cast<Eigen::Index>(weights.size()));
    f.reversed = in.take<std::int8_t>() != 0;
    f.loops.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
    for (Loop& l : f.loops) {
      l.coedges.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
      for (Coedge& c : l.coedges) {
        c.edge = in.take<std::int32_t>();
        c.same_sense = in.take<std::int8_t>() != 0;
        c.pcurve = take_curve(in);
      }
    }
    f.name = take_string(in);
    f.colour = take_colour(in);
    if (in.take<std::int8_t>()) {
      Elementary e;
      e.kind = static_cast<ElementaryKind>(in.take<std::int32_t>());
      for (Eigen::Vector3d* v : {&e.origin, &e.x_axis, &e.y_axis, &e.z_axis}) {
        const std::vector<double> xyz = in.doubles();
        if (xyz.size() == 3) *v = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
      }
      e.radius = in.take<double>();
      e.minor_radius = in.take<double>();
      e.semi_angle = in.take<double>();
      f.elementary = e;
    }
  }
  m.bodies.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (Body& b : m.bodies) {
    b.kind = static_cast<BodyKind>(in.take<std::int32_t>());
    b.shells.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
    for (Shell& s : b.shells) s.faces = take_ints(in);
    b.edges = take_ints(in);
    b.name = take_string(in);
    b.colour = take_colour(in);
  }
  m.parts.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (Part& p : m.parts) {
    p.name = take_string(in);
    p.bodies = take_ints(in);
    p.components.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
    for (Instance& i : p.components) i = take_instance(in);
    p.colour = take_colour(in);
  }
  m.roots.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (Instance& i : m.roots) i = take_instance(in);
  ModelReadReport& r = x.report;
  r.size_mm = in.take<double>();
  for (int* v : {&r.faces_bspline, &r.faces_affine, &r.faces_angular, &r.faces_approximated,
                 &r.pcurves_kept, &r.pcurves_exact, &r.pcurves_fitted})
    *v = in.take<std::int32_t>();
  r.max_approximation_error_mm = in.take<double>();
  r.max_rederivation_error_mm = in.take<double>();
  r.max_edge_tolerance_mm = in.take<double>();
  r.healing.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (auto& h : r.healing) h = take_string(in);
  r.ignored.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (auto& h : r.ignored) h = take_string(in);
  r.skipped.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (auto& h : r.skipped) h = take_string(in);
  r.left_out.resize(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (auto& h : r.left_out) h = take_string(in);
  return x;
}

/// The figures that depend only on the model: counts, the largest edge gap and the problems.
void complete_report(ImportedModel& x) {
  x.report.counts = counts(x.model);
  x.report.problems = problems(x.model);
  double gap = 0;
  if (x.report.problems.empty())
    for (const EdgeGap& g : edge_gaps(x.model)) gap = std::max(gap, g.gap_mm);
  x.report.max_edge_gap_mm = gap;
}

}  // namespace clay::brep::detail
