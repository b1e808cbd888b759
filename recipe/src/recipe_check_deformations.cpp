// The recipe checker: deformation stacks, lattices, style and direct steps (recipe_checker.hpp).
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "recipe_checker.hpp"

namespace clay::recipe::check_detail {

std::optional<deform::Frame> RecipeChecker::lattice_frame(const Json& j, const std::string& path) {
  if (!c_.object(j, path, {"origin", "s", "t", "u"}, "a lattice frame {origin, s, t, u}"))
    return std::nullopt;
  deform::Frame f;
  if (!c_.vec3_members(j, path, {{"origin", &f.origin}, {"s", &f.s}, {"t", &f.t}, {"u", &f.u}}))
    return std::nullopt;
  return c_.checked(f, path, deform::problems(f, path));
}

std::optional<std::array<int, 3>> RecipeChecker::triple(const Json& obj, const std::string& path,
                                                        std::string_view key, int lo, int hi,
                                                        std::string_view hint) {
  const Json* j = c_.member(obj, path, key, true, hint);
  if (!j) return std::nullopt;
  const std::string p = key_path(path, key);
  if (!j->is_array() || j->size() != 3) {
    c_.add(p, "expected 3 integers " + std::string(hint) + ", found " + found(*j));
    return std::nullopt;
  }
  std::array<int, 3> out{};
  bool ok = true;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto x = c_.integer((*j)[k], index_path(p, k), lo, hi);
    ok = ok && x.has_value();
    out[k] = x.value_or(0);
  }
  return ok ? std::optional(out) : std::nullopt;
}

bool RecipeChecker::lattice_size_ok(std::array<long, 3> counts, const std::string& path) {
  const long total = counts[0] * counts[1] * counts[2];
  if (total <= limit::lattice_points) return true;
  c_.add(path, "the lattice would have " + std::to_string(counts[0]) + " x " +
                   std::to_string(counts[1]) + " x " + std::to_string(counts[2]) + " = " +
                   std::to_string(total) + " control points; at most " +
                   std::to_string(limit::lattice_points) +
                   " are allowed (recipe limit): use fewer cells or lower degrees");
  return false;
}

bool RecipeChecker::chunks_ok(long chunks, const std::string& path) {
  if (chunks <= limit::chunks) return true;
  c_.add(path, "the lattice would have " + std::to_string(chunks) + " chunks; at most " +
                   std::to_string(limit::chunks) +
                   " are allowed (recipe limit): use fewer sectors, rings, sections or layers");
  return false;
}

std::optional<Eigen::Index> RecipeChecker::lattice_row(const Json& m, const std::string& p,
                                                       std::array<int, 3> counts) {
  const Json* idx = c_.member(m, p, "index", true, "[i, j, k]");
  if (!idx) return std::nullopt;
  const std::string ip = key_path(p, "index");
  if (!idx->is_array() || idx->size() != 3) {
    c_.add(ip, "expected [i, j, k], found " + found(*idx));
    return std::nullopt;
  }
  Eigen::Index row = 0;
  bool ok = true;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto x = c_.integer((*idx)[k], index_path(ip, k), 0, counts[k] - 1);
    ok = ok && x.has_value();
    row = row * counts[k] + x.value_or(0);
  }
  return ok ? std::optional(row) : std::nullopt;
}

