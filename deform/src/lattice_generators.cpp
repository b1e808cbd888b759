// The generators of extended lattices (Coquillart 1990 §3.1): cylindrical lattices of cubic
// Bézier arcs around an axis, and prismatic lattices over a polygon.
#include <clay/deform/extended_lattice.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/parallel.hpp>

#include <Eigen/Dense>  // determinant, LU, JacobiSVD

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <sstream>
#include <utility>

#include "extended_internal.hpp"
#include "messages.hpp"

namespace clay::deform {

namespace {

using Vec3 = Eigen::Vector3d;
using detail::format;
using internal::all_finite;

constexpr int max_count = 1024;              // sectors, rings, layers, ...
constexpr long long max_chunks = 1'000'000;  // per generated lattice

[[noreturn]] void bad_argument(const std::string& field, const std::string& value,
                               const std::string& rule) {
  throw Error(ErrorCategory::InvalidArgument, field + " = " + value + " breaks the rule " + rule);
}

void check_count(const std::string& type, const std::string& field, int value, int lo) {
  if (value < lo || value > max_count)
    bad_argument(type + "::" + field, std::to_string(value),
                 std::to_string(lo) + " <= " + field + " <= " + std::to_string(max_count));
}

/// Unit-circle control point `angular` (0 .. 3 sectors − 1) of the cubic Bézier arcs.
Eigen::Vector2d arc_point(int angular, int sectors) {
  const double step = 2 * std::numbers::pi / sectors;
  const int b = angular / 3, j = angular % 3;
  const double kappa = 4.0 / 3.0 * std::tan(step / 4);
  const double t0 = b * step, t1 = (b + 1) * step;
  const Eigen::Vector2d p0(std::cos(t0), std::sin(t0)), p1(std::cos(t1), std::sin(t1));
  if (j == 0) return p0;
  if (j == 1) return p0 + kappa * Eigen::Vector2d(-p0.y(), p0.x());
  return p1 - kappa * Eigen::Vector2d(-p1.y(), p1.x());
}

}  // namespace

// ---- cylindrical lattice
// -----------------------------------------------------------------------------

void CylinderSpec::validate() const {
  if (!all_finite(origin))
    bad_argument("CylinderSpec::origin", format(origin), "finite coordinates");
  if (!all_finite(axis) || !(axis.norm() > 0))
    bad_argument("CylinderSpec::axis", format(axis), "a finite non-zero direction");
  if (!all_finite(reference) ||
      !(reference.cross(axis).norm() > 1e-9 * reference.norm() * axis.norm()))
    bad_argument("CylinderSpec::reference", format(reference),
                 "a finite direction not parallel to the axis " + format(axis));
  if (!(std::isfinite(radius) && radius > 0))
    bad_argument("CylinderSpec::radius", format(radius), "0 < radius < infinity (mm)");
  if (!(std::isfinite(inner_radius) && inner_radius >= 0 && inner_radius < radius))
    bad_argument("CylinderSpec::inner_radius", format(inner_radius),
                 "0 <= inner_radius < radius = " + format(radius) + " (0 merges the axis points)");
  if (!(std::isfinite(height) && height > 0))
    bad_argument("CylinderSpec::height", format(height), "0 < height < infinity (mm)");
  check_count("CylinderSpec", "sectors", sectors, 3);
  check_count("CylinderSpec", "rings", rings, 1);
  check_count("CylinderSpec", "layers", layers, 1);
  const long long chunks = static_cast<long long>(sectors) * rings * layers;
  if (chunks > max_chunks)
    bad_argument("CylinderSpec::sectors * rings * layers", std::to_string(chunks),
                 "<= " + std::to_string(max_chunks) + " chunks");
}

int cylindrical_index(const CylinderSpec& spec, int radial, int angular, int axial) {
  spec.validate();
  const int nI = 3 * spec.rings + 1, nJ = 3 * spec.sectors, nK = 3 * spec.layers + 1;
  if (radial < 0 || radial >= nI || axial < 0 || axial >= nK)
    throw Error(ErrorCategory::OutOfDomain,
                "cylindrical_index: (radial, axial) = (" + std::to_string(radial) + ", " +
                    std::to_string(axial) +
                    ") breaks the rule 0 <= radial <= " + std::to_string(nI - 1) +
                    ", 0 <= axial <= " + std::to_string(nK - 1) + " (3 rings, 3 layers)");
  const int j = ((angular % nJ) + nJ) % nJ;
  if (spec.inner_radius == 0) {
    if (radial == 0) return axial;
    return nK + ((radial - 1) * nJ + j) * nK + axial;
  }
  return (radial * nJ + j) * nK + axial;
}

ExtendedLattice make_cylindrical_lattice(const CylinderSpec& spec) {
  spec.validate();
  const Vec3 e3 = spec.axis.normalized();
  const Vec3 e1 = (spec.reference - spec.reference.dot(e3) * e3).normalized();
  const Vec3 e2 = e3.cross(e1);
  const int nI = 3 * spec.rings + 1, nJ = 3 * spec.sectors, nK = 3 * spec.layers + 1;
  const bool merged = spec.inner_radius == 0;
  const Eigen::Index rows = merged ? static_cast<Eigen::Index>(nK) * (1 + (nI - 1) * nJ)
                                   : static_cast<Eigen::Index>(nI) * nJ * nK;
  ExtendedLattice L;
  L.rest.resize(rows, 3);
  std::vector<Eigen::Vector2d> arc(static_cast<size_t>(nJ));
  for (int j = 0; j < nJ; ++j) arc[static_cast<size_t>(j)] = arc_point(j, spec.sectors);
  for (int i = 0; i < nI; ++i) {
    // rho linear in the radial index: the map is linear in u (linear precision of Bernstein).
    const double rho = spec.inner_radius + (spec.radius - spec.inner_radius) * i / (nI - 1);
    for (int j = 0; j < nJ; ++j)
      for (int k = 0; k < nK; ++k) {
        const Vec3 base = spec.origin + (spec.height * k / (nK - 1)) * e3;
        const Eigen::Vector2d& c = arc[static_cast<size_t>(j)];
        const Vec3 p = (merged && i == 0) ? base : Vec3(base + rho * (c.x() * e1 + c.y() * e2));
        L.rest.row(cylindrical_index(spec, i, j, k)) = p.transpose();
      }
  }
  L.points = L.rest;
  L.chunks.reserve(static_cast<size_t>(spec.rings) * spec.sectors * spec.layers);
  for (int a = 0; a < spec.rings; ++a)
    for (int b = 0; b < spec.sectors; ++b)
      for (int c = 0; c < spec.layers; ++c) {
        Chunk chunk;
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k)
              chunk[static_cast<size_t>((i * 4 + j) * 4 + k)] =
                  cylindrical_index(spec, 3 * a + i, 3 * b + j, 3 * c + k);
        L.chunks.push_back(chunk);
      }
  return L;
}

