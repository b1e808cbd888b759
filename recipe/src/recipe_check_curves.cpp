// The recipe checker: strokes, curves and sketches (recipe_checker.hpp).
#include "recipe_checker.hpp"

namespace clay::recipe::check_detail {

std::optional<sketch::SketchPlane> RecipeChecker::plane(const Json& j, const std::string& path) {
  if (!c_.object(j, path, {"origin", "x_axis", "y_axis", "normal"},
                 "a plane {origin, x_axis, y_axis} or {origin, normal}"))
    return std::nullopt;
  if (j.contains("normal")) {
    // By origin and normal (sketch::make_plane): the x axis is the given x_axis made orthogonal
    // to the normal, or the world axis least aligned with it.
    if (j.contains("y_axis")) {
      c_.add(key_path(path, "y_axis"),
             "a plane given by its normal takes no y_axis (it is normal x x_axis); give "
             "{origin, normal} or {origin, x_axis, y_axis}");
      return std::nullopt;
    }
    Eigen::Vector3d origin, normal, x_axis;
    if (!c_.vec3_members(j, path, {{"origin", &origin}, {"normal", &normal}})) return std::nullopt;
    std::optional<Eigen::Vector3d> x;
    if (j.contains("x_axis")) {
      if (!c_.vec3_members(j, path, {{"x_axis", &x_axis}})) return std::nullopt;
      x = x_axis;
    }
    std::optional<sketch::SketchPlane> out;
    c_.attempt(path, [&] { out = sketch::make_plane(origin, normal, x); });
    return out;
  }
  sketch::SketchPlane pl;
  if (!c_.vec3_members(j, path,
                       {{"origin", &pl.origin}, {"x_axis", &pl.x_axis}, {"y_axis", &pl.y_axis}}))
    return std::nullopt;
  return c_.checked(pl, path, sketch::problems(pl, path));
}

void RecipeChecker::stroke(const std::string& name, const Json& j, const std::string& path) {
  // Defined even when broken: one problem, not a cascade. A stroke split at its corners defines
  // its pieces NAME.1 .. NAME.N instead of NAME (declared_pieces reads "pieces" as declare() did).
  const int declared = declared_pieces(j);
  if (declared == 0) names_.curves.push_back(name);
  for (int k = 1; k <= declared; ++k) names_.curves.push_back(piece_name(name, k));
  if (!c_.object(j, path,
                 {"points", "plane", "tolerance_mm", "degree", "fairness", "closing_ratio",
                  "pieces", "corner_angle", "accept_out_of_tolerance"},
                 "a stroke {points, plane, tolerance_mm, degree, fairness, closing_ratio, pieces, "
                 "corner_angle}",
                 {renamed_mm}))
    return;
  StrokeDef s{name, path, {}, {}};
  const Json* pts = c_.member(j, path, "points", true, "the drawn points [[x, y, z], ...]");
  const auto p =
      pts ? c_.points(*pts, key_path(path, "points"), 2, limit::stroke_points) : std::nullopt;
  if (const Json* pl = c_.member(j, path, "plane", false, ""))
    s.stroke.plane = plane(*pl, key_path(path, "plane"));
  s.fit.tolerance_mm = c_.number_or(j, path, "tolerance_mm", s.fit.tolerance_mm, tolerance_range);
  s.fit.degree = c_.integer_or(j, path, "degree", s.fit.degree, 2, 9);
  s.fit.fairness = c_.number_or(j, path, "fairness", s.fit.fairness, non_negative);
  s.fit.closing_ratio = c_.number_or(j, path, "closing_ratio", s.fit.closing_ratio, Range{0, 0.5});
  s.pieces = c_.integer_or(j, path, "pieces", 0, 1, limit::stroke_pieces);
  // Without "pieces", one curve per stroke, never split (docs/recipe.md); with it, split where
  // the stroke turns by more than corner_angle (fit_stroke's default, 50 degrees).
  s.fit.corner_angle = 180.0;
  if (j.contains("corner_angle")) {
    if (s.pieces == 0)
      c_.add(key_path(path, "corner_angle"),
             "\"corner_angle\" splits a stroke at its corners, so it needs \"pieces\" (how many "
             "curves the stroke gives, named " +
                 piece_name(name, 1) + " .. " + piece_name(name, 2) + " ...); add it or drop this");
    s.fit.corner_angle = c_.number_or(j, path, "corner_angle", 50.0, Range{0, 180, true, false});
  } else if (s.pieces > 0) {
    s.fit.corner_angle = sketch::FitOptions{}.corner_angle;
  }
  s.accept_out_of_tolerance = c_.boolean_or(j, path, "accept_out_of_tolerance", false);
  if (!p) return;
  s.stroke.points = *p;
  const auto list = sketch::problems(s.stroke, path);
  if (!list.empty()) return c_.add_all(path, list);
  if (c_.attempt(path, [&] { s.fit.validate(); })) data.strokes.push_back(std::move(s));
}

int declared_pieces(const Json& stroke) {
  if (!stroke.is_object()) return 0;
  const auto it = stroke.find("pieces");
  if (it == stroke.end() || !it->is_number_integer()) return 0;
  const auto n = it->get<long long>();
  return n >= 1 && n <= limit::stroke_pieces ? static_cast<int>(n) : 0;
}

std::optional<surface::BSplineCurve> RecipeChecker::inline_curve(const Json& j,
                                                                 const std::string& path) {
  if (!c_.object(j, path, {"degree", "knots", "points", "weights"},
                 "a B-spline curve {degree, knots, points, weights}"))
    return std::nullopt;
  const Json* d = c_.member(j, path, "degree", true, "the degree, e.g. 3");
  const Json* k = c_.member(j, path, "knots", true, "the knot vector (count + degree + 1 numbers)");
  const Json* p = c_.member(j, path, "points", true, "the control points [[x, y, z], ...]");
  const auto degree =
      d ? c_.integer(*d, key_path(path, "degree"), 1, surface::max_kernel_degree) : std::nullopt;
  const auto knots =
      k ? c_.numbers(*k, key_path(path, "knots"), 2, limit::curve_points + knot_slack)
        : std::nullopt;
  const auto points = p ? c_.points(*p, key_path(path, "points"), 2) : std::nullopt;
  std::optional<std::vector<double>> weights;
  if (const Json* w = c_.member(j, path, "weights", false, ""))
    if (!(weights =
              c_.numbers(*w, key_path(path, "weights"), 2, limit::curve_points, weight_range)))
      return std::nullopt;
  if (!degree || !knots || !points) return std::nullopt;
  surface::BSplineCurve curve;
  curve.basis = {*degree, *knots};
  curve.points = *points;
  curve.weights = weights ? Eigen::Map<const Eigen::VectorXd>(
                                weights->data(), static_cast<Eigen::Index>(weights->size()))
                                .eval()
                          : Eigen::VectorXd::Ones(points->rows()).eval();
  return c_.checked(curve, path, surface::problems(curve, path));
}

void RecipeChecker::curve(const std::string& name, const Json& j, const std::string& path) {
  CurveDef def;
  def.name = name;
  def.path = path;
  const bool ok = one_of(j, path,
                         {"bspline", "line", "arc", "arc_through", "arc_radius", "polyline",
                          "reversed", "mirror", "iso", "boundary", "project", "offset"},
                         "a curve", def.kind);
  const std::string p = key_path(path, def.kind);
  if (ok) {
    const Json& v = j.at(def.kind);
    if (def.kind == "bspline") {
      def.curve = inline_curve(v, p);
    } else if (def.kind == "line") {
      if (c_.object(v, p, {"from", "to"}, "a line {from, to}")) {
        const Json* a = c_.member(v, p, "from", true, "[x, y, z]");
        const Json* b = c_.member(v, p, "to", true, "[x, y, z]");
        const auto from = a ? c_.vec3(*a, key_path(p, "from")) : std::nullopt;
        const auto to = b ? c_.vec3(*b, key_path(p, "to")) : std::nullopt;
        if (from && to) {
          Points3 pts(2, 3);
          pts.row(0) = from->transpose();
          pts.row(1) = to->transpose();
          def.curve = polyline_curve(pts, p);
        }
      }
    } else if (def.kind == "polyline") {
      if (c_.object(v, p, {"points"}, "a polyline {points}")) {
        const Json* a = c_.member(v, p, "points", true, "[[x, y, z], ...]");
        if (const auto pts = a ? c_.points(*a, key_path(p, "points"), 2) : std::nullopt)
          def.curve = polyline_curve(*pts, p);
      }
    } else if (def.kind == "arc") {
      def.curve = arc(v, p);
    } else if (def.kind == "arc_through") {
      def.curve = arc_through(v, p);
    } else if (def.kind == "arc_radius") {
      def.curve = arc_radius(v, p);
    } else if (def.kind == "mirror") {
      if (c_.object(v, p, {"curve", "plane"}, "a mirror {curve, plane: {origin, normal}}")) {
        std::optional<std::string> source;
        if (const Json* m = c_.member(v, p, "curve", true, "the name of a curve"))
          source = curve_ref(*m, key_path(p, "curve"));
        const auto plane = mirror_plane(v, p);
        if (source && plane) {
          def.mirror_of = *source;
          def.plane = *plane;
        }
      }
    } else if (def.kind == "iso" || def.kind == "boundary" || def.kind == "project" ||
               def.kind == "offset") {
      from_surface(v, p, def);
    } else {  // reversed
      if (const auto n = curve_ref(v, p)) def.reversed_of = *n;
    }
  }
  names_.curves.push_back(name);
  if (def.curve || !def.reversed_of.empty() || !def.mirror_of.empty() || def.from_surface())
    data.curves.push_back(std::move(def));
}

void RecipeChecker::from_surface(const Json& v, const std::string& p, CurveDef& def) {
  const bool ok =
      def.kind == "iso" ? c_.object(v, p, {"surface", "u", "v"}, "an iso-curve {surface, u or v}")
      : def.kind == "boundary" ? c_.object(v, p, {"surface", "edge"}, "a boundary {surface, edge}")
      : def.kind == "project"
          ? c_.object(v, p, {"curve", "surface", "tolerance_mm"},
                      "a projection {curve, surface, tolerance_mm}", {renamed_mm})
          : c_.object(v, p, {"curve", "surface", "distance", "tolerance_mm"},
                      "an offset {curve, surface, distance, tolerance_mm}", {renamed_mm});
  if (!ok) return;
  std::optional<std::string> surface;
  // The surface may come later in the document: the run builds it first (the checker reports
  // a cycle, a surface that needs this curve).
  if (const Json* m = c_.member(v, p, "surface", true, "the name of a surface")) {
    const std::string sp = key_path(p, "surface");
    if (const auto n = c_.string(*m, sp)) {
      if (names_.surfaces_declared.count(*n))
        surface = n;
      else
        c_.add(sp, "no surface named \"" + *n + "\"; " +
                       listing(std::vector<std::string>(names_.surfaces_declared.begin(),
                                                        names_.surfaces_declared.end())));
    }
  }
  std::optional<std::string> source;
  if (def.kind == "project" || def.kind == "offset") {
    if (const Json* m = c_.member(v, p, "curve", true, "the name of a curve"))
      source = curve_ref(*m, key_path(p, "curve"));
    def.fit.tolerance_mm = c_.number_or(v, p, "tolerance_mm", 1e-3, tolerance_range);
    if (!source) return;
    def.source = *source;
  }
  if (def.kind == "offset") {
    const Json* d = c_.member(v, p, "distance", true, "the offset in mm along the normal");
    const auto distance = d ? c_.number(*d, key_path(p, "distance"), any) : std::nullopt;
    if (!distance) return;
    def.distance = *distance;
  }
  if (def.kind == "iso") {
    const bool u = v.contains("u"), w = v.contains("v");
    if (u == w) {
      c_.add(p, u ? "gives both \"u\" and \"v\"; an iso-curve fixes one: give \"u\" or \"v\""
                  : "needs \"u\" or \"v\": the fixed parameter, a fraction of the surface's "
                    "domain in [0, 1] (e.g. \"v\": 0.5)");
      return;
    }
    def.fixed_u = u;
    const auto at = c_.number(v.at(u ? "u" : "v"), key_path(p, u ? "u" : "v"), Range{0, 1});
    if (!at) return;
    def.at = *at;
  }
  if (def.kind == "boundary") {
    const Json* e = c_.member(v, p, "edge", true, "\"u0\", \"u1\", \"v0\" or \"v1\"");
    const auto k = e ? c_.choice(*e, key_path(p, "edge"), {"u0", "u1", "v0", "v1"}) : std::nullopt;
    if (!k) return;
    def.fixed_u = *k < 2;
    def.at = (*k % 2 == 1) ? 1.0 : 0.0;
  }
  if (surface) def.surface = *surface;
}

std::optional<MirrorPlane> RecipeChecker::mirror_plane(const Json& v, const std::string& p) {
  const Json* m = c_.member(v, p, "plane", true, "a plane {origin, normal}");
  if (!m) return std::nullopt;
  const std::string pp = key_path(p, "plane");
  if (!c_.object(*m, pp, {"origin", "normal"}, "a mirror plane {origin, normal}"))
    return std::nullopt;
  const Json* o = c_.member(*m, pp, "origin", true, "[x, y, z]");
  const Json* n = c_.member(*m, pp, "normal", true, "[x, y, z]");
  const auto origin = o ? c_.vec3(*o, key_path(pp, "origin")) : std::nullopt;
  const auto normal = n ? c_.vec3(*n, key_path(pp, "normal")) : std::nullopt;
  if (!origin || !normal) return std::nullopt;
  if (!(normal->norm() > 0)) {
    c_.add(key_path(pp, "normal"), "is [0, 0, 0]; give the plane's normal, of any length");
    return std::nullopt;
  }
  return MirrorPlane{*origin, normal->normalized()};
}

std::optional<surface::BSplineCurve> RecipeChecker::arc_through(const Json& v,
                                                                const std::string& p) {
  if (!c_.object(v, p, {"start", "through", "end"},
                 "an arc through three points {start, through, end}"))
    return std::nullopt;
  const auto pts = points3(v, p, {"start", "through", "end"});
  if (!pts[0] || !pts[1] || !pts[2]) return std::nullopt;
  std::optional<surface::BSplineCurve> out;
  c_.attempt(p, [&] { out = surface::arc_through(*pts[0], *pts[1], *pts[2]); });
  return out;
}

std::optional<surface::BSplineCurve> RecipeChecker::arc_radius(const Json& v,
                                                               const std::string& p) {
  if (!c_.object(v, p, {"start", "end", "radius", "normal", "side"},
                 "an arc {start, end, radius, normal, side}"))
    return std::nullopt;
  const auto vs = points3(v, p, {"start", "end", "normal"});
  const Json* r = c_.member(v, p, "radius", true, "the radius in mm");
  const auto radius = r ? c_.number(*r, key_path(p, "radius"), positive) : std::nullopt;
  std::optional<std::size_t> side;
  if (const Json* s = c_.member(v, p, "side", true, "\"left\" or \"right\""))
    side = c_.choice(*s, key_path(p, "side"), {"left", "right"});
  if (!vs[0] || !vs[1] || !vs[2] || !radius || !side) return std::nullopt;
  const Eigen::Vector3d a = *vs[0], b = *vs[1];
  const Eigen::Vector3d chord = b - a;
  // In the plane through the chord normal to `normal` (its part across the chord): `left` is
  // normal x chord, seen from the normal's tip.
  const double half = 0.5 * chord.norm();
  if (!(half > 0)) {
    c_.add(key_path(p, "end"), "is the start point; an arc needs two different ends");
    return std::nullopt;
  }
  if (!(vs[2]->norm() > 0)) {
    c_.add(key_path(p, "normal"), "is [0, 0, 0]; give the normal of the arc's plane");
    return std::nullopt;
  }
  const Eigen::Vector3d n = *vs[2] - vs[2]->dot(chord) / chord.squaredNorm() * chord;
  if (!(n.norm() > 1e-9 * vs[2]->norm())) {
    c_.add(key_path(p, "normal"),
           "lies along the chord from start to end; give the normal of "
           "the arc's plane");
    return std::nullopt;
  }
  if (!(*radius >= half)) {
    c_.add(key_path(p, "radius"), "is " + shortest(*radius) +
                                      " mm, less than half the chord from start to end (" +
                                      shortest(half) + " mm); give at least that");
    return std::nullopt;
  }
  // The minor arc, bulging to `side` of the chord: its middle point is the chord's middle moved
  // sideways by the sagitta r - sqrt(r^2 - (c/2)^2).
  const Eigen::Vector3d left = n.normalized().cross(chord).normalized();
  const double sagitta = *radius - std::sqrt(std::max(0.0, *radius * *radius - half * half));
  const Eigen::Vector3d middle = 0.5 * (a + b) + (*side == 0 ? 1.0 : -1.0) * sagitta * left;
  std::optional<surface::BSplineCurve> out;
  c_.attempt(p, [&] { out = surface::arc_through(a, middle, b); });
  return out;
}

std::optional<surface::BSplineCurve> RecipeChecker::polyline_curve(const Points3& pts,
                                                                   const std::string& path) {
  const auto n = pts.rows();
  for (Eigen::Index i = 1; i < n; ++i)
    if (pts.row(i) == pts.row(i - 1)) {
      c_.add(path, "points " + std::to_string(i - 1) + " and " + std::to_string(i) +
                       " are the same; a polyline needs distinct consecutive points");
      return std::nullopt;
    }
  surface::BSplineCurve c;
  c.basis.degree = 1;
  c.basis.knots.resize(static_cast<std::size_t>(n) + 2);
  c.basis.knots.front() = 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
    c.basis.knots[static_cast<std::size_t>(i) + 1] =
        static_cast<double>(i) / static_cast<double>(n - 1);
  c.basis.knots.back() = 1.0;
  c.points = pts;
  c.weights = Eigen::VectorXd::Ones(n);
  return c;
}

std::array<std::optional<Eigen::Vector3d>, 3> RecipeChecker::points3(
    const Json& v, const std::string& p, const std::array<const char*, 3>& keys) {
  std::array<std::optional<Eigen::Vector3d>, 3> out;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const Json* m = c_.member(v, p, keys[k], true, "[x, y, z]");
    out[k] = m ? c_.vec3(*m, key_path(p, keys[k])) : std::nullopt;
  }
  return out;
}