std::optional<deform::Deformation> RecipeChecker::lattice(
    const Json& j, const std::string& path, bool bspline,
    std::initializer_list<std::string_view> extra_keys) {
  std::vector<std::string_view> keys{"kind",    "name",   "enabled", "frame",
                                     "degrees", "points", "moves"};
  if (bspline) keys.insert(keys.end(), {"bases", "cells", "knots"});
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  for (const auto& [key, v] : j.items()) {
    (void)v;
    if (std::find(keys.begin(), keys.end(), key) == keys.end())
      c_.add(key_path(path, key), "unknown key \"" + key + "\" in a " +
                                      std::string(bspline ? "bspline_lattice" : "bezier_lattice") +
                                      " step; the keys are: " +
                                      join(std::vector<std::string>(keys.begin(), keys.end())));
  }
  const Json* fj = c_.member(j, path, "frame", true, "{\"origin\", \"s\", \"t\", \"u\"}");
  const auto frame = fj ? lattice_frame(*fj, key_path(path, "frame")) : std::nullopt;
  std::optional<deform::Deformation> out;
  if (!bspline) {
    const auto degrees = triple(j, path, "degrees", 1, surface::max_kernel_degree, "[l, m, n]");
    if (!frame || !degrees) return std::nullopt;
    if (!lattice_size_ok({(*degrees)[0] + 1L, (*degrees)[1] + 1L, (*degrees)[2] + 1L},
                         key_path(path, "degrees")))
      return std::nullopt;
    deform::BezierLattice lat = deform::make_bezier_lattice(*frame, *degrees);
    if (!lattice_points(j, path, lat.points, lat.counts())) return std::nullopt;
    const auto list = deform::problems(lat, path);
    if (!list.empty()) return c_.add_all(path, list), std::nullopt;
    out = std::move(lat);
  } else {
    std::optional<deform::BSplineLattice> lat;
    const bool has_bases = j.contains("bases");
    if (has_bases == j.contains("cells")) {
      c_.add(path,
             "give either \"bases\" (three {degree, knots}) or \"cells\" with \"degrees\" and "
             "\"knots\"");
      return std::nullopt;
    }
    if (has_bases) {
      const Json& b = j.at("bases");
      const std::string bp = key_path(path, "bases");
      if (!b.is_array() || b.size() != 3) {
        c_.add(bp, "expected 3 bases [{degree, knots}, ...] along s, t, u, found " + found(b));
        return std::nullopt;
      }
      std::array<surface::BSplineBasis, 3> bases;
      bool ok = true;
      for (std::size_t k = 0; k < 3; ++k) {
        const std::string p = index_path(bp, k);
        if (!c_.object(b[k], p, {"degree", "knots"}, "a basis {degree, knots}")) {
          ok = false;
          continue;
        }
        const Json* d = c_.member(b[k], p, "degree", true, "the degree");
        const Json* kn = c_.member(b[k], p, "knots", true, "the knot vector on [0, 1]");
        const auto degree =
            d ? c_.integer(*d, key_path(p, "degree"), 1, surface::max_kernel_degree) : std::nullopt;
        const auto knots =
            kn ? c_.numbers(*kn, key_path(p, "knots"), 2, limit::lattice_points) : std::nullopt;
        ok = ok && degree && knots;
        if (degree && knots) bases[k] = {*degree, *knots};
      }
      if (!ok || !frame) return std::nullopt;
      std::array<long, 3> counts{};
      for (std::size_t k = 0; k < 3; ++k)
        counts[k] = std::max(0L, static_cast<long>(bases[k].knots.size()) - bases[k].degree - 1);
      if (!lattice_size_ok(counts, bp)) return std::nullopt;
      if (!c_.attempt(bp, [&] { lat = deform::make_bspline_lattice(*frame, bases); }))
        return std::nullopt;
    } else {
      const auto cells = triple(j, path, "cells", 1, limit::lattice_cells, "[a, b, c]");
      const auto degrees = triple(j, path, "degrees", 1, surface::max_kernel_degree, "[p, q, r]");
      deform::LatticeKnots knots = deform::LatticeKnots::Clamped;
      if (const Json* k = c_.member(j, path, "knots", false, ""))
        if (const auto c = c_.choice(*k, key_path(path, "knots"), {"clamped", "uniform"}))
          knots = static_cast<deform::LatticeKnots>(*c);
      if (!cells || !degrees || !frame) return std::nullopt;
      if (!lattice_size_ok({(*cells)[0] + static_cast<long>((*degrees)[0]),
                            (*cells)[1] + static_cast<long>((*degrees)[1]),
                            (*cells)[2] + static_cast<long>((*degrees)[2])},
                           path))
        return std::nullopt;
      if (!c_.attempt(path,
                      [&] { lat = deform::make_bspline_lattice(*frame, *degrees, *cells, knots); }))
        return std::nullopt;
    }
    if (!lattice_points(j, path, lat->points, lat->counts())) return std::nullopt;
    const auto list = deform::problems(*lat, path);
    if (!list.empty()) return c_.add_all(path, list), std::nullopt;
    out = std::move(*lat);
  }
  return out;
}

bool RecipeChecker::lattice_points(const Json& j, const std::string& path, Points3& points,
                                   std::array<int, 3> counts) {
  const bool has_points = j.contains("points"), has_moves = j.contains("moves");
  if (has_points && has_moves) {
    c_.add(path, "give either \"points\" (every control point) or \"moves\" (by index), not both");
    return false;
  }
  if (has_points) {
    const auto p = c_.points(j.at("points"), key_path(path, "points"), 1);
    if (!p) return false;
    if (p->rows() != points.rows()) {
      c_.add(key_path(path, "points"),
             "found " + std::to_string(p->rows()) + " control points, the lattice has " +
                 std::to_string(points.rows()) + " (" + std::to_string(counts[0]) + " x " +
                 std::to_string(counts[1]) + " x " + std::to_string(counts[2]) +
                 "); give all, s-major, or use \"moves\"");
      return false;
    }
    points = *p;
    return true;
  }
  if (!has_moves) return true;  // undisplaced (an identity step)
  return apply_moves(
      j.at("moves"), key_path(path, "moves"), points,
      [&](const Json& m, const std::string& p) { return lattice_row(m, p, counts); },
      std::vector<std::string_view>{"index"});
}

