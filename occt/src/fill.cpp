// Filling through OpenCASCADE: exact 2/3/4-sided fills (GeomFill_BSplineCurves) and the N-sided
// plate (BRepOffsetAPI_MakeFilling). We arrange, orient, join and make the curves compatible
// ourselves, so OpenCASCADE's own arrangement (tolerance 1e-7, fixed) and knot merging have
// nothing left to do, and we know which curve became which edge.
#include <clay/occt/fill.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>
#include <clay/surface/self_intersection.hpp>
#include <clay/surface/skin.hpp>
#include <clay/tolerance.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepOffsetAPI_MakeFilling.hxx>
#include <BRep_Tool.hxx>
#include <GeomAbs_Shape.hxx>
#include <GeomConvert.hxx>
#include <GeomFill_BSplineCurves.hxx>
#include <GeomFill_Coons.hxx>
#include <GeomFill_Filling.hxx>
#include <Geom_Surface.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pnt.hxx>

#include <clay/surface/detail/builder_tools.hpp>
#include "convert.hpp"

namespace clay::surface {
namespace {

using detail::normalized;

std::string num(double x) { return detail::short_number(x); }
std::string curve_name(size_t k) { return "curve #" + std::to_string(k); }

gp_Pnt pnt(const Eigen::Vector3d& p) { return gp_Pnt(p.x(), p.y(), p.z()); }

Eigen::Vector3d first_point(const BSplineCurve& c) { return c.points.row(0).transpose(); }
Eigen::Vector3d last_point(const BSplineCurve& c) {
  return c.points.row(c.points.rows() - 1).transpose();
}

/// Validates every curve and rejects degenerate ones (control polygon ~0 long).
void check_curves(const std::vector<BSplineCurve>& curves, const char* what, double size) {
  for (size_t k = 0; k < curves.size(); ++k) {
    validate(curves[k], std::string(what) + " #" + std::to_string(k));
    const double length = detail::polygon_length(curves[k]);
    if (!(length > 1e-12 * size))
      throw Error(ErrorCategory::InvalidGeometry, std::string(what) + " #" + std::to_string(k) +
                                                      " is degenerate: its control polygon is " +
                                                      num(length) +
                                                      " mm long; give a curve, not a point");
  }
}

double size_of(const std::vector<BSplineCurve>& a, const std::vector<BSplineCurve>& b = {}) {
  std::vector<const BSplineCurve*> all;
  for (const BSplineCurve& c : a) all.push_back(&c);
  for (const BSplineCurve& c : b) all.push_back(&c);
  return detail::model_size(all);
}

/// One curve of a closed loop: which input curve, whether it runs backwards, and its clamped,
/// [0, 1] copy in loop direction (corners joined).
struct LoopCurve {
  size_t input = 0;
  bool reversed = false;
  BSplineCurve curve;
  double alpha = 1;  // Möbius reparametrization applied (see unit_end_weights), 1 for none
};

/// A closed loop of the curves (clamped, on [0, 1]) chained from curve #0: each next curve is the
/// unused one with an end nearest to the current end. Throws InvalidGeometry naming every gap
/// above `tolerance`. Joins each corner at the midpoint of its two ends; `joined` gets the largest
/// distance a curve end moved.
std::vector<LoopCurve> closed_loop(const std::vector<BSplineCurve>& curves, double tolerance,
                                   const char* builder, double& joined) {
  const size_t n = curves.size();
  std::vector<BSplineCurve> clamped;
  for (const BSplineCurve& c : curves) clamped.push_back(normalized(c));
  std::vector<LoopCurve> loop;
  std::vector<bool> used(n, false);
  loop.push_back({0, false, clamped[0], 1.0});
  used[0] = true;
  std::vector<double> gaps;
  for (size_t step = 1; step < n; ++step) {
    const Eigen::Vector3d end = last_point(loop.back().curve);
    double best = INFINITY;
    size_t best_k = 0;
    bool best_reversed = false;
    for (size_t k = 0; k < n; ++k) {
      if (used[k]) continue;
      const double to_start = (first_point(clamped[k]) - end).norm();
      const double to_end = (last_point(clamped[k]) - end).norm();
      if (to_start < best) best = to_start, best_k = k, best_reversed = false;
      if (to_end < best) best = to_end, best_k = k, best_reversed = true;
    }
    used[best_k] = true;
    loop.push_back(
        {best_k, best_reversed, best_reversed ? reversed(clamped[best_k]) : clamped[best_k], 1.0});
    gaps.push_back(best);
  }
  gaps.push_back((first_point(loop.front().curve) - last_point(loop.back().curve)).norm());

  std::string problems;
  for (size_t k = 0; k < n; ++k) {
    if (gaps[k] <= tolerance) continue;
    const LoopCurve& a = loop[k];
    const LoopCurve& b = loop[(k + 1) % n];
    problems += (problems.empty() ? "" : "; ") + curve_name(a.input) +
                (a.reversed ? " start" : " end") + " and " + curve_name(b.input) +
                (b.reversed ? " end" : " start") + " are " + num(gaps[k]) +
                " mm apart (tolerance " + num(tolerance) + " mm)";
  }
  if (!problems.empty())
    throw Error(ErrorCategory::InvalidGeometry,
                std::string(builder) + ": the boundary curves do not form a closed loop: " +
                    problems + "; move the curve ends together or raise gap_tolerance");

  joined = 0;
  for (size_t k = 0; k < n; ++k) {
    BSplineCurve& a = loop[k].curve;
    BSplineCurve& b = loop[(k + 1) % n].curve;
    const Eigen::Vector3d corner = 0.5 * (last_point(a) + first_point(b));
    joined = std::max({joined, (corner - last_point(a)).norm(), (corner - first_point(b)).norm()});
    a.points.row(a.points.rows() - 1) = corner.transpose();
    b.points.row(0) = corner.transpose();
  }
  return loop;
}

/// The loop as one closed curve on [0, n]: loop curve k (degree raised to the loop's highest) on
/// [k, k + 1], C0 joins (knots repeated degree times), each curve's weights scaled so that it
/// starts with the weight its predecessor ends with (same shapes).
BSplineCurve joined(const std::vector<LoopCurve>& loop) {
  int p = 1;
  for (const LoopCurve& c : loop) p = std::max(p, c.curve.basis.degree);
  std::vector<double> knots(static_cast<size_t>(p + 1), 0.0);
  std::vector<Eigen::RowVector3d> points;
  std::vector<double> weights;
  for (size_t k = 0; k < loop.size(); ++k) {
    BSplineCurve c = loop[k].curve;
    if (c.basis.degree < p) c = elevate_degree(c, p - c.basis.degree);
    const size_t m = c.basis.knots.size();
    for (size_t i = static_cast<size_t>(p + 1); i + static_cast<size_t>(p + 1) < m; ++i)
      knots.push_back(static_cast<double>(k) + c.basis.knots[i]);
    knots.insert(knots.end(), static_cast<size_t>(k + 1 < loop.size() ? p : p + 1),
                 static_cast<double>(k + 1));
    const double scale = k == 0 ? 1.0 : weights.back() / c.weights[0];
    for (Eigen::Index i = k == 0 ? 0 : 1; i < c.points.rows(); ++i) {
      points.push_back(c.points.row(i));
      weights.push_back(scale * c.weights[i]);
    }
  }
  Points3 net(static_cast<Eigen::Index>(points.size()), 3);
  Eigen::VectorXd w(net.rows());
  for (size_t i = 0; i < points.size(); ++i) {
    net.row(static_cast<Eigen::Index>(i)) = points[i];
    w[static_cast<Eigen::Index>(i)] = weights[i];
  }
  return make_curve(p, std::move(knots), std::move(net), std::move(w));
}

/// Throws InvalidGeometry when the closed loop crosses, touches or doubles back onto itself within
/// `tolerance` (find_self_intersection on the joined loop): within one curve ("curve #1 crosses
/// itself at t = ...") or between two ("curve #0 at t = 0.4 and curve #2 at t = 0.6 meet ..."),
/// parameters in the input curves' own domains.
void reject_crossing_loop(const std::vector<BSplineCurve>& curves,
                          const std::vector<LoopCurve>& loop, double tolerance,
                          const char* builder) {
  const std::optional<CurveSelfIntersection> x = find_self_intersection(joined(loop), tolerance);
  if (!x) return;
  // Loop parameter T -> (input curve, its own parameter).
  auto input = [&](double T) {
    const size_t k = std::min(static_cast<size_t>(std::max(0.0, std::floor(T))), loop.size() - 1);
    const double u = T - static_cast<double>(k);
    const auto [a, b] = curves[loop[k].input].basis.domain();
    return std::pair{loop[k].input, loop[k].reversed ? b - u * (b - a) : a + u * (b - a)};
  };
  auto [c0, t0] = input(x->t0);
  auto [c1, t1] = input(x->t1);
  if (c0 == c1) {
    CurveSelfIntersection own = *x;
    own.t0 = std::min(t0, t1);
    own.t1 = std::max(t0, t1);
    throw Error(ErrorCategory::InvalidGeometry,
                std::string(builder) + ": " + curve_name(c0) + " " +
                    detail::describe(own, tolerance) +
                    "; a boundary curve must not cross or touch itself: move its control points "
                    "apart there");
  }
  if (c1 < c0) std::swap(c0, c1), std::swap(t0, t1);
  std::string how = "at point " + detail::point_text(x->point, 1e-3 * tolerance);
  if (x->distance > 1e-3 * tolerance)
    how += ", " + num(x->distance) + " mm apart, tolerance " + num(tolerance) + " mm";
  throw Error(ErrorCategory::InvalidGeometry,
              std::string(builder) + ": the boundary crosses itself: " + curve_name(c0) +
                  " at t = " + detail::parameter_text(t0) + " and " + curve_name(c1) +
                  " at t = " + detail::parameter_text(t1) + " meet " + how +
                  "; the boundary curves must form a simple loop: move them apart there");
}

/// One edge of a filled surface and the input curve it must reproduce.
struct Side {
  const BSplineCurve* input = nullptr;  // nullptr: a collapsed side, compared with `point`
  bool input_reversed = false;          // the input runs against the edge
  bool fixed_u = false;                 // edge u = const (else v = const)
  bool at_end = false;                  // the constant is the domain end (else start)
  bool edge_reversed = false;           // the edge runs against its surface parameter
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double alpha = 1;  // edge parameter f is curve parameter alpha f / (alpha f + 1 - f)
  // When merging slivers of the knot union reparametrized the side: its compatible curve and
  // index, so the edge at surface parameter g carries the curve's point at input_parameter(g).
  const CompatibleCurves* merged = nullptr;
  int index = 0;
};

/// Largest distance between each side's input curve and the surface edge, at `count` samples.
double side_deviation(const BSplineSurface& s, const std::vector<Side>& sides, int count,
                      int& samples) {
  const auto [ua, ub] = s.u.domain();
  const auto [va, vb] = s.v.domain();
  double worst = 0;
  samples = 0;
  for (const Side& side : sides) {
    for (double f : linspace(0.0, 1.0, count)) {
      const double g = side.edge_reversed ? 1.0 - f : f;
      const double u = side.fixed_u ? (side.at_end ? ub : ua) : ua + g * (ub - ua);
      const double v = side.fixed_u ? va + g * (vb - va) : (side.at_end ? vb : va);
      Eigen::Vector3d expected = side.point;
      if (side.input) {
        const auto [a, b] = side.input->basis.domain();
        double h = f;
        if (side.merged) {
          const double moved = input_parameter(*side.merged, side.index, g);
          h = side.edge_reversed ? 1.0 - moved : moved;
        }
        const double m =
            side.alpha == 1.0 ? h : std::min(1.0, side.alpha * h / (side.alpha * h + 1.0 - h));
        const double t = side.input_reversed ? b - m * (b - a) : a + m * (b - a);
        expected = evaluate(*side.input, std::clamp(t, a, b));
      }
      worst = std::max(
          worst, (evaluate(s, std::clamp(u, ua, ub), std::clamp(v, va, vb)) - expected).norm());
      ++samples;
    }
  }
  return worst;
}

/// A rational curve (clamped, on [0, 1]) with both end weights 1, the same shape: the Möbius
/// reparametrization t = alpha s / (alpha s + 1 - s), alpha = (w_0 / w_n)^(1/p), gives knots
/// s_k = t_k / (t_k + alpha (1 - t_k)) and weights w_i prod_{k=i+1..i+p} ((alpha - 1) s_k + 1)
/// (Lee & Lucian 1991), then all weights are divided by the first. The fills need it: a surface
/// corner has one weight, so the curves meeting there must agree on it for the edges to be exact.
/// Polynomial curves come back unchanged with alpha = 1.
BSplineCurve unit_end_weights(const BSplineCurve& c, double& alpha) {
  alpha = 1.0;
  const Eigen::Index n = c.weights.size();
  if (!c.is_rational() || (c.weights[0] == 1.0 && c.weights[n - 1] == 1.0)) return c;
  BSplineCurve r = c;
  const int p = c.basis.degree;
  alpha = std::pow(c.weights[0] / c.weights[n - 1], 1.0 / p);
  if (alpha != 1.0) {
    for (double& t : r.basis.knots) t = t / (t + alpha * (1.0 - t));
    for (Eigen::Index i = 0; i < n; ++i) {
      double factor = 1.0;
      for (Eigen::Index k = i + 1; k <= i + p; ++k)
        factor *= (alpha - 1.0) * r.basis.knots[static_cast<size_t>(k)] + 1.0;
      r.weights[i] = c.weights[i] * factor;
    }
  }
  r.weights /= r.weights[0];
  r.weights[n - 1] = 1.0;  // w_n alpha^p / w_0 is 1 up to rounding
  return r;
}

/// Poles and weights of a GeomFill result as our surface on the given bases.
BSplineSurface surface_from_filling(const GeomFill_Filling& filling, const BSplineBasis& u,
                                    const BSplineBasis& v) {
  const int nu = filling.NbUPoles(), nv = filling.NbVPoles();
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  filling.Poles(poles);
  TColStd_Array2OfReal weights(1, nu, 1, nv);
  weights.Init(1.0);
  if (filling.isRational()) filling.Weights(weights);
  Points3 points(static_cast<Eigen::Index>(nu) * nv, 3);
  Eigen::VectorXd w(points.rows());
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const gp_Pnt& q = poles(i + 1, j + 1);
      points.row(static_cast<Eigen::Index>(i) * nv + j) << q.X(), q.Y(), q.Z();
      w[static_cast<Eigen::Index>(i) * nv + j] = weights(i + 1, j + 1);
    }
  return make_surface(u, v, std::move(points), std::move(w));
}

TColgp_Array1OfPnt occt_points(const BSplineCurve& c) {
  TColgp_Array1OfPnt out(1, static_cast<int>(c.points.rows()));
  for (Eigen::Index i = 0; i < c.points.rows(); ++i)
    out(static_cast<int>(i) + 1) = gp_Pnt(c.points(i, 0), c.points(i, 1), c.points(i, 2));
  return out;
}

TColStd_Array1OfReal occt_weights(const BSplineCurve& c) {
  TColStd_Array1OfReal out(1, static_cast<int>(c.weights.size()));
  for (Eigen::Index i = 0; i < c.weights.size(); ++i) out(static_cast<int>(i) + 1) = c.weights[i];
  return out;
}

/// The rational Coons patch GeomFill_BSplineCurves means to build, from compatible sides: u0 (v =
/// 0) and u1 (v = 1) along u, v0 (u = 0) and v1 (u = 1) along v. GeomFill_BSplineCurves calls
/// GeomFill_Coons(P1, P4, P3, P2, W1, W4, W3, W2), whose Init gives the u = 0 column the poles of
/// its 2nd argument but the weights of its 8th: the side weights of u = 0 and u = 1 end up swapped
/// (OpenCASCADE 7.6.3) and the edges are not the curves. Passing the weights in pole order fixes
/// it.
BSplineSurface rational_coons(const BSplineCurve& u0, const BSplineCurve& v1,
                              const BSplineCurve& u1, const BSplineCurve& v0) {
  GeomFill_Coons coons(occt_points(u0), occt_points(v0), occt_points(u1), occt_points(v1),
                       occt_weights(u0), occt_weights(v1), occt_weights(u1), occt_weights(v0));
  return surface_from_filling(coons, u0.basis, v1.basis);
}

GeomFill_FillingStyle occt_style(FillStyle style) {
  switch (style) {
    case FillStyle::Stretch:
      return GeomFill_StretchStyle;
    case FillStyle::Coons:
      return GeomFill_CoonsStyle;
    case FillStyle::Curved:
      return GeomFill_CurvedStyle;
  }
  return GeomFill_CoonsStyle;
}

const char* style_name(FillStyle style) {
  switch (style) {
    case FillStyle::Stretch:
      return "stretch";
    case FillStyle::Coons:
      return "coons";
    case FillStyle::Curved:
      return "curved";
  }
  return "coons";
}

/// Two curves made compatible (same degree and knots on [0, 1]), slivers of their knot union
/// merged within `merge` (the report in `merged`); for Coons, raised to degree 3 when they have
/// fewer than 4 control points. `note` records what was merged and raised.
std::pair<BSplineCurve, BSplineCurve> compatible_pair(const BSplineCurve& a, const BSplineCurve& b,
                                                      bool coons, const KnotMergeOptions& merge,
                                                      const std::string& name_a,
                                                      const std::string& name_b,
                                                      CompatibleCurves& merged, std::string& note) {
  merged = make_compatible({a, b}, merge, {"fill: " + name_a, "fill: " + name_b});
  std::vector<BSplineCurve> pair = merged.curves;
  const std::string merges = detail::merge_note(merged, "curve", {name_a, name_b});
  if (!merges.empty()) note += std::string(note.empty() ? "" : "; ") + merges;
  if (coons && pair[0].basis.count() < 4) {
    const int from = pair[0].basis.degree;
    pair[0] = elevate_degree(pair[0], 3 - from);
    pair[1] = elevate_degree(pair[1], 3 - from);
    note += std::string(note.empty() ? "" : "; ") + name_a + " and " + name_b +
            " raised from degree " + std::to_string(from) +
            " to 3 (Coons needs 4 control points per side)";
  }
  return {pair[0], pair[1]};
}

/// A curve collapsed to `p` with the basis and weights of `like` (the side opposite it).
BSplineCurve point_curve(const BSplineCurve& like, const Eigen::Vector3d& p) {
  BSplineCurve c = like;
  c.points.rowwise() = p.transpose();
  return c;
}

template <class F>
auto with_occt(const char* what, F f) {
  return occt::guarded(ErrorCategory::InvalidGeometry, what, std::move(f));
}

}  // namespace