std::optional<surface::BSplineCurve> RecipeChecker::arc(const Json& v, const std::string& p) {
  if (!c_.object(v, p, {"center", "x_axis", "y_axis", "radius", "start", "end"},
                 "an arc {center, x_axis, y_axis, radius, start, end}"))
    return std::nullopt;
  const auto vs = points3(v, p, {"center", "x_axis", "y_axis"});
  const Json* r = c_.member(v, p, "radius", true, "the radius in mm");
  const Json* s = c_.member(v, p, "start", true, "the start angle in degrees");
  const Json* e = c_.member(v, p, "end", true, "the end angle in degrees");
  const auto radius = r ? c_.number(*r, key_path(p, "radius"), positive) : std::nullopt;
  const Range angle{-limit::arc_degrees, limit::arc_degrees};
  const auto start = s ? c_.number(*s, key_path(p, "start"), angle) : std::nullopt;
  const auto end = e ? c_.number(*e, key_path(p, "end"), angle) : std::nullopt;
  if (!vs[0] || !vs[1] || !vs[2] || !radius || !start || !end) return std::nullopt;
  if (!(*end > *start && *end - *start <= 360.0)) {
    c_.add(p, "end − start = " + shortest(*end - *start) + " degrees; give 0 < end − start <= 360");
    return std::nullopt;
  }
  std::optional<surface::BSplineCurve> out;
  c_.attempt(p, [&] {
    out = surface::circular_arc(*vs[0], *vs[1], *vs[2], *radius, *start * degrees_to_radians,
                                *end * degrees_to_radians);
  });
  return out;
}