std::optional<deform::Deformation> RecipeChecker::extended_from_generator(const Json& j,
                                                                          const std::string& path) {
  for (const auto& [key, v] : j.items()) {
    (void)v;
    if (key != "kind" && key != "name" && key != "enabled" && key != "generator" && key != "moves")
      c_.add(key_path(path, key), "unknown key \"" + key +
                                      "\" in an extended_lattice step with a generator; "
                                      "the keys are: kind, name, enabled, generator, moves");
  }
  const std::string gp = key_path(path, "generator");
  std::string kind;
  if (!one_of(j.at("generator"), gp, {"cylinder", "prism"}, "a lattice generator", kind))
    return std::nullopt;
  const Json& g = j.at("generator").at(kind);
  const std::string p = key_path(gp, kind);
  deform::ExtendedLattice lat;
  std::function<std::optional<Eigen::Index>(const Json&, const std::string&)> row_of;
  std::vector<std::string_view> index_keys{"index"};
  if (kind == "cylinder") {
    if (!c_.object(g, p,
                   {"origin", "axis", "reference", "radius", "inner_radius", "height", "sectors",
                    "rings", "layers"},
                   "a cylinder lattice {origin, axis, reference, radius, inner_radius, height, "
                   "sectors, rings, layers}"))
      return std::nullopt;
    deform::CylinderSpec spec;
    for (auto [key, target] : {std::pair{"origin", &spec.origin}, std::pair{"axis", &spec.axis},
                               std::pair{"reference", &spec.reference}})
      if (const Json* m = c_.member(g, p, key, false, ""))
        *target = c_.vec3(*m, key_path(p, key)).value_or(*target);
    spec.radius = c_.number_or(g, p, "radius", spec.radius, positive);
    spec.inner_radius = c_.number_or(g, p, "inner_radius", spec.inner_radius, non_negative);
    spec.height = c_.number_or(g, p, "height", spec.height, positive);
    spec.sectors = c_.integer_or(g, p, "sectors", spec.sectors, 3, limit::cylinder_sectors);
    spec.rings = c_.integer_or(g, p, "rings", spec.rings, 1, limit::cylinder_rings);
    spec.layers = c_.integer_or(g, p, "layers", spec.layers, 1, limit::lattice_layers);
    if (!chunks_ok(static_cast<long>(spec.sectors) * spec.rings * spec.layers, p))
      return std::nullopt;
    if (!c_.attempt(p, [&] { lat = deform::make_cylindrical_lattice(spec); })) return std::nullopt;
    row_of = [this, spec](const Json& m, const std::string& mp) -> std::optional<Eigen::Index> {
      const Json* idx = c_.member(m, mp, "index", true, "[radial, angular, axial]");
      if (!idx) return std::nullopt;
      const std::string ip = key_path(mp, "index");
      if (!idx->is_array() || idx->size() != 3) {
        c_.add(ip, "expected [radial, angular, axial], found " + found(*idx));
        return std::nullopt;
      }
      const auto r = c_.integer((*idx)[0], index_path(ip, 0), 0, 3 * spec.rings);
      const auto a = c_.integer((*idx)[1], index_path(ip, 1), -3 * 1024 * 1024, 3 * 1024 * 1024);
      const auto h = c_.integer((*idx)[2], index_path(ip, 2), 0, 3 * spec.layers);
      if (!r || !a || !h) return std::nullopt;
      std::optional<Eigen::Index> row;
      c_.attempt(ip, [&] { row = deform::cylindrical_index(spec, *r, *a, *h); });
      return row;
    };
  } else {
    if (!c_.object(g, p, {"origin", "x_axis", "y_axis", "extrusion", "sections", "layers"},
                   "a prism lattice {origin, x_axis, y_axis, extrusion, sections, layers}"))
      return std::nullopt;
    deform::PrismSpec spec;
    for (auto [key, target] :
         {std::pair{"origin", &spec.origin}, std::pair{"x_axis", &spec.x_axis},
          std::pair{"y_axis", &spec.y_axis}, std::pair{"extrusion", &spec.extrusion}})
      if (const Json* m = c_.member(g, p, key, false, ""))
        *target = c_.vec3(*m, key_path(p, key)).value_or(*target);
    spec.layers = c_.integer_or(g, p, "layers", spec.layers, 1, limit::lattice_layers);
    const Json* s = c_.member(g, p, "sections", true, "two or more sections [[[a, b], ...], ...]");
    if (!s) return std::nullopt;
    const std::string sp = key_path(p, "sections");
    if (!s->is_array() || s->size() < 2) {
      c_.add(sp, "expected two or more sections (arrays of [a, b]), found " + found(*s));
      return std::nullopt;
    }
    // Counted before any section is read: reading 100,000 of them took a minute (issue #18).
    if (!c_.at_most(*s, sp, static_cast<std::size_t>(limit::prism_sections), "sections"))
      return std::nullopt;
    bool ok = true;
    for (std::size_t a = 0; a < s->size(); ++a) {
      const std::string ap = index_path(sp, a);
      if (!(*s)[a].is_array()) {
        c_.add(ap, "expected an array of [a, b] points, found " + found((*s)[a]));
        ok = false;
        continue;
      }
      if (!c_.at_most((*s)[a], ap, 3 * static_cast<std::size_t>(limit::prism_sections - 1) + 1,
                      "section points")) {
        ok = false;
        continue;
      }
      std::vector<Eigen::Vector2d> section;
      for (std::size_t b = 0; b < (*s)[a].size(); ++b) {
        const auto v = c_.vec2((*s)[a][b], index_path(ap, b));
        ok = ok && v.has_value();
        if (v) section.push_back(*v);
      }
      spec.sections.push_back(std::move(section));
    }
    if (!ok || spec.sections.empty()) return std::nullopt;  // each bad section reported above
    const long segments_first =
        std::max(0L, static_cast<long>(spec.sections.front().size()) - 1) / 3;
    if (!chunks_ok(static_cast<long>(spec.sections.size() - 1) * segments_first * spec.layers, p))
      return std::nullopt;
    if (!c_.attempt(p, [&] { lat = deform::make_prismatic_lattice(spec); })) return std::nullopt;
    // A control point by its welded row, or by its index [i, j, k] in the lattice before
    // welding (i across the sections, j along them, k along the extrusion), found through the
    // chunk that holds it: chunk (a, b, c) is chunks[(a * segments + b) * layers + c].
    const auto rows = lat.rest.rows();
    const int gaps = static_cast<int>(spec.sections.size()) - 1;
    const int segments = (static_cast<int>(spec.sections.front().size()) - 1) / 3;
    const int layers = spec.layers;
    const auto chunks = lat.chunks;
    row_of = [this, rows, gaps, segments, layers, chunks](
                 const Json& m, const std::string& mp) -> std::optional<Eigen::Index> {
      if (m.contains("row") == m.contains("index")) {
        c_.add(mp, "give exactly one of \"row\" (a control-point row) and \"index\" ([i, j, k])");
        return std::nullopt;
      }
      if (m.contains("row")) {
        const auto x = c_.integer(m.at("row"), key_path(mp, "row"), 0, static_cast<int>(rows) - 1);
        return x ? std::optional<Eigen::Index>(*x) : std::nullopt;
      }
      const Json& idx = m.at("index");
      const std::string ip = key_path(mp, "index");
      if (!idx.is_array() || idx.size() != 3) {
        c_.add(ip, "expected [i, j, k], found " + found(idx));
        return std::nullopt;
      }
      const auto i = c_.integer(idx[0], index_path(ip, 0), 0, 3 * gaps);
      const auto jj = c_.integer(idx[1], index_path(ip, 1), 0, 3 * segments);
      const auto k = c_.integer(idx[2], index_path(ip, 2), 0, 3 * layers);
      if (!i || !jj || !k) return std::nullopt;
      const int a = std::min(*i / 3, gaps - 1), b = std::min(*jj / 3, segments - 1),
                c = std::min(*k / 3, layers - 1);
      const auto& chunk = chunks[static_cast<std::size_t>((a * segments + b) * layers + c)];
      return chunk[static_cast<std::size_t>(((*i - 3 * a) * 4 + (*jj - 3 * b)) * 4 + (*k - 3 * c))];
    };
    index_keys = {std::string_view("row"), std::string_view("index")};
  }
  if (const Json* m = c_.member(j, path, "moves", false, ""))
    if (!apply_moves(*m, key_path(path, "moves"), lat.points, row_of, index_keys))
      return std::nullopt;
  const auto list = deform::problems(lat, path);
  if (!list.empty()) return c_.add_all(path, list), std::nullopt;
  return deform::Deformation(std::move(lat));
}