std::vector<std::string> FillOptions::problems() const {
  std::vector<std::string> out;
  if (!(gap_tolerance > 0.0 && std::isfinite(gap_tolerance)))
    out.push_back("FillOptions::gap_tolerance is " + num(gap_tolerance) +
                  "; it must be > 0 and finite");
  detail::merge_option_problems("FillOptions", min_span_ratio, merge_tolerance, out);
  if (style != FillStyle::Stretch && style != FillStyle::Coons && style != FillStyle::Curved)
    out.push_back("FillOptions::style is " + std::to_string(static_cast<int>(style)) +
                  "; it must be Stretch, Coons or Curved");
  return out;
}

void FillOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

BuiltSurface fill(const std::vector<BSplineCurve>& boundary, const FillOptions& options) {
  options.validate();
  const size_t n = boundary.size();
  if (n < 2 || n > 4)
    throw Error(ErrorCategory::InvalidArgument,
                "fill: takes 2, 3 or 4 boundary curves, got " + std::to_string(n) +
                    (n > 4 ? "; use fill_n_sided for more" : "; give 2 to 4 curves"));
  const double size = size_of(boundary);
  check_curves(boundary, "curve", size);
  // Points closer than this are one point: the gap tolerance, at least the kernel's relative one.
  const double crossing_tolerance =
      std::max(options.gap_tolerance, tolerance::exact_relative * size);
  if (n == 2)
    for (size_t k = 0; k < n; ++k)
      detail::reject_self_intersection(boundary[k], crossing_tolerance, "fill: " + curve_name(k),
                                       "a boundary curve must not cross or touch itself: move its "
                                       "control points apart there");
  const bool coons = options.style == FillStyle::Coons;
  const GeomFill_FillingStyle style = occt_style(options.style);
  const KnotMergeOptions merge{options.min_span_ratio, options.merge_tolerance * size};
  CompatibleCurves merged02, merged13;  // slivers merged between opposite sides
  std::string note;
  std::vector<Side> sides;
  Handle(Geom_BSplineSurface) result;
  BSplineSurface own;  // used instead of `result` for the rational Coons patch
  bool reparametrized = false;

  if (n == 2) {
    BSplineCurve a = normalized(boundary[0]);
    BSplineCurve b = normalized(boundary[1]);
    const double sa = (first_point(a) - first_point(b)).norm(),
                 ea = (last_point(a) - last_point(b)).norm();
    const double sr = (first_point(a) - last_point(b)).norm(),
                 er = (last_point(a) - first_point(b)).norm();
    if (options.style != FillStyle::Curved) {
      // Ruled surface: turn curve #1 to run like curve #0 (ends paired by distance).
      const bool turn = sr + er < sa + ea;
      if (turn) {
        b = reversed(b);
        note = "curve #1 reversed";
      }
      BSplineCurve ca, cb;
      std::tie(ca, cb) =
          compatible_pair(a, b, false, merge, curve_name(0), curve_name(1), merged02, note);
      result = with_occt("fill", [&] {
        GeomFill_BSplineCurves filler(occt::to_occt(ca, "curve #0"), occt::to_occt(cb, "curve #1"),
                                      style);
        return filler.Surface();
      });
      sides.push_back({&boundary[0], false, false, false, false, {}, 1.0, &merged02, 0});
      sides.push_back({&boundary[1], turn, false, true, false, {}, 1.0, &merged02, 1});
    } else {
      // Curved with two curves: both must start at a shared corner.
      const double gaps[4] = {sa, sr, er, ea};  // start-start, start-end, end-start, end-end
      const int best = static_cast<int>(std::min_element(gaps, gaps + 4) - gaps);
      if (gaps[best] > options.gap_tolerance)
        throw Error(ErrorCategory::InvalidGeometry,
                    "fill: a curved fill of 2 curves needs them to share a corner, but curve #0 " +
                        std::string(best >= 2 ? "end" : "start") + " and curve #1 " +
                        (best % 2 ? "end" : "start") + " (the nearest ends) are " +
                        num(gaps[best]) + " mm apart (tolerance " + num(options.gap_tolerance) +
                        " mm); join them, or use Stretch or Coons for the ruled surface");
      const bool turn_a = best >= 2, turn_b = best % 2 == 1;
      if (turn_a) a = reversed(a);
      if (turn_b) b = reversed(b);
      double alpha_a = 1, alpha_b = 1;
      a = unit_end_weights(a, alpha_a);
      b = unit_end_weights(b, alpha_b);
      reparametrized = alpha_a != 1.0 || alpha_b != 1.0;
      const Eigen::Vector3d corner = 0.5 * (first_point(a) + first_point(b));
      const double moved = (corner - first_point(a)).norm();
      a.points.row(0) = corner.transpose();
      b.points.row(0) = corner.transpose();
      if (turn_a) note = "curve #0 reversed";
      if (turn_b) note += std::string(note.empty() ? "" : "; ") + "curve #1 reversed";
      if (moved > 0)
        note += std::string(note.empty() ? "" : "; ") + "corner joined (ends moved " + num(moved) +
                " mm)";
      result = with_occt("fill", [&] {
        GeomFill_BSplineCurves filler(occt::to_occt(a, "curve #0"), occt::to_occt(b, "curve #1"),
                                      style);
        return filler.Surface();
      });
      sides.push_back({&boundary[0], turn_a, false, false, false, {}, alpha_a});
      sides.push_back({&boundary[1], turn_b, true, false, false, {}, alpha_b});
    }
  } else {
    double joined = 0;
    std::vector<LoopCurve> loop = closed_loop(boundary, options.gap_tolerance, "fill", joined);
    reject_crossing_loop(boundary, loop, crossing_tolerance, "fill");
    bool rational = false;
    for (LoopCurve& c : loop) {
      rational = rational || c.curve.is_rational();
      c.curve = unit_end_weights(c.curve, c.alpha);
      reparametrized = reparametrized || c.alpha != 1.0;
    }
    for (const LoopCurve& c : loop)
      if (c.reversed)
        note += std::string(note.empty() ? "" : "; ") + curve_name(c.input) + " reversed";
    if (joined > 0)
      note += std::string(note.empty() ? "" : "; ") + "corners joined (ends moved up to " +
              num(joined) + " mm)";
    // GeomFill_BSplineCurves arranges C1 (v = 0, along u), C2 (u = 1), C3 reversed (v = 1),
    // C4 reversed (u = 0); its arrangement finds our loop order unchanged because our corners
    // coincide exactly. Opposite sides are made compatible in surface direction.
    const BSplineCurve& c1 = loop[0].curve;
    const BSplineCurve& c2 = loop[1].curve;
    const BSplineCurve& c3 = loop[2].curve;
    BSplineCurve u0, u1, v1, v0;
    std::tie(u0, u1) = compatible_pair(c1, reversed(c3), coons, merge, curve_name(loop[0].input),
                                       curve_name(loop[2].input), merged02, note);
    if (n == 4) {
      std::tie(v1, v0) =
          compatible_pair(c2, reversed(loop[3].curve), coons, merge, curve_name(loop[1].input),
                          curve_name(loop[3].input), merged13, note);
    } else {
      BSplineCurve single = make_compatible({c2})[0];
      if (coons && single.basis.count() < 4) {
        const int from = single.basis.degree;
        single = elevate_degree(single, 3 - from);
        note += std::string(note.empty() ? "" : "; ") + curve_name(loop[1].input) +
                " raised from degree " + std::to_string(from) +
                " to 3 (Coons needs 4 control points per side)";
      }
      v1 = single;
      v0 = point_curve(single, first_point(c1));
    }
    if (coons && rational) {
      own = with_occt("fill", [&] { return rational_coons(u0, v1, u1, v0); });
      note += std::string(note.empty() ? "" : "; ") +
              "rational Coons built by GeomFill_Coons with corrected side weights";
    } else {
      result = with_occt("fill", [&] {
        GeomFill_BSplineCurves filler(
            occt::to_occt(u0, curve_name(loop[0].input)),
            occt::to_occt(v1, curve_name(loop[1].input)),
            occt::to_occt(reversed(u1), curve_name(loop[2].input)),
            occt::to_occt(reversed(v0), n == 4 ? curve_name(loop[3].input) : "collapsed side"),
            style);
        return filler.Surface();
      });
    }
    // Side k of the loop: which edge it became (fixed u, at the domain end, run backwards) and
    // the compatible pair it came from (0 and 2: merged02; 1 and 3: merged13, none with 3 curves).
    const bool fixed_u[4] = {false, true, false, true}, at_end[4] = {false, true, true, false};
    for (size_t k = 0; k < n; ++k) {
      const LoopCurve& c = loop[k];
      const CompatibleCurves* pair = k % 2 == 0 ? &merged02 : (n == 4 ? &merged13 : nullptr);
      sides.push_back({&boundary[c.input],
                       c.reversed,
                       fixed_u[k],
                       at_end[k],
                       k >= 2,
                       {},
                       c.alpha,
                       pair,
                       k >= 2 ? 1 : 0});
    }
    if (n == 3) sides.push_back({nullptr, false, true, false, true, first_point(c1)});
  }
  if (reparametrized)
    note += std::string(note.empty() ? "" : "; ") +
            "rational curves reparametrized (Möbius) to end weights 1 so corners share one weight";

  BuiltSurface built;
  built.surface = result.IsNull() ? own : occt::from_occt(result, "filled surface");
  int samples = 0;
  const int spans = std::max(built.surface.u.count(), built.surface.v.count());
  const double worst = side_deviation(built.surface, sides, std::max(101, 8 * spans + 1), samples);
  std::string method =
      std::string(style_name(options.style)) + " fill of " + std::to_string(n) + " curves";
  if (!note.empty()) method += " (" + note + ")";
  built.report = describe(built.surface, method);
  built.report.exact = merged02.merges.empty() && merged13.merges.empty();
  built.report.max_deviation_mm = worst;
  built.report.samples = samples;
  return built;
}