bool RecipeChecker::one_of(const Json& j, const std::string& path,
                           std::initializer_list<std::string_view> kinds, std::string_view what,
                           std::string& kind) {
  std::vector<std::string> names(kinds.begin(), kinds.end());
  if (!j.is_object()) {
    c_.add(path, "expected " + std::string(what) + " as an object with one of " + join(names) +
                     ", found " + found(j));
    return false;
  }
  std::vector<std::string> present;
  for (const auto& [key, value] : j.items()) {
    (void)value;
    if (std::find(names.begin(), names.end(), key) != names.end())
      present.push_back(key);
    else
      c_.add(key_path(path, key), "unknown key \"" + key + "\" in " + std::string(what) +
                                      "; give exactly one of " + join(names));
  }
  if (present.size() != 1) {
    if (present.empty())
      c_.add(path, std::string(what) + " needs exactly one of " + join(names));
    else
      c_.add(path, std::string(what) + " has " + join(present) + "; give exactly one");
    return false;
  }
  kind = present.front();
  return true;
}

void RecipeChecker::sketch(const std::string& name, const Json& j, const std::string& path) {
  SketchDef def{name, path, {}, {}, {}, {}, {}, {}};
  bool deferred = false;
  const auto register_entities = [&] {
    const auto e = j.is_object() ? j.find("entities") : j.end();
    if (j.is_object() && e != j.end() && e->is_object())
      for (const auto& [entity, v] : e->items()) {
        (void)v;
        names_.curves.push_back(name + "." + entity);
      }
  };
  if (!c_.object(j, path, {"plane", "points", "entities", "constraints", "residual_tolerance"},
                 "a sketch {plane, points, entities, constraints, residual_tolerance}",
                 {renamed_residual})) {
    return;
  }
  const std::size_t before = c_.problems.size();
  sketch::PlaneId plane_id;
  if (const Json* pl = c_.member(j, path, "plane", false, ""))
    if (const auto p = plane(*pl, key_path(path, "plane"))) plane_id = def.sketch.add_plane(*p);
  std::map<std::string, sketch::PointId> points;
  std::map<std::string, sketch::EntityId> entities;
  if (const Json* pts = c_.member(j, path, "points", true, "an object of NAME: position")) {
    const std::string pp = key_path(path, "points");
    if (pts->is_object() && pts->size() > limit::sketch_items) {
      c_.add(pp, std::to_string(pts->size()) + " points; at most " +
                     std::to_string(limit::sketch_items) +
                     " are allowed in a sketch (recipe limit)");
    } else if (pts->is_object()) {
      for (const auto& item : pts->items()) {  // no structured binding: Clang 14 cannot capture one
        const std::string& pname = item.key();
        const Json& pv = item.value();
        const std::string p = key_path(pp, pname);
        if (!plane_id.free()) {
          if (const auto ab = c_.vec2(pv, p))
            c_.attempt(p, [&] { points[pname] = def.sketch.add_point(plane_id, *ab); });
        } else if (const auto x = c_.vec3(pv, p)) {
          c_.attempt(p, [&] { points[pname] = def.sketch.add_point(*x); });
        }
      }
    } else {
      c_.add(pp, "expected an object of NAME: position, found " + found(*pts));
    }
  }
  // Messages of the sketch and the solver name points and entities as the recipe does.
  def.sketch.point_names.resize(def.sketch.points.size());
  for (const auto& [pname, id] : points)
    def.sketch.point_names[static_cast<std::size_t>(id.index)] = pname;
  auto name_next_entity = [&](const std::string& ename) {
    def.sketch.entity_names.resize(def.sketch.entities.size() + 1);
    def.sketch.entity_names.back() = ename;
  };
  // A point or entity declared in this sketch but not built has its own problem reported at
  // its declaration; references to it stay quiet rather than adding a follow-on "no point".
  // An entity left unbuilt because it refers to such a point or entity is quiet too.
  const std::string points_path = key_path(path, "points"),
                    entities_path = key_path(path, "entities");
  std::set<std::string> unbuilt_by_reference;
  std::string building;  // the entity being built, while entities are read
  auto failed = [&](const Json* section, const std::string& section_path,
                    const std::string& declared) {
    if (!section || !section->is_object() || !section->contains(declared)) return false;
    const std::string at = key_path(section_path, declared);
    const bool quiet =
        (section_path == entities_path && unbuilt_by_reference.count(declared) > 0) ||
        std::any_of(c_.problems.begin(), c_.problems.end(), [&](const internal::JsonProblem& q) {
          return q.path == at || q.path.rfind(at + ".", 0) == 0 || q.path.rfind(at + "[", 0) == 0;
        });
    if (quiet && !building.empty()) unbuilt_by_reference.insert(building);
    return quiet;
  };
  const Json* declared_points = j.contains("points") ? &j.at("points") : nullptr;
  const Json* declared_entities = j.contains("entities") ? &j.at("entities") : nullptr;
  auto point_ref = [&](const Json& v, const std::string& p) -> std::optional<sketch::PointId> {
    const auto n = c_.string(v, p);
    if (!n) return std::nullopt;
    const auto it = points.find(*n);
    if (it != points.end()) return it->second;
    if (failed(declared_points, points_path, *n)) return std::nullopt;
    // "E.start" / "E.end": an end point of a line, arc or B-spline curve entity (a curve's
    // first or last control point: the curve is clamped).
    if (const auto dot = n->rfind('.'); dot != std::string::npos) {
      const std::string e = n->substr(0, dot), end = n->substr(dot + 1);
      const auto ei = entities.find(e);
      if (ei == entities.end() && (end == "start" || end == "end") &&
          failed(declared_entities, entities_path, e))
        return std::nullopt;
      if (ei != entities.end() && (end == "start" || end == "end")) {
        const bool start = end == "start";
        const auto& entity = def.sketch.entities[static_cast<std::size_t>(ei->second.index)];
        if (const auto* l = std::get_if<sketch::Line>(&entity)) return start ? l->start : l->end;
        if (const auto* a = std::get_if<sketch::Arc>(&entity)) return start ? a->start : a->end;
        if (const auto* c = std::get_if<sketch::Curve>(&entity))
          return start ? c->control_points.front() : c->control_points.back();
        c_.add(p, "\"" + e + "\" is a circle, which has no end points; refer to its center point");
        return std::nullopt;
      }
    }
    std::vector<std::string> known;
    for (const auto& [k, id] : points) known.push_back(k);
    c_.add(p, "no point named \"" + *n +
                  "\" in this sketch (an entity's end is \"ENTITY.start\" or "
                  "\"ENTITY.end\"); " +
                  listing(known));
    return std::nullopt;
  };
  auto entity_ref = [&](const Json& v, const std::string& p) -> std::optional<sketch::EntityId> {
    const auto n = c_.string(v, p);
    if (!n) return std::nullopt;
    const auto it = entities.find(*n);
    if (it != entities.end()) return it->second;
    if (failed(declared_entities, entities_path, *n)) return std::nullopt;
    std::vector<std::string> known;
    for (const auto& [k, id] : entities) known.push_back(k);
    c_.add(p, "no entity named \"" + *n + "\" in this sketch; " + listing(known));
    return std::nullopt;
  };
  if (const Json* ents =
          c_.member(j, path, "entities", true, "an object of NAME: {line|circle|arc}")) {
    const std::string ep = key_path(path, "entities");
    if (ents->is_object() && ents->size() > limit::sketch_items) {
      c_.add(ep, std::to_string(ents->size()) + " entities; at most " +
                     std::to_string(limit::sketch_items) +
                     " are allowed in a sketch (recipe limit)");
    } else if (ents->is_object()) {
      for (const auto& item :
           ents->items()) {  // no structured binding: Clang 14 cannot capture one
        const std::string& ename = item.key();
        const Json& ev = item.value();
        const std::string p = key_path(ep, ename);
        building = ename;
        std::string kind;
        if (!one_of(ev, p, {"line", "circle", "arc", "bspline", "curve"}, "a sketch entity", kind))
          continue;
        const Json& v = ev.at(kind);
        const std::string kp = key_path(p, kind);
        if (kind == "bspline" || kind == "curve") {
          // A clamped B-spline whose control points become sketch points (the solver moves
          // them): inline, or a curve of the "curves" section given inline there.
          std::optional<surface::BSplineCurve> curve;
          if (kind == "bspline") {
            curve = inline_curve(v, kp);
          } else if (const auto source = curve_ref(v, kp)) {
            def.uses.push_back(*source);
            const auto cd = std::find_if(data.curves.begin(), data.curves.end(),
                                         [&](const CurveDef& d) { return d.name == *source; });
            if (runtime_curve) {
              if (const surface::BSplineCurve* c = runtime_curve(*source)) curve = *c;
            } else if (cd != data.curves.end() && cd->curve) {
              curve = cd->curve;
            } else {
              // A stroke's fit or a reversed curve: known when the recipe runs. Checked here
              // with a stand-in (a straight cubic in the plane), built again then.
              surface::Points3 stand_in(4, 3);
              for (int k = 0; k < 4; ++k)
                stand_in.row(k) =
                    (plane_id.free()
                         ? Eigen::Vector3d(k, 0, 0)
                         : sketch::to_world(
                               def.sketch.planes[static_cast<std::size_t>(plane_id.index)],
                               Eigen::Vector2d(k, 0)))
                        .transpose();
              surface::BSplineCurve c;
              c.basis.degree = 3;
              c.basis.knots.assign({0, 0, 0, 0, 1, 1, 1, 1});
              c.points = stand_in;
              c.weights = Eigen::VectorXd::Ones(4);
              curve = std::move(c);
              deferred = true;
            }
          }
          if (curve) {
            name_next_entity(ename);
            c_.attempt(kp, [&] { entities[ename] = def.sketch.add_curve(*curve, plane_id); });
          }
          continue;
        }
        if (kind == "line") {
          if (!v.is_array() || v.size() != 2) {
            c_.add(kp, "expected [\"P\", \"Q\"] (two point names), found " + found(v));
            continue;
          }
          const auto a = point_ref(v[0], index_path(kp, 0));
          const auto b = point_ref(v[1], index_path(kp, 1));
          if (a && b) {
            name_next_entity(ename);
            c_.attempt(kp, [&] { entities[ename] = def.sketch.add_line(*a, *b); });
          }
        } else if (kind == "circle") {
          if (!c_.object(v, kp, {"center", "radius"}, "a circle {center, radius}")) continue;
          const Json* cj = c_.member(v, kp, "center", true, "a point name");
          const Json* rj = c_.member(v, kp, "radius", true, "the radius in mm");
          const auto center = cj ? point_ref(*cj, key_path(kp, "center")) : std::nullopt;
          const auto r = rj ? c_.number(*rj, key_path(kp, "radius"), positive) : std::nullopt;
          if (plane_id.free()) {
            c_.add(kp, "a circle needs the sketch's plane; give the sketch a \"plane\"");
            continue;
          }
          if (center && r) {
            name_next_entity(ename);
            c_.attempt(kp, [&] { entities[ename] = def.sketch.add_circle(*center, *r, plane_id); });
          }
        } else {
          if (!c_.object(v, kp, {"center", "start", "end"}, "an arc {center, start, end}"))
            continue;
          std::array<std::optional<sketch::PointId>, 3> ids;
          int k = 0;
          for (const char* key : {"center", "start", "end"}) {
            const Json* m = c_.member(v, kp, key, true, "a point name");
            ids[static_cast<std::size_t>(k++)] =
                m ? point_ref(*m, key_path(kp, key)) : std::nullopt;
          }
          if (plane_id.free()) {
            c_.add(kp, "an arc needs the sketch's plane; give the sketch a \"plane\"");
            continue;
          }
          if (ids[0] && ids[1] && ids[2]) {
            name_next_entity(ename);
            c_.attempt(kp, [&] {
              entities[ename] = def.sketch.add_arc(*ids[0], *ids[1], *ids[2], plane_id);
            });
          }
        }
      }
    } else {
      c_.add(ep, "expected an object of NAME: {line|circle|arc}, found " + found(*ents));
    }
    building.clear();
  }
  if (const Json* cons = c_.member(j, path, "constraints", false, "")) {
    const std::string cp = key_path(path, "constraints");
    if (!cons->is_array()) {
      c_.add(cp, "expected an array of {\"type\": ..., ...}, found " + found(*cons));
    } else if (c_.at_most(*cons, cp, limit::sketch_items, "constraints")) {
      for (std::size_t i = 0; i < cons->size(); ++i)
        if (auto con = constraint((*cons)[i], index_path(cp, i), point_ref, entity_ref)) {
          con->label = index_path(cp, i);  // the solver's messages name it by its path
          def.constraints.push_back(*con);
        }
    }
  }
  def.solve.residual_tolerance = c_.number_or(
      j, path, "residual_tolerance", def.solve.residual_tolerance, Range{0, 1e-3, true, false});
  register_entities();
  if (c_.problems.size() != before) return;
  for (const auto& [ename, id] : entities) def.entities.emplace_back(name + "." + ename, id);
  // keep the entities in document order (the map sorted them)
  const Json& ents = j.at("entities");
  std::vector<std::pair<std::string, sketch::EntityId>> ordered;
  for (const auto& [ename, ev] : ents.items()) {
    (void)ev;
    ordered.emplace_back(name + "." + ename, entities.at(ename));
  }
  def.entities = std::move(ordered);
  if (deferred) def.deferred_json = j.dump();
  data.sketches.push_back(std::move(def));
}

}  // namespace clay::recipe::check_detail