double RecipeChecker::bound_within_metre(const std::vector<double>& c) {
  double sum = 0, scale = 1;
  for (double x : c) sum += std::abs(x) * scale, scale *= 1000.0;
  return sum;
}

bool RecipeChecker::within_limits(const deform::Deformation& d, const std::string& path) {
  const std::size_t before = c_.problems.size();
  auto frame = [&](const deform::AxisFrame& f) {
    for (auto [key, v] : {std::pair{"origin", &f.origin}, std::pair{"axis", &f.axis},
                          std::pair{"reference", &f.reference}})
      if (!(v->cwiseAbs().maxCoeff() <= limit::magnitude))
        c_.add(key_path(key_path(path, "frame"), key),
               "a coordinate is beyond ±" + shortest(limit::magnitude) +
                   " mm (recipe limit); give the frame in millimetres within it");
  };
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, deform::Twist>) {
          frame(x.frame);
          const double turns = bound_within_metre(x.angle) / (2 * std::numbers::pi);
          if (!(turns <= limit::twist_turns))
            c_.add(key_path(path, "angle"),
                   "the twist may turn " + shortest(turns * 360) +
                       " degrees within 1 m of its origin (sum of |angle[k]| · 1000^k = " +
                       shortest(turns * 2 * std::numbers::pi) + " rad); at most " +
                       shortest(limit::twist_turns * 360) + " degrees (" +
                       shortest(limit::twist_turns) +
                       " turns) are allowed (recipe limit): the coefficients are radians per mm^k");
        } else if constexpr (std::is_same_v<T, deform::Taper>) {
          frame(x.frame);
          const double scale = bound_within_metre(x.profile);
          if (!(scale <= limit::taper_scale))
            c_.add(key_path(path, "profile"),
                   "the taper may scale by up to " + shortest(scale) +
                       " within 1 m of its origin (sum of |profile[k]| · 1000^k); at most " +
                       shortest(limit::taper_scale) +
                       " is allowed (recipe limit): the coefficients are per mm^k");
        } else if constexpr (std::is_same_v<T, deform::Bend>) {
          frame(x.frame);
          for (auto [key, v] : {std::pair{"y_min", x.y_min}, std::pair{"y_max", x.y_max},
                                std::pair{"center", x.center}})
            if (!(std::abs(v) <= limit::magnitude))
              c_.add(key_path(path, key), shortest(v) + " mm is beyond ±" +
                                              shortest(limit::magnitude) + " mm (recipe limit)");
          const double turns = std::abs(x.rate) * (x.y_max - x.y_min) / (2 * std::numbers::pi);
          if (!(std::abs(x.rate) <= limit::bend_rate))
            c_.add(key_path(path, "rate"),
                   shortest(x.rate) + " rad/mm is beyond ±" + shortest(limit::bend_rate) +
                       " rad/mm (recipe limit: a radius of curvature of at least 1 mm)");
          else if (!(turns <= limit::bend_turns))
            c_.add(key_path(path, "rate"),
                   "the bend turns " + shortest(turns * 360) +
                       " degrees over its region (rate · (y_max − y_min)); at most " +
                       shortest(limit::bend_turns * 360) + " degrees are allowed (recipe limit)");
        } else if constexpr (std::is_same_v<T, deform::ExtendedLattice>) {
          if (static_cast<long>(x.chunks.size()) > limit::chunks)
            c_.add(key_path(path, "chunks"), std::to_string(x.chunks.size()) + " chunks; at most " +
                                                 std::to_string(limit::chunks) +
                                                 " are allowed (recipe limit)");
          for (auto [key, m] : {std::pair{"rest", &x.rest}, std::pair{"points", &x.points}})
            if (m->size() > 0 && !(m->cwiseAbs().maxCoeff() <= limit::magnitude))
              c_.add(key_path(path, key), "a coordinate is beyond ±" + shortest(limit::magnitude) +
                                              " mm (recipe limit)");
        }
      },
      d);
  return c_.problems.size() == before;
}