std::vector<std::string> NSidedFillOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const char* field, const std::string& value, const char* rule) {
    out.push_back(std::string("NSidedFillOptions::") + field + " is " + value + "; it must be " +
                  rule);
  };
  if (degree < 2 || degree > 14) bad("degree", std::to_string(degree), "in [2, 14]");
  if (points_on_curve < 2 || points_on_curve > 1000)
    bad("points_on_curve", std::to_string(points_on_curve), "in [2, 1000]");
  if (iterations < 1 || iterations > 50)
    bad("iterations", std::to_string(iterations), "in [1, 50]");
  if (!(tolerance_2d > 0 && std::isfinite(tolerance_2d)))
    bad("tolerance_2d", num(tolerance_2d), "> 0 and finite");
  if (!(tolerance_3d > 0 && std::isfinite(tolerance_3d)))
    bad("tolerance_3d", num(tolerance_3d), "> 0 and finite");
  if (!(angular_tolerance > 0 && std::isfinite(angular_tolerance)))
    bad("angular_tolerance", num(angular_tolerance), "> 0 and finite");
  if (!(curvature_tolerance > 0 && std::isfinite(curvature_tolerance)))
    bad("curvature_tolerance", num(curvature_tolerance), "> 0 and finite");
  if (max_degree < 3 || max_degree > 25)
    bad("max_degree", std::to_string(max_degree), "in [3, 25]");
  if (max_segments < 1 || max_segments > 1000)
    bad("max_segments", std::to_string(max_segments), "in [1, 1000]");
  if (!(gap_tolerance > 0 && std::isfinite(gap_tolerance)))
    bad("gap_tolerance", num(gap_tolerance), "> 0 and finite");
  if (samples_per_curve < 2) bad("samples_per_curve", std::to_string(samples_per_curve), ">= 2");
  return out;
}

void NSidedFillOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

NSidedFill fill_n_sided(const std::vector<BSplineCurve>& boundary,
                        const std::vector<BSplineCurve>& interior,
                        const NSidedFillOptions& options) {
  options.validate();
  if (boundary.size() < 3)
    throw Error(ErrorCategory::InvalidArgument,
                "fill_n_sided: needs at least 3 boundary curves, got " +
                    std::to_string(boundary.size()) + "; use fill for 2");
  const double size = size_of(boundary, interior);
  check_curves(boundary, "curve", size);
  check_curves(interior, "interior curve", size);
  double joined = 0;
  const std::vector<LoopCurve> loop =
      closed_loop(boundary, options.gap_tolerance, "fill_n_sided", joined);
  reject_crossing_loop(boundary, loop,
                       std::max(options.gap_tolerance, tolerance::exact_relative * size),
                       "fill_n_sided");

  double occt_g0 = 0;
  const Handle(Geom_BSplineSurface) plate = with_occt("fill_n_sided", [&] {
    const size_t n = loop.size();
    std::vector<TopoDS_Vertex> corners;
    for (size_t k = 0; k < n; ++k)
      corners.push_back(BRepBuilderAPI_MakeVertex(pnt(first_point(loop[k].curve))).Vertex());
    BRepOffsetAPI_MakeFilling filler(options.degree, options.points_on_curve, options.iterations,
                                     options.anisotropy, options.tolerance_2d, options.tolerance_3d,
                                     options.angular_tolerance, options.curvature_tolerance,
                                     options.max_degree, options.max_segments);
    for (size_t k = 0; k < n; ++k) {
      BRepBuilderAPI_MakeEdge edge(occt::to_occt(loop[k].curve, curve_name(loop[k].input)),
                                   corners[k], corners[(k + 1) % n]);
      if (!edge.IsDone())
        throw Error(
            ErrorCategory::InvalidGeometry,
            "fill_n_sided: OpenCASCADE could not make an edge of " + curve_name(loop[k].input));
      filler.Add(edge.Edge(), GeomAbs_C0, Standard_True);
    }
    for (size_t k = 0; k < interior.size(); ++k) {
      BRepBuilderAPI_MakeEdge edge(
          occt::to_occt(interior[k], "interior curve #" + std::to_string(k)));
      if (!edge.IsDone())
        throw Error(ErrorCategory::InvalidGeometry,
                    "fill_n_sided: OpenCASCADE could not make an edge of interior curve #" +
                        std::to_string(k));
      filler.Add(edge.Edge(), GeomAbs_C0, Standard_False);
    }
    filler.Build();
    if (!filler.IsDone())
      throw Error(
          ErrorCategory::InvalidGeometry,
          "fill_n_sided: OpenCASCADE's plate filling (BRepOffsetAPI_MakeFilling) failed for "
          "these curves; check that the boundary is a simple loop and the interior curves "
          "lie inside it");
    occt_g0 = filler.G0Error();
    const TopoDS_Face face = TopoDS::Face(filler.Shape());
    const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
    Handle(Geom_BSplineSurface) bspline = Handle(Geom_BSplineSurface)::DownCast(surface);
    if (bspline.IsNull()) bspline = GeomConvert::SurfaceToBSplineSurface(surface);
    return bspline;
  });

  NSidedFill out;
  out.built.surface = occt::from_occt(plate, "plate surface");
  const BSplineSurface& s = out.built.surface;
  int samples = 0;
  auto measure = [&](const BSplineCurve& c) {
    const auto [a, b] = c.basis.domain();
    double worst = 0;
    for (double t : linspace(a, b, options.samples_per_curve)) {
      worst = std::max(worst, closest_point(s, evaluate(c, t)).distance);
      ++samples;
    }
    return worst;
  };
  for (const BSplineCurve& c : boundary) out.curve_deviations.push_back(measure(c));
  for (const BSplineCurve& c : interior) out.curve_deviations.push_back(measure(c));
  std::string method = "n-sided plate fill of " + std::to_string(boundary.size()) + " curves";
  if (!interior.empty()) method += " and " + std::to_string(interior.size()) + " interior";
  method += " (OpenCASCADE G0 error " + num(occt_g0) + " mm";
  if (joined > 0) method += "; corners joined, ends moved up to " + num(joined) + " mm";
  method += ")";
  out.built.report = describe(s, method);
  out.built.report.exact = false;
  out.built.report.max_deviation_mm =
      *std::max_element(out.curve_deviations.begin(), out.curve_deviations.end());
  out.built.report.samples = samples;
  return out;
}

}  // namespace clay::surface
