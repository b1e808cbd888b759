#pragma once
// Reading the steps of the "clayform.deformation-stack" schema (docs/deform.md) with the shared
// JsonReader (internal, not installed): deform::stack_from_json and the recipe checker, whose
// taper, twist, bend and extended-lattice steps use the same schema, both call read_step, so a
// problem carries its JSON path wherever the step sits. A detail header of the deform module
// (deform/detail/): never installed, included only by sources of deform and the modules above it.
// Its names stay in clay::internal beside the JsonReader they extend.
#include <clay/deform/stack.hpp>
#include <clay/internal/json_reader.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace clay::internal {

// ---- per kind: the JSON name and the fields after "kind", "name", "enabled" -------------------

inline std::string_view kind_of(const deform::BezierLattice&) { return "bezier_lattice"; }
inline std::string_view kind_of(const deform::BSplineLattice&) { return "bspline_lattice"; }
inline std::string_view kind_of(const deform::ExtendedLattice&) { return "extended_lattice"; }
inline std::string_view kind_of(const deform::Taper&) { return "taper"; }
inline std::string_view kind_of(const deform::Twist&) { return "twist"; }
inline std::string_view kind_of(const deform::Bend&) { return "bend"; }

inline std::optional<deform::Frame> lattice_frame(JsonReader& r, const Json& v,
                                                  const std::string& path) {
  if (!r.object(v, path, {"origin", "s", "t", "u"}, "a lattice frame {origin, s, t, u}"))
    return std::nullopt;
  deform::Frame f;
  bool ok = true;
  for (auto [key, target] :
       {std::pair{"origin", &f.origin}, {"s", &f.s}, {"t", &f.t}, {"u", &f.u}}) {
    const Json* m = r.member(v, path, key, true, "[x, y, z] (mm)");
    const auto x = m ? r.vec3(*m, key_path(path, key)) : std::nullopt;
    ok = ok && x.has_value();
    if (x) *target = *x;
  }
  return ok ? std::optional(f) : std::nullopt;
}

inline std::optional<deform::AxisFrame> axis_frame(JsonReader& r, const Json& v,
                                                   const std::string& path) {
  if (!r.object(v, path, {"origin", "axis", "reference"},
                "an axis frame {origin, axis, reference}"))
    return std::nullopt;
  deform::AxisFrame f;
  bool ok = true;
  for (auto [key, target] :
       {std::pair{"origin", &f.origin}, {"axis", &f.axis}, {"reference", &f.reference}}) {
    const Json* m = r.member(v, path, key, true, "[x, y, z]");
    const auto x = m ? r.vec3(*m, key_path(path, key)) : std::nullopt;
    ok = ok && x.has_value();
    if (x) *target = *x;
  }
  return ok ? std::optional(f) : std::nullopt;
}

/// A required member read by `read(value, path)`; nullopt (reported) when missing or bad.
template <class Read>
auto required(JsonReader& r, const Json& j, const std::string& path, std::string_view key,
              std::string_view hint, Read read) -> decltype(read(j, path)) {
  const Json* m = r.member(j, path, key, true, hint);
  if (!m) return std::nullopt;
  return read(*m, key_path(path, key));
}

/// A required member holding control points [[x, y, z], ...].
inline std::optional<surface::Points3> points_member(JsonReader& r, const Json& j,
                                                     const std::string& path, std::string_view key,
                                                     std::string_view hint) {
  return required(r, j, path, key, hint,
                  [&](const Json& v, const std::string& p) { return r.points(v, p, 0); });
}