std::optional<deform::Deformation> RecipeChecker::schema_step(const Json& j,
                                                              const std::string& path) {
  auto step = internal::read_step(c_, j, path);
  if (!step) return std::nullopt;
  const std::string label = internal::step_label(path, *step);
  const auto list =
      std::visit([&](const auto& d) { return problems(d, label); }, step->deformation);
  if (!list.empty()) {
    c_.add_all(label, list);
    return std::nullopt;
  }
  return std::move(step->deformation);
}

void RecipeChecker::stack(const std::string& name, const Json& j, const std::string& path) {
  StackDef def{name, path, {}};
  if (!j.is_array()) {
    c_.add(path, "expected an array of deformation steps, found " + found(j));
    return;
  }
  const std::size_t before = c_.problems.size();
  if (!c_.at_most(j, path, limit::steps, "steps")) return;
  // One reader per step kind, by its name in the schema (docs/recipe.md § deformations); each
  // sets the step and says whether it was valid.
  auto set = [](StepDef& step, auto read) {
    if (!read) return false;
    step.step = std::move(*read);
    return true;
  };
  auto schema = [&](const Json& s, const std::string& p, StepDef& step) {
    auto d = schema_step(s, p);
    return d && within_limits(*d, p) && set(step, std::move(d));
  };
  using Reader = std::function<bool(const Json&, const std::string&, StepDef&)>;
  const std::vector<std::pair<std::string, Reader>> readers = {
      {"bezier_lattice", [&](const Json& s, const std::string& p,
                             StepDef& st) { return set(st, lattice(s, p, false, {"keep"})); }},
      {"bspline_lattice", [&](const Json& s, const std::string& p,
                              StepDef& st) { return set(st, lattice(s, p, true, {"keep"})); }},
      {"extended_lattice",  // from a generator (a primitive's lattice), or given point by point
       [&](const Json& s, const std::string& p, StepDef& st) {
         return s.contains("generator") ? set(st, extended_from_generator(s, p)) : schema(s, p, st);
       }},
      {"taper", schema},
      {"twist", schema},
      {"bend", schema},
      {"style",
       [&](const Json& s, const std::string& p, StepDef& st) { return set(st, style(s, p)); }},
      {"direct_manipulation",
       [&](const Json& s, const std::string& p, StepDef& st) { return set(st, direct(s, p)); }}};
  std::vector<std::string> kinds;
  for (const auto& reader : readers) kinds.push_back(reader.first);
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string p = index_path(path, i);
    const Json& s = j[i];
    if (!s.is_object()) {
      c_.add(p, "expected a step {\"kind\": ..., ...}, found " + found(s));
      continue;
    }
    StepDef step{p, "", "", true, deform::Deformation{}};
    const Json* k = c_.member(s, p, "kind", true, "the step's kind, e.g. \"bezier_lattice\"");
    if (!k) continue;
    const auto kind = c_.choice(*k, key_path(p, "kind"), kinds);
    if (!kind) continue;
    step.kind = k->get<std::string>();
    if (const Json* n = c_.member(s, p, "name", false, ""))
      step.name = c_.string(*n, key_path(p, "name")).value_or("");
    step.enabled = c_.boolean_or(s, p, "enabled", true);
    // "keep" belongs to lattice steps (the other kinds' readers refuse it as an unknown key).
    const bool lattice_kind = step.kind == "bezier_lattice" || step.kind == "bspline_lattice";
    if (const Json* keep = lattice_kind && s.contains("keep") ? &s.at("keep") : nullptr)
      step.keep = kept_properties(*keep, key_path(p, "keep"));
    const bool ok = readers[static_cast<std::size_t>(*kind)].second(s, p, step);
    if (ok) def.steps.push_back(std::move(step));
  }
  if (c_.problems.size() == before) data.stacks.push_back(std::move(def));
}