// ---- prismatic lattice
// ----------------------------------------------------------------------------------

void PrismSpec::validate() const {
  if (!all_finite(origin)) bad_argument("PrismSpec::origin", format(origin), "finite coordinates");
  if (!all_finite(x_axis) || !(x_axis.norm() > 0))
    bad_argument("PrismSpec::x_axis", format(x_axis), "a finite non-zero direction");
  if (!all_finite(y_axis) || !(y_axis.cross(x_axis).norm() > 1e-9 * y_axis.norm() * x_axis.norm()))
    bad_argument("PrismSpec::y_axis", format(y_axis),
                 "a finite direction not parallel to x_axis " + format(x_axis));
  const Vec3 normal = x_axis.cross(y_axis).normalized();
  if (!all_finite(extrusion) || !(std::abs(extrusion.dot(normal)) > 1e-9 * extrusion.norm()))
    bad_argument("PrismSpec::extrusion", format(extrusion),
                 "a finite vector off the plane of x_axis and y_axis (extrusion . normal != 0)");
  if (sections.size() < 2)
    bad_argument("PrismSpec::sections.size()", std::to_string(sections.size()),
                 ">= 2 (the loft needs two section curves)");
  const size_t count = sections[0].size();
  for (size_t s = 0; s < sections.size(); ++s) {
    const size_t n = sections[s].size();
    const std::string field = "PrismSpec::sections[" + std::to_string(s) + "].size()";
    if (n < 4 || (n - 1) % 3 != 0)
      bad_argument(field, std::to_string(n), "= 3 segments + 1 >= 4 (piecewise cubic Bézier)");
    if (n != count)
      bad_argument(field, std::to_string(n),
                   "= sections[0].size() = " + std::to_string(count) + " (every section alike)");
    for (size_t p = 0; p < n; ++p)
      if (!all_finite(sections[s][p]))
        bad_argument("PrismSpec::sections[" + std::to_string(s) + "][" + std::to_string(p) + "]",
                     "(" + format(sections[s][p].x()) + ", " + format(sections[s][p].y()) + ")",
                     "finite coordinates");
  }
  check_count("PrismSpec", "layers", layers, 1);
  const long long chunks = static_cast<long long>(sections.size() - 1) *
                           static_cast<long long>((count - 1) / 3) * layers;
  if (chunks > max_chunks)
    bad_argument("PrismSpec (sections - 1) * segments * layers", std::to_string(chunks),
                 "<= " + std::to_string(max_chunks) + " chunks");
}

ExtendedLattice make_prismatic_lattice(const PrismSpec& spec) {
  spec.validate();
  const Vec3 e1 = spec.x_axis.normalized();
  const Vec3 e2 = (spec.y_axis - spec.y_axis.dot(e1) * e1).normalized();
  const int gaps = static_cast<int>(spec.sections.size()) - 1;
  const int nJ = static_cast<int>(spec.sections[0].size());
  const int segments = (nJ - 1) / 3;
  const int nI = 3 * gaps + 1, nK = 3 * spec.layers + 1;
  auto index = [&](int i, int j, int k) { return (i * nJ + j) * nK + k; };
  ExtendedLattice L;
  L.rest.resize(static_cast<Eigen::Index>(nI) * nJ * nK, 3);
  for (int i = 0; i < nI; ++i) {
    const int a = std::min(i / 3, gaps - 1), r = i - 3 * a;  // row r of the ruled gap a
    for (int j = 0; j < nJ; ++j) {
      const Eigen::Vector2d p =
          ((3 - r) * spec.sections[static_cast<size_t>(a)][static_cast<size_t>(j)] +
           r * spec.sections[static_cast<size_t>(a) + 1][static_cast<size_t>(j)]) /
          3.0;
      for (int k = 0; k < nK; ++k)
        L.rest.row(index(i, j, k)) = (spec.origin + p.x() * e1 + p.y() * e2 +
                                      (static_cast<double>(k) / (nK - 1)) * spec.extrusion)
                                         .transpose();
    }
  }
  L.points = L.rest;
  for (int a = 0; a < gaps; ++a)
    for (int b = 0; b < segments; ++b)
      for (int c = 0; c < spec.layers; ++c) {
        Chunk chunk;
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k)
              chunk[static_cast<size_t>((i * 4 + j) * 4 + k)] =
                  index(3 * a + i, 3 * b + j, 3 * c + k);
        L.chunks.push_back(chunk);
      }
  const double size = (L.rest.colwise().maxCoeff() - L.rest.colwise().minCoeff()).norm();
  return merge_coincident_points(L, 1e-12 * size);
}

}  // namespace clay::deform