inline bool read_fields(JsonReader& r, deform::BezierLattice& d, const Json& j,
                        const std::string& path) {
  r.object(j, path, {"kind", "name", "enabled", "frame", "degrees", "points"},
           "a bezier_lattice step");
  const auto frame =
      required(r, j, path, "frame", "the lattice frame {origin, s, t, u}",
               [&](const Json& v, const std::string& p) { return lattice_frame(r, v, p); });
  bool ok = frame.has_value();
  if (frame) d.frame = *frame;
  if (const Json* deg = r.member(j, path, "degrees", true, "the degrees as [l, m, n]")) {
    const std::string dp = key_path(path, "degrees");
    if (!deg->is_array() || deg->size() != 3) {
      r.add(dp, "expected 3 integers, found " + found(*deg) + "; give [l, m, n]");
      ok = false;
    } else {
      for (std::size_t i = 0; i < 3; ++i) {
        const auto v = r.integer((*deg)[i], index_path(dp, i), 0, 1'000'000'000);
        ok = ok && v.has_value();
        if (v) d.degrees[i] = *v;
      }
    }
  } else {
    ok = false;
  }
  const auto pts = points_member(r, j, path, "points", "the control points [[x, y, z], ...]");
  if (pts) d.points = *pts;
  return ok && pts.has_value();
}

inline bool read_fields(JsonReader& r, deform::BSplineLattice& d, const Json& j,
                        const std::string& path) {
  r.object(j, path, {"kind", "name", "enabled", "frame", "bases", "points"},
           "a bspline_lattice step");
  const auto frame =
      required(r, j, path, "frame", "the lattice frame {origin, s, t, u}",
               [&](const Json& v, const std::string& p) { return lattice_frame(r, v, p); });
  bool ok = frame.has_value();
  if (frame) d.frame = *frame;
  if (const Json* bases =
          r.member(j, path, "bases", true, "three bases [{degree, knots}, ...] along S, T, U")) {
    const std::string bp = key_path(path, "bases");
    if (!bases->is_array() || bases->size() != 3) {
      r.add(bp, "expected 3 bases (along S, T, U), found " + found(*bases) +
                    "; give [{\"degree\": p, \"knots\": [...]}, ...]");
      ok = false;
    } else {
      for (std::size_t i = 0; i < 3; ++i) {
        const std::string p = index_path(bp, i);
        const Json& b = (*bases)[i];
        if (!r.object(b, p, {"degree", "knots"}, "a basis {degree, knots}")) {
          ok = false;
          continue;
        }
        const auto degree = required(
            r, b, p, "degree", "the degree p >= 1",
            [&](const Json& v, const std::string& q) { return r.integer(v, q, 0, 1'000'000'000); });
        const auto knots =
            required(r, b, p, "knots", "the knot vector",
                     [&](const Json& v, const std::string& q) { return r.numbers(v, q, 0); });
        ok = ok && degree && knots;
        if (degree) d.bases[i].degree = *degree;
        if (knots) d.bases[i].knots = *knots;
      }
    }
  } else {
    ok = false;
  }
  const auto pts = points_member(r, j, path, "points", "the control points [[x, y, z], ...]");
  if (pts) d.points = *pts;
  return ok && pts.has_value();
}

inline bool read_fields(JsonReader& r, deform::ExtendedLattice& d, const Json& j,
                        const std::string& path) {
  r.object(j, path, {"kind", "name", "enabled", "rest", "points", "chunks"},
           "an extended_lattice step");
  const auto rest = points_member(r, j, path, "rest", "the rest control points [[x, y, z], ...]");
  const auto pts =
      points_member(r, j, path, "points", "the current control points [[x, y, z], ...]");
  bool ok = rest && pts;
  if (rest) d.rest = *rest;
  if (pts) d.points = *pts;
  const Eigen::Index rows = d.rest.rows();
  if (rest && pts && d.points.rows() != rows) {
    r.add(key_path(path, "points"), "found " + std::to_string(d.points.rows()) +
                                        " control points but rest has " + std::to_string(rows) +
                                        "; give one current position per rest control point");
    ok = false;
  }
  const Json* chunks = r.member(j, path, "chunks", true, "the chunks, each 64 row indices");
  if (!chunks) return false;
  const std::string cp = key_path(path, "chunks");
  if (!chunks->is_array()) {
    r.add(cp, "expected an array of chunks (64 row indices each), found " + found(*chunks));
    return false;
  }
  d.chunks.resize(chunks->size());
  for (std::size_t c = 0; c < chunks->size(); ++c) {
    const std::string p = index_path(cp, c);
    const Json& chunk = (*chunks)[c];
    if (!chunk.is_array() ||
        chunk.size() != static_cast<std::size_t>(deform::chunk_control_points)) {
      r.add(p, "expected 64 indices (control point (i, j, k) at (i * 4 + j) * 4 + k), found " +
                   found(chunk));
      ok = false;
      continue;
    }
    for (std::size_t e = 0; e < chunk.size(); ++e) {
      const std::string ep = index_path(p, e);
      if (!chunk[e].is_number_integer()) {
        r.add(ep,
              "expected an integer, found " + found(chunk[e]) + "; give a row of rest / points");
        ok = false;
        continue;
      }
      const long long index = chunk[e].get<long long>();
      if (rest && (index < 0 || index >= rows)) {
        r.add(ep, "index " + std::to_string(index) + " is out of range " +
                      (rows > 0 ? "(0.." + std::to_string(rows - 1) + ")" : "(rest has no rows)") +
                      "; give a row of rest / points");
        ok = false;
        continue;
      }
      d.chunks[c][e] = static_cast<int>(index);
    }
  }
  return ok;
}

inline bool read_fields(JsonReader& r, deform::Taper& d, const Json& j, const std::string& path) {
  r.object(j, path, {"kind", "name", "enabled", "frame", "profile"}, "a taper step");
  const auto frame =
      required(r, j, path, "frame", "the axis frame {origin, axis, reference}",
               [&](const Json& v, const std::string& p) { return axis_frame(r, v, p); });
  const auto profile =
      required(r, j, path, "profile", "the coefficients of r(z), e.g. [1, -0.01]",
               [&](const Json& v, const std::string& p) { return r.numbers(v, p, 0); });
  if (frame) d.frame = *frame;
  if (profile) d.profile = *profile;
  return frame && profile;
}

inline bool read_fields(JsonReader& r, deform::Twist& d, const Json& j, const std::string& path) {
  r.object(j, path, {"kind", "name", "enabled", "frame", "angle"}, "a twist step");
  const auto frame =
      required(r, j, path, "frame", "the axis frame {origin, axis, reference}",
               [&](const Json& v, const std::string& p) { return axis_frame(r, v, p); });
  const auto angle =
      required(r, j, path, "angle", "the coefficients of θ(z) in radians, e.g. [0, 0.01]",
               [&](const Json& v, const std::string& p) { return r.numbers(v, p, 0); });
  if (frame) d.frame = *frame;
  if (angle) d.angle = *angle;
  return frame && angle;
}

inline bool read_fields(JsonReader& r, deform::Bend& d, const Json& j, const std::string& path) {
  r.object(j, path, {"kind", "name", "enabled", "frame", "y_min", "y_max", "center", "rate"},
           "a bend step");
  const auto frame =
      required(r, j, path, "frame", "the axis frame {origin, axis, reference}",
               [&](const Json& v, const std::string& p) { return axis_frame(r, v, p); });
  bool ok = frame.has_value();
  if (frame) d.frame = *frame;
  for (auto [key, target, hint] :
       {std::tuple{"y_min", &d.y_min, "the start of the bent region (mm)"},
        {"y_max", &d.y_max, "the end of the bent region (mm)"},
        {"center", &d.center, "the centre of the bend y0 (mm)"},
        {"rate", &d.rate, "the bending rate k (rad/mm)"}}) {
    const auto x = required(r, j, path, key, hint,
                            [&](const Json& v, const std::string& p) { return r.number(v, p); });
    ok = ok && x.has_value();
    if (x) *target = *x;
  }
  return ok;
}

/// Calls f(T{}) for every alternative T of deform::Deformation, in the variant's order.
template <class F>
void for_each_kind(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::variant_alternative_t<I, deform::Deformation>{}), ...);
  }
  (std::make_index_sequence<std::variant_size_v<deform::Deformation>>{});
}

/// The kinds of the schema, in the variant's order.
inline std::vector<std::string> deformation_kinds() {
  std::vector<std::string> out;
  for_each_kind([&](const auto& none) { out.emplace_back(kind_of(none)); });
  return out;
}

/// The deformation of kind `kind` read from j (structure only: deform::problems checks the
/// values); nullopt with the problems recorded when it cannot be read.
inline std::optional<deform::Deformation> read_deformation(JsonReader& r, std::string_view kind,
                                                           const Json& j, const std::string& path) {
  std::optional<deform::Deformation> out;
  bool known = false;
  for_each_kind([&](auto value) {
    if (kind != kind_of(value)) return;
    known = true;
    if (read_fields(r, value, j, path)) out = std::move(value);
  });
  if (!known)
    r.add(key_path(path, "kind"),
          "unknown kind \"" + std::string(kind) + "\"; give one of " + join(deformation_kinds()));
  return out;
}

/// A whole step {kind, name, enabled, ...}; nullopt with the problems recorded when it cannot
/// be read.
inline std::optional<deform::DeformationStep> read_step(JsonReader& r, const Json& j,
                                                        const std::string& path) {
  if (!j.is_object()) {
    r.add(path, "expected a step {\"kind\": ..., ...} (a JSON object), found " + found(j));
    return std::nullopt;
  }
  deform::DeformationStep step;
  bool ok = true;
  if (const Json* n = r.member(j, path, "name", false, "")) {
    const auto name = r.string(*n, key_path(path, "name"));
    ok = name.has_value();
    step.name = name.value_or("");
  }
  if (const Json* e = r.member(j, path, "enabled", false, "")) {
    const auto enabled = r.boolean(*e, key_path(path, "enabled"));
    ok = ok && enabled.has_value();
    step.enabled = enabled.value_or(true);
  }
  const Json* kind = r.member(j, path, "kind", true,
                              "the kind of deformation, one of " + join(deformation_kinds()));
  if (!kind) return std::nullopt;
  const auto k = r.string(*kind, key_path(path, "kind"));
  if (!k) return std::nullopt;
  auto d = read_deformation(r, *k, j, path);
  if (!d || !ok) return std::nullopt;
  step.deformation = std::move(*d);
  return step;
}

/// "steps[3] (bend 'hood')": how the semantic problems of a step are labelled.
inline std::string step_label(const std::string& path, const deform::DeformationStep& step) {
  std::string label = path + " (" + std::string(deform::kind_name(step.deformation));
  if (!step.name.empty()) label += " '" + step.name + "'";
  return label + ")";
}

}  // namespace clay::internal
