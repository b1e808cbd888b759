// Loft (skinning): sections made compatible and interpolated across v (The NURBS Book §10.3).
#include <clay/surface/skin.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/tolerance.hpp>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <clay/surface/detail/builder_tools.hpp>
#include "section_interpolation.hpp"

namespace clay::surface {
namespace {

using detail::interpolate_sections;
using detail::model_size;
using detail::normalized;
using detail::polygon_length;

std::string num(double x) { return detail::short_number(x); }

std::string name(const char* what, size_t k) {
  return std::string(what) + " #" + std::to_string(k);
}

// ---- Loft ----

struct PreparedLoft {
  std::vector<BSplineCurve> compatible;  // oriented, compatible, on [0, 1]
  CompatibleCurves merged;               // what merging the slivers of the knot union did
  std::vector<bool> reversed;
  std::vector<double> v;
  int degree = 1;
};

std::vector<double> section_parameters(const std::vector<BSplineCurve>& c,
                                       LoftParametrization kind) {
  const size_t count = c.size();
  std::vector<double> v(count, 0.0);
  v.back() = 1.0;
  if (kind == LoftParametrization::Uniform) {
    for (size_t k = 1; k + 1 < count; ++k)
      v[k] = static_cast<double>(k) / static_cast<double>(count - 1);
    return v;
  }
  // Per column i of control points: cumulative (chord or centripetal) length across the sections,
  // normalized; then averaged over the columns (The NURBS Book eq. 10.8). Columns that do not move
  // (e.g. a shared apex) carry no information and are skipped.
  const Eigen::Index n = c.front().points.rows();
  std::vector<double> sum(count, 0.0);
  int used = 0;
  std::vector<double> step(count, 0.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    double total = 0;
    for (size_t k = 1; k < count; ++k) {
      const double d = (c[k].points.row(i) - c[k - 1].points.row(i)).norm();
      step[k] = kind == LoftParametrization::Centripetal ? std::sqrt(d) : d;
      total += step[k];
    }
    if (!(total > 0.0)) continue;
    ++used;
    double run = 0;
    for (size_t k = 1; k + 1 < count; ++k) {
      run += step[k];
      sum[k] += run / total;
    }
  }
  for (size_t k = 1; k + 1 < count; ++k) v[k] = sum[k] / used;
  return v;
}

PreparedLoft prepare_loft(const std::vector<BSplineCurve>& sections, const LoftOptions& options) {
  options.validate();
  if (sections.size() < 2)
    throw Error(ErrorCategory::InvalidArgument, "loft: needs at least 2 sections, got " +
                                                    std::to_string(sections.size()) +
                                                    "; give two or more section curves");
  std::vector<const BSplineCurve*> all;
  for (size_t k = 0; k < sections.size(); ++k) {
    validate(sections[k], name("loft section", k));
    all.push_back(&sections[k]);
  }
  const double size = model_size(all);
  const double tol = options.relative_tolerance * size;
  for (size_t k = 0; k < sections.size(); ++k) {
    const double length = polygon_length(sections[k]);
    if (!(length > tol))
      throw Error(ErrorCategory::InvalidGeometry,
                  "loft: section #" + std::to_string(k) +
                      " is degenerate: its control polygon is " + num(length) +
                      " mm long (tolerance " + num(tol) +
                      " mm); a loft needs curves, not points: remove it or give a curve");
  }
  for (size_t k = 0; k < sections.size(); ++k)
    detail::reject_self_intersection(
        sections[k], tol, "loft: section #" + std::to_string(k),
        "the lofted surface would intersect itself there: move the section's control points so "
        "that it does not cross or touch itself");

  PreparedLoft out;
  std::vector<BSplineCurve> oriented;
  for (const BSplineCurve& s : sections) oriented.push_back(normalized(s));
  out.reversed.assign(sections.size(), false);
  const std::vector<double> ts = linspace(0.0, 1.0, 65);
  for (size_t k = 1; k < oriented.size(); ++k) {
    double same = 0, against = 0, largest = 0;
    for (double t : ts) {
      const Eigen::Vector3d a = evaluate(oriented[k], t);
      const double d = (a - evaluate(oriented[k - 1], t)).norm();
      same += d * d;
      largest = std::max(largest, d);
      against += (a - evaluate(oriented[k - 1], 1.0 - t)).squaredNorm();
    }
    if (against < same) {
      if (!options.auto_orient)
        throw Error(ErrorCategory::InvalidGeometry,
                    "loft: section #" + std::to_string(k) + " runs against section #" +
                        std::to_string(k - 1) +
                        " (it lies nearer to that section run backwards); reverse it or set "
                        "LoftOptions::auto_orient");
      oriented[k] = reversed(oriented[k]);
      out.reversed[k] = true;
      largest = 0;
      for (double t : ts)
        largest =
            std::max(largest, (evaluate(oriented[k], t) - evaluate(oriented[k - 1], t)).norm());
    }
    if (!(largest > tol))
      throw Error(ErrorCategory::InvalidGeometry,
                  "loft: sections #" + std::to_string(k - 1) + " and #" + std::to_string(k) +
                      " coincide (largest distance " + num(largest) + " mm, tolerance " + num(tol) +
                      " mm); remove one of them");
  }
  std::vector<std::string> names;
  for (size_t k = 0; k < sections.size(); ++k)
    names.push_back("loft section #" + std::to_string(k));
  out.merged = make_compatible(
      oriented, KnotMergeOptions{options.min_span_ratio, options.merge_tolerance * size}, names);
  out.compatible = out.merged.curves;
  out.v = section_parameters(out.compatible, options.parametrization);
  for (size_t k = 1; k < out.v.size(); ++k)
    if (!(out.v[k] > out.v[k - 1]))
      throw Error(
          ErrorCategory::InvalidGeometry,
          "loft: sections #" + std::to_string(k - 1) + " and #" + std::to_string(k) +
              " get the same parameter (their control points coincide); remove one of them");
  out.degree = std::min(options.degree, static_cast<int>(sections.size()) - 1);
  return out;
}

}  // namespace

std::vector<std::string> LoftOptions::problems() const {
  std::vector<std::string> out;
  if (degree < 1 || degree > max_kernel_degree)
    out.push_back("LoftOptions::degree is " + std::to_string(degree) + "; it must be in [1, " +
                  std::to_string(max_kernel_degree) + "]");
  if (!(relative_tolerance > 0.0 && relative_tolerance <= 1e-2))
    out.push_back("LoftOptions::relative_tolerance is " + num(relative_tolerance) +
                  "; it must be in (0, 1e-2]");
  detail::merge_option_problems("LoftOptions", min_span_ratio, merge_tolerance, out);
  return out;
}

void LoftOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::vector<double> loft_parameters(const std::vector<BSplineCurve>& sections,
                                    const LoftOptions& options) {
  return prepare_loft(sections, options).v;
}

BuiltSurface loft(const std::vector<BSplineCurve>& sections, const LoftOptions& options) {
  const PreparedLoft prepared = prepare_loft(sections, options);
  BuiltSurface built;
  built.surface = interpolate_sections(prepared.compatible, prepared.v, prepared.degree);

  // Exactness check: S(u, v_k) against the input section k at the same (normalized) parameter,
  // or, where merging a sliver reparametrized the section, at the parameter it was moved from.
  const int spans = static_cast<int>(breakpoints(built.surface.u).size()) - 1;
  const std::vector<double> us = linspace(0.0, 1.0, std::max(65, 8 * spans + 1));
  const Points3 grid = evaluate_grid(built.surface, us, prepared.v);
  const size_t count = sections.size();
  double worst = 0;
  for (size_t k = 0; k < count; ++k) {
    const auto [a, b] = sections[k].basis.domain();
    for (size_t i = 0; i < us.size(); ++i) {
      const double f = input_parameter(prepared.merged, static_cast<int>(k), us[i]);
      const double t = prepared.reversed[k] ? b - f * (b - a) : a + f * (b - a);
      const Eigen::Vector3d expected = evaluate(sections[k], std::clamp(t, a, b));
      worst = std::max(
          worst,
          (grid.row(static_cast<Eigen::Index>(i * count + k)).transpose() - expected).norm());
    }
  }
  std::string method = "loft of " + std::to_string(count) + " sections";
  std::string turned;
  for (size_t k = 0; k < count; ++k)
    if (prepared.reversed[k]) turned += (turned.empty() ? "" : ", #") + std::to_string(k);
  if (!turned.empty()) method += " (reversed: #" + turned + ")";
  const std::string merges = detail::merge_note(prepared.merged, "section");
  if (!merges.empty()) method += " (" + merges + ")";
  built.report = describe(built.surface, method);
  built.report.exact = prepared.merged.merges.empty();
  built.report.max_deviation_mm = worst;
  built.report.samples = static_cast<int>(us.size() * count);
  return built;
}

}  // namespace clay::surface
