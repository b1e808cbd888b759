// The recipe checker: surfaces (recipe_checker.hpp).
#include "recipe_checker.hpp"

#include <system_error>

namespace clay::recipe::check_detail {

void RecipeChecker::surface(const std::string& name, const Json& j, const std::string& path) {
  SurfaceDef def{name, path, "", surface::BSplineSurface{}};
  const std::size_t before = c_.problems.size();
  if (one_of(j, path,
             {"bspline", "fill", "skin", "sweep", "revolve", "superellipsoid", "supertoroid",
              "import", "deform", "mirror", "rebuild"},
             "a surface", def.kind)) {
    const Json& v = j.at(def.kind);
    const std::string p = key_path(path, def.kind);
    if (def.kind == "bspline") {
      if (auto s = inline_surface(v, p)) def.build = std::move(*s);
    } else if (def.kind == "fill") {
      FillDef f;
      if (c_.object(
              v, p,
              {"curves", "style", "join", "gap_tolerance", "min_span_ratio", "merge_tolerance"},
              "a fill {curves, style, join, gap_tolerance, min_span_ratio, merge_tolerance}")) {
        f.curves = curve_refs(v, p, "curves", 2, 4);
        if (const Json* s = c_.member(v, p, "style", false, ""))
          if (const auto k = c_.choice(*s, key_path(p, "style"), {"stretch", "coons", "curved"}))
            f.options.style = static_cast<surface::FillStyle>(*k);
        if (const Json* s = c_.member(v, p, "join", false, ""))
          if (const auto k = c_.choice(*s, key_path(p, "join"), {"exact", "snap"}))
            f.snap = *k == 1;
        // Snapping moves the strokes' ends, so how far is stated, not defaulted.
        if (f.snap && !v.contains("gap_tolerance"))
          c_.add(key_path(p, "join"),
                 "\"join\": \"snap\" needs \"gap_tolerance\": the largest gap between curve ends "
                 "to close, in mm (e.g. \"gap_tolerance\": 2)");
        f.options.gap_tolerance =
            c_.number_or(v, p, "gap_tolerance", f.options.gap_tolerance, positive);
        f.options.min_span_ratio = c_.number_or(v, p, "min_span_ratio", f.options.min_span_ratio,
                                                Range{0, 0.5, false, true});
        f.options.merge_tolerance = c_.number_or(v, p, "merge_tolerance", f.options.merge_tolerance,
                                                 Range{0, 1e-2, true, false});
        c_.attempt(p, [&] { f.options.validate(); });
      }
      def.build = std::move(f);
    } else if (def.kind == "skin") {
      SkinDef s;
      if (c_.object(
              v, p, {"sections", "degree", "parametrization", "min_span_ratio", "merge_tolerance"},
              "a skin {sections, degree, parametrization, min_span_ratio, merge_tolerance}")) {
        s.sections = curve_refs(v, p, "sections", 2, limit::entries);
        s.options.degree =
            c_.integer_or(v, p, "degree", s.options.degree, 1, surface::max_exchange_degree);
        if (const Json* m = c_.member(v, p, "parametrization", false, ""))
          if (const auto k = c_.choice(*m, key_path(p, "parametrization"),
                                       {"chord_length", "centripetal", "uniform"}))
            s.options.parametrization = static_cast<surface::LoftParametrization>(*k);
        s.options.min_span_ratio = c_.number_or(v, p, "min_span_ratio", s.options.min_span_ratio,
                                                Range{0, 0.5, false, true});
        s.options.merge_tolerance = c_.number_or(v, p, "merge_tolerance", s.options.merge_tolerance,
                                                 Range{0, 1e-2, true, false});
        c_.attempt(p, [&] { s.options.validate(); });
      }
      def.build = std::move(s);
    } else if (def.kind == "sweep") {
      SweepDef s;
      if (c_.object(v, p, {"profile", "path", "twist_degrees", "relative_tolerance"},
                    "a sweep {profile, path, twist_degrees, relative_tolerance}",
                    {renamed_relative})) {
        if (const Json* m = c_.member(v, p, "profile", true, "a curve name"))
          s.profile = curve_ref(*m, key_path(p, "profile")).value_or("");
        if (const Json* m = c_.member(v, p, "path", true, "a curve name"))
          s.path = curve_ref(*m, key_path(p, "path")).value_or("");
        s.options.twist_degrees =
            c_.number_or(v, p, "twist_degrees", s.options.twist_degrees,
                         Range{-limit::sweep_twist_degrees, limit::sweep_twist_degrees});
        s.options.relative_tolerance =
            c_.number_or(v, p, "relative_tolerance", s.options.relative_tolerance, tolerance_range);
        c_.attempt(p, [&] { s.options.validate(); });
      }
      def.build = std::move(s);
    } else if (def.kind == "revolve") {
      RevolveDef r;
      if (c_.object(v, p, {"profile", "axis", "angle"}, "a revolve {profile, axis, angle}")) {
        if (const Json* m = c_.member(v, p, "profile", true, "a curve name"))
          r.profile = curve_ref(*m, key_path(p, "profile")).value_or("");
        if (const Json* a =
                c_.member(v, p, "axis", true, "{\"point\": [x, y, z], \"direction\": [x, y, z]}")) {
          const std::string ap = key_path(p, "axis");
          if (c_.object(*a, ap, {"point", "direction"}, "an axis {point, direction}")) {
            if (const Json* m = c_.member(*a, ap, "point", true, "[x, y, z]"))
              r.axis.point = c_.vec3(*m, key_path(ap, "point")).value_or(r.axis.point);
            if (const Json* m = c_.member(*a, ap, "direction", true, "[x, y, z]"))
              r.axis.direction = c_.vec3(*m, key_path(ap, "direction")).value_or(r.axis.direction);
            if (r.axis.direction.norm() == 0.0)
              c_.add(key_path(ap, "direction"),
                     "the axis direction is zero; give a non-zero vector");
          }
        }
        r.angle = c_.number_or(v, p, "angle", r.angle, Range{0, 360, true, false});
      }
      def.build = std::move(r);
    } else if (def.kind == "superellipsoid" || def.kind == "supertoroid") {
      const bool toroid = def.kind == "supertoroid";
      std::initializer_list<std::string_view> keys_e{"radii", "e1", "e2", "tolerance_mm", "degree"};
      std::initializer_list<std::string_view> keys_t{"radii",        "e1",     "e2",
                                                     "tolerance_mm", "degree", "hole"};
      if (c_.object(v, p, toroid ? keys_t : keys_e, toroid ? "a supertoroid" : "a superellipsoid",
                    {renamed_mm})) {
        surface::SuperquadricOptions o;
        Eigen::Vector3d radii = Eigen::Vector3d::Ones();
        if (const Json* m = c_.member(v, p, "radii", false, "")) {
          radii = c_.vec3(*m, key_path(p, "radii")).value_or(radii);
          if (!(radii.minCoeff() > 0))
            c_.add(key_path(p, "radii"), "every radius must be > 0 (mm)");
        }
        const double e1 = c_.number_or(v, p, "e1", 1.0, Range{0, 10, true, false});
        const double e2 = c_.number_or(v, p, "e2", 1.0, Range{0, 10, true, false});
        o.tolerance_mm = c_.number_or(v, p, "tolerance_mm", o.tolerance_mm, tolerance_range);
        o.degree = c_.integer_or(v, p, "degree", o.degree, 2, 7);
        if (toroid) {
          SupertoroidDef d{{radii, 2.0, e1, e2}, o};
          d.shape.hole = c_.number_or(v, p, "hole", 2.0, Range{1, inf, true, false});
          def.build = d;
        } else {
          def.build = SuperellipsoidDef{{radii, e1, e2}, o};
        }
      }
    } else if (def.kind == "import") {
      ImportDef d;
      if (c_.object(v, p, {"file", "index"}, "an import {file, index}")) {
        if (const Json* f =
                c_.member(v, p, "file", true, "the path of a .step/.stp/.igs/.iges file"))
          if (const auto file = exchange_file(*f, key_path(p, "file"))) d.file = *file;
        d.index = c_.integer_or(v, p, "index", 0, 0, 1000000);
      }
      def.build = d;
    } else if (def.kind == "mirror") {
      MirrorDef d;
      if (c_.object(v, p, {"surface", "plane"}, "a mirror {surface, plane: {origin, normal}}")) {
        if (const Json* m = c_.member(v, p, "surface", true, "the name of an earlier surface"))
          d.surface = surface_ref(*m, key_path(p, "surface")).value_or("");
        if (const auto plane = mirror_plane(v, p)) d.plane = *plane;
      }
      def.build = d;
    } else if (def.kind == "rebuild") {
      RebuildDef d;
      if (c_.object(v, p, {"surface", "count_u", "count_v", "degree", "relative_tolerance"},
                    "a rebuild {surface, count_u, count_v, degree, relative_tolerance}",
                    {renamed_relative})) {
        if (const Json* m = c_.member(v, p, "surface", true, "the name of an earlier surface"))
          d.surface = surface_ref(*m, key_path(p, "surface")).value_or("");
        d.degree = c_.integer_or(v, p, "degree", 3, 1, surface::max_exchange_degree);
        // Both counts give a fixed uniform net; neither, an adaptive net that grows only where
        // the tolerance needs it (a "rebuild to tolerance").
        for (auto [key, count] :
             {std::pair{"count_u", &d.count_u}, std::pair{"count_v", &d.count_v}})
          if (const Json* m = c_.member(v, p, key, false, ""))
            *count = c_.integer(*m, key_path(p, key), d.degree + 1, 1000).value_or(0);
        if (v.contains("count_u") != v.contains("count_v"))
          c_.add(key_path(p, v.contains("count_u") ? "count_v" : "count_u"),
                 "give both \"count_u\" and \"count_v\" for a fixed net, or neither for a net "
                 "that grows to the tolerance");
        d.relative_tolerance =
            c_.number_or(v, p, "relative_tolerance", d.relative_tolerance, Range{1e-9, 1e-1});
      }
      def.build = d;
    } else {  // deform
      DeformDef d;
      d.composition = data.composition;
      if (c_.object(v, p, {"surface", "deformation", "composition"},
                    "a deform {surface, deformation, composition}")) {
        if (const Json* m = c_.member(v, p, "surface", true, "the name of an earlier surface"))
          d.surface = surface_ref(*m, key_path(p, "surface")).value_or("");
        if (const Json* m = c_.member(v, p, "deformation", true, "the name of a deformation stack"))
          if (const auto s = c_.string(*m, key_path(p, "deformation"))) {
            if (Names::has(names_.stacks, *s))
              d.deformation = *s;
            else
              c_.add(key_path(p, "deformation"),
                     "no deformation stack named \"" + *s + "\"; " + listing(names_.stacks));
          }
        if (const Json* m = c_.member(v, p, "composition", false, ""))
          d.composition = composition(*m, key_path(p, "composition"), d.composition);
        if (!d.composition.refit) exact_composable(d.deformation, key_path(p, "deformation"));
      }
      def.build = d;
    }
  }
  names_.surfaces.push_back(name);
  if (c_.problems.size() == before) data.surfaces.push_back(std::move(def));
}

void RecipeChecker::exact_composable(const std::string& stack_name, const std::string& path) {
  for (const auto& stack : data.stacks) {
    if (stack.name != stack_name) continue;
    for (const auto& step : stack.steps) {
      const auto* d = std::get_if<deform::Deformation>(&step.step);
      if (!step.enabled || !d) continue;
      if (std::holds_alternative<deform::Twist>(*d) || std::holds_alternative<deform::Bend>(*d) ||
          std::holds_alternative<deform::ExtendedLattice>(*d))
        c_.add(
            path,
            step.path + " is a " + step.kind + ", which cannot be composed exactly (only " +
                "Bézier and B-spline lattices and tapers can); give this surface or the recipe " +
                "\"composition\": {\"mode\": \"refit\", \"relative_tolerance\": 1e-4}");
    }
  }
}

std::optional<surface::BSplineSurface> RecipeChecker::inline_surface(const Json& j,
                                                                     const std::string& path) {
  if (!c_.object(j, path, {"degrees", "knots_u", "knots_v", "points", "weights"},
                 "a B-spline surface {degrees, knots_u, knots_v, points, weights}"))
    return std::nullopt;
  const Json* d = c_.member(j, path, "degrees", true, "[p, q]");
  const Json* ku = c_.member(j, path, "knots_u", true, "the u knot vector");
  const Json* kv = c_.member(j, path, "knots_v", true, "the v knot vector");
  const Json* p = c_.member(j, path, "points", true,
                            "count_u x count_v control points, (i, j) at row i * count_v + j");
  std::optional<std::pair<int, int>> degrees;
  if (d) {
    if (!d->is_array() || d->size() != 2) {
      c_.add(key_path(path, "degrees"), "expected [p, q], found " + found(*d));
    } else {
      const auto a = c_.integer((*d)[0], index_path(key_path(path, "degrees"), 0), 1,
                                surface::max_kernel_degree);
      const auto b = c_.integer((*d)[1], index_path(key_path(path, "degrees"), 1), 1,
                                surface::max_kernel_degree);
      if (a && b) degrees = std::pair{*a, *b};
    }
  }
  const auto knots_u = ku ? c_.numbers(*ku, key_path(path, "knots_u"), 2) : std::nullopt;
  const auto knots_v = kv ? c_.numbers(*kv, key_path(path, "knots_v"), 2) : std::nullopt;
  const auto points =
      p ? c_.points(*p, key_path(path, "points"), 4, limit::surface_points) : std::nullopt;
  std::optional<std::vector<double>> weights;
  if (const Json* w = c_.member(j, path, "weights", false, ""))
    if (!(weights =
              c_.numbers(*w, key_path(path, "weights"), 4, limit::surface_points, weight_range)))
      return std::nullopt;
  if (!degrees || !knots_u || !knots_v || !points) return std::nullopt;
  surface::BSplineSurface s;
  s.u = {degrees->first, *knots_u};
  s.v = {degrees->second, *knots_v};
  s.points = *points;
  s.weights = weights ? Eigen::Map<const Eigen::VectorXd>(
                            weights->data(), static_cast<Eigen::Index>(weights->size()))
                            .eval()
                      : Eigen::VectorXd::Ones(points->rows()).eval();
  return c_.checked(s, path, surface::problems(s, path));
}

}  // namespace clay::recipe::check_detail