std::vector<std::string> RecipeChecker::kept_properties(const Json& j, const std::string& path) {
  static const std::vector<std::string> known = {"volume", "centroid", "area"};
  std::vector<std::string> out;
  if (!j.is_array() || j.empty()) {
    c_.add(path, "expected a list of properties the move keeps, such as [\"volume\"], found " +
                     found(j) + "; give some of " + join(known));
    return out;
  }
  for (std::size_t i = 0; i < j.size(); ++i) {
    const auto k = c_.choice(j[i], index_path(path, i), known);
    if (!k) continue;
    const std::string& name = known[static_cast<std::size_t>(*k)];
    if (std::find(out.begin(), out.end(), name) != out.end())
      c_.add(index_path(path, i), "\"" + name + "\" is listed twice; list it once");
    else
      out.push_back(name);
  }
  return out;
}

std::optional<StyleDef> RecipeChecker::style(const Json& j, const std::string& p) {
  if (!c_.object(j, p,
                 {"kind", "name", "enabled", "target", "bound", "mode", "lambda", "relaxation",
                  "smoothing", "key_points_per_row", "boundary_rows", "relative_tolerance",
                  "curve_tolerance", "max_refinements", "max_key_point_rounds", "continuity",
                  "net_convergence", "net_convergence_best_effort", "accept_out_of_tolerance"},
                 "a style step", {renamed_relative}))
    return std::nullopt;
  StyleDef d;
  const std::size_t before = c_.problems.size();
  if (const Json* t = c_.member(j, p, "target", true, "the target curve's name"))
    d.target = curve_ref(*t, key_path(p, "target")).value_or("");
  if (const Json* b = c_.member(j, p, "bound", false, ""))
    d.bound = curve_ref(*b, key_path(p, "bound")).value_or("");
  // A bound curve given inline is known now: an open one is reported here, not at run time
  // (the rule of deform::influence_factors: ends within 1e-7 of the curve's size).
  if (!d.bound.empty()) {
    const auto cd = std::find_if(data.curves.begin(), data.curves.end(),
                                 [&](const CurveDef& x) { return x.name == d.bound; });
    if (cd != data.curves.end() && cd->curve) {
      const surface::Points3& pts = cd->curve->points;
      const double size = (pts.colwise().maxCoeff() - pts.colwise().minCoeff()).norm();
      const auto [t0, t1] = cd->curve->basis.domain();
      const double gap =
          (surface::evaluate(*cd->curve, t1) - surface::evaluate(*cd->curve, t0)).norm();
      if (gap > 1e-7 * size) {
        char apart[32];
        std::snprintf(apart, sizeof apart, "%.4g", gap);
        c_.add(key_path(p, "bound"),
               "the bound curve \"" + d.bound + "\" is open: its ends are " + apart +
                   " mm apart; a bound curve must be closed (make its last control point "
                   "equal its first)");
      }
    }
  }
  auto& o = d.options;
  if (const Json* m = c_.member(j, p, "mode", false, ""))
    if (const auto k = c_.choice(*m, key_path(p, "mode"), {"paper", "exact"}))
      o.mode = *k == 0 ? deform::StyleMode::Paper : deform::StyleMode::Exact;
  o.lambda = c_.number_or(j, p, "lambda", o.lambda, Range{0, 1});
  o.relaxation = c_.boolean_or(j, p, "relaxation", o.relaxation);
  o.smoothing = c_.boolean_or(j, p, "smoothing", o.smoothing);
  o.key_points_per_row = c_.integer_or(j, p, "key_points_per_row", o.key_points_per_row, 1, 64);
  o.boundary_rows = c_.integer_or(j, p, "boundary_rows", o.boundary_rows, 0, 4);
  o.relative_tolerance = c_.number_or(j, p, "relative_tolerance", o.relative_tolerance, positive);
  o.curve_tolerance = c_.number_or(j, p, "curve_tolerance", o.curve_tolerance, positive);
  o.max_refinements = c_.integer_or(j, p, "max_refinements", o.max_refinements, 0, 10);
  if (const Json* m = c_.member(j, p, "continuity", false, ""))
    if (const auto k = c_.choice(*m, key_path(p, "continuity"), {"G1", "G2"}))
      o.continuity = *k == 0 ? deform::BoundContinuity::G1 : deform::BoundContinuity::G2;
  o.net_convergence = c_.number_or(j, p, "net_convergence", o.net_convergence, Range{0, 0.5});
  o.net_convergence_best_effort =
      c_.boolean_or(j, p, "net_convergence_best_effort", o.net_convergence_best_effort);
  if (o.net_convergence_best_effort && !(o.net_convergence > 0))
    c_.add(key_path(p, "net_convergence_best_effort"),
           "best effort needs a \"net_convergence\" to work towards (e.g. 0.05): set it, or "
           "drop \"net_convergence_best_effort\"");
  o.max_key_point_rounds =
      c_.integer_or(j, p, "max_key_point_rounds", o.max_key_point_rounds, 0, 16);
  d.accept_out_of_tolerance =
      c_.boolean_or(j, p, "accept_out_of_tolerance", d.accept_out_of_tolerance);
  c_.attempt(p, [&] { o.validate(); });
  if (c_.problems.size() != before) return std::nullopt;
  return d;
}

std::optional<DirectDef> RecipeChecker::direct(const Json& j, const std::string& p) {
  if (!c_.object(j, p,
                 {"kind", "name", "enabled", "lattice", "moves", "locked", "tied",
                  "relative_tolerance", "accept_out_of_tolerance"},
                 "a direct_manipulation step", {renamed_relative}))
    return std::nullopt;
  const std::size_t before = c_.problems.size();
  DirectDef d{deform::BezierLattice{}, {}, {}, false};
  d.accept_out_of_tolerance = c_.boolean_or(j, p, "accept_out_of_tolerance", false);
  const Json* lj =
      c_.member(j, p, "lattice", true, "a bezier_lattice or bspline_lattice object with \"kind\"");
  std::array<int, 3> counts{0, 0, 0};
  if (lj) {
    const std::string lp = key_path(p, "lattice");
    const Json* k = lj->is_object() ? c_.member(*lj, lp, "kind", true,
                                                "\"bezier_lattice\" or \"bspline_lattice\"")
                                    : nullptr;
    if (!lj->is_object()) c_.add(lp, "expected a lattice object, found " + found(*lj));
    const auto kind = k ? c_.choice(*k, key_path(lp, "kind"), {"bezier_lattice", "bspline_lattice"})
                        : std::nullopt;
    if (kind) {
      if (auto lat = lattice(*lj, lp, k->get<std::string>() == "bspline_lattice", {})) {
        if (auto* b = std::get_if<deform::BezierLattice>(&*lat)) {
          counts = b->counts();
          d.lattice = *b;
        } else {
          const auto& s = std::get<deform::BSplineLattice>(*lat);
          counts = s.counts();
          d.lattice = s;
        }
      }
    }
  }
  const Json* mj = c_.member(j, p, "moves", true,
                             "[{\"point\": [x,y,z] | \"surface_point\": [u, v], \"to\": [x,y,z]}]");
  if (mj) {
    const std::string mp = key_path(p, "moves");
    if (!mj->is_array() || mj->empty()) {
      c_.add(mp, "expected a non-empty array of moves, found " + found(*mj));
    } else if (c_.at_most(*mj, mp, limit::moves, "moves")) {
      for (std::size_t i = 0; i < mj->size(); ++i) {
        const std::string ip = index_path(mp, i);
        const Json& m = (*mj)[i];
        if (!c_.object(m, ip, {"point", "surface_point", "to"},
                       "a move {point | surface_point, to}"))
          continue;
        DirectMove move;
        const bool has_point = m.contains("point"), has_uv = m.contains("surface_point");
        if (has_point == has_uv) {
          c_.add(ip, "give exactly one of \"point\" ([x, y, z]) and \"surface_point\" ([u, v])");
          continue;
        }
        if (has_point) {
          if (const auto v = c_.vec3(m.at("point"), key_path(ip, "point"))) move.point = *v;
        } else if (const auto uv = c_.vec2(m.at("surface_point"), key_path(ip, "surface_point"))) {
          move.on_surface = true;
          move.point = Eigen::Vector3d((*uv)[0], (*uv)[1], 0.0);
        }
        if (const Json* t = c_.member(m, ip, "to", true, "the target [x, y, z]"))
          if (const auto v = c_.vec3(*t, key_path(ip, "to"))) move.to = *v;
        d.moves.push_back(move);
      }
    }
  }
  const Eigen::Index rows = static_cast<Eigen::Index>(counts[0]) * counts[1] * counts[2];
  auto index_row = [&](const Json& v, const std::string& ip) -> std::optional<Eigen::Index> {
    if (!v.is_array() || v.size() != 3) {
      c_.add(ip, "expected [i, j, k], found " + found(v));
      return std::nullopt;
    }
    Eigen::Index row = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto x = c_.integer(v[k], index_path(ip, k), 0, std::max(counts[k] - 1, 0));
      if (!x) return std::nullopt;
      row = row * counts[k] + *x;
    }
    return row;
  };
  if (const Json* lk = c_.member(j, p, "locked", false, "")) {
    const std::string lp = key_path(p, "locked");
    if (!lk->is_array()) {
      c_.add(lp, "expected an array of [i, j, k], found " + found(*lk));
    } else if (rows > 0) {
      d.options.locked.assign(static_cast<std::size_t>(rows), false);
      for (std::size_t i = 0; i < lk->size(); ++i)
        if (const auto r = index_row((*lk)[i], index_path(lp, i)))
          d.options.locked[static_cast<std::size_t>(*r)] = true;
    }
  }
  if (const Json* tj = c_.member(j, p, "tied", false, "")) {
    const std::string tp = key_path(p, "tied");
    if (!tj->is_array()) {
      c_.add(tp, "expected an array of groups [[i, j, k], ...], found " + found(*tj));
    } else {
      for (std::size_t g = 0; g < tj->size(); ++g) {
        const std::string gp = index_path(tp, g);
        if (!(*tj)[g].is_array() || (*tj)[g].size() < 2) {
          c_.add(gp, "expected a group of at least 2 indices [i, j, k], found " + found((*tj)[g]));
          continue;
        }
        std::vector<Eigen::Index> group;
        for (std::size_t i = 0; i < (*tj)[g].size(); ++i)
          if (const auto r = index_row((*tj)[g][i], index_path(gp, i))) group.push_back(*r);
        d.options.tied.push_back(std::move(group));
      }
    }
  }
  d.options.relative_tolerance =
      c_.number_or(j, p, "relative_tolerance", d.options.relative_tolerance, positive);
  c_.attempt(p, [&] { d.options.validate(); });
  if (c_.problems.size() != before) return std::nullopt;
  return d;
}

}  // namespace clay::recipe::check_detail
