// Extended lattices (Coquillart 1990): validity and welding coincident control points. The
// generators are in lattice_generators.cpp; freezing, chunk_point and the evaluation of eq. (1) in
// extended_freeze.cpp.
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

[[noreturn]] void bad_argument(const std::string& field, const std::string& value,
                               const std::string& rule) {
  throw Error(ErrorCategory::InvalidArgument, field + " = " + value + " breaks the rule " + rule);
}

}  // namespace

// ---- the lattice
// ---------------------------------------------------------------------------------

std::vector<std::string> problems(const ExtendedLattice& lattice, std::string_view name) {
  std::vector<std::string> out;
  const std::string n(name);
  const Eigen::Index rows = lattice.rest.rows();
  if (lattice.points.rows() != rows)
    out.push_back(n + ": " + std::to_string(rows) + " rest control points but " +
                  std::to_string(lattice.points.rows()) +
                  " current ones; give one current position per rest control point");
  if (lattice.chunks.empty())
    out.push_back(n + ": no chunks; give at least one chunk of 64 control point indices");
  for (const auto* m : {&lattice.rest, &lattice.points})
    for (Eigen::Index r = 0; r < m->rows(); ++r)
      if (!all_finite(m->row(r))) {
        out.push_back(n + ": " + (m == &lattice.rest ? "rest" : "current") + " control point row " +
                      std::to_string(r) + " is not finite " + format(Vec3(m->row(r).transpose())) +
                      "; give finite coordinates");
        break;  // one is enough to name the culprit
      }
  bool bad_index = false;
  for (size_t c = 0; c < lattice.chunks.size() && !bad_index; ++c)
    for (int e = 0; e < chunk_control_points; ++e) {
      const int index = lattice.chunks[c][static_cast<size_t>(e)];
      if (index < 0 || index >= rows) {
        out.push_back(n + ": chunk " + std::to_string(c) + " control point (" +
                      std::to_string(e / 16) + ", " + std::to_string(e / 4 % 4) + ", " +
                      std::to_string(e % 4) + ") has index " + std::to_string(index) +
                      " outside [0, " + std::to_string(rows) +
                      "); give row indices of rest / points");
        bad_index = true;
        break;
      }
    }
  if (!out.empty()) return out;
  for (size_t c = 0; c < lattice.chunks.size(); ++c) {
    const auto& chunk = lattice.chunks[c];
    bool same = true;
    for (int e = 1; e < chunk_control_points && same; ++e)
      same = lattice.rest.row(chunk[static_cast<size_t>(e)]) == lattice.rest.row(chunk[0]);
    if (same) {
      out.push_back(n + ": chunk " + std::to_string(c) +
                    " has zero extent: its 64 rest control points all lie at " +
                    format(Vec3(lattice.rest.row(chunk[0]).transpose())) +
                    "; give a chunk that spans space or remove it");
      break;
    }
  }
  return out;
}

void validate(const ExtendedLattice& lattice, std::string_view name) {
  const auto list = problems(lattice, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}

ExtendedLattice merge_coincident_points(const ExtendedLattice& lattice, double tolerance) {
  if (!(std::isfinite(tolerance) && tolerance >= 0))
    bad_argument("merge_coincident_points: tolerance", format(tolerance),
                 "0 <= tolerance < infinity (mm)");
  validate(lattice);
  const Eigen::Index rows = lattice.rest.rows();
  // Union-find over pairs within the tolerance, found by a sweep along x; the root is the
  // smallest index of its group.
  std::vector<Eigen::Index> parent(static_cast<size_t>(rows));
  std::iota(parent.begin(), parent.end(), Eigen::Index{0});
  auto find = [&](Eigen::Index i) {
    while (parent[static_cast<size_t>(i)] != i)
      i = parent[static_cast<size_t>(i)] =
          parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    return i;
  };
  std::vector<Eigen::Index> order(static_cast<size_t>(rows));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return lattice.rest(a, 0) < lattice.rest(b, 0);
  });
  for (size_t a = 0; a < order.size(); ++a)
    for (size_t b = a + 1; b < order.size(); ++b) {
      const Eigen::Index i = order[a], j = order[b];
      if (lattice.rest(j, 0) - lattice.rest(i, 0) > tolerance) break;
      if ((lattice.rest.row(i) - lattice.rest.row(j)).norm() <= tolerance) {
        const Eigen::Index ri = find(i), rj = find(j);
        if (ri != rj) parent[static_cast<size_t>(std::max(ri, rj))] = std::min(ri, rj);
      }
    }
  // Renumber the roots that chunks use, in increasing order.
  std::vector<int> number(static_cast<size_t>(rows), -1);
  for (const auto& chunk : lattice.chunks)
    for (int index : chunk) number[static_cast<size_t>(find(index))] = 0;
  int next = 0;
  for (auto& v : number)
    if (v == 0) v = next++;
  ExtendedLattice out;
  out.rest.resize(next, 3);
  out.points.resize(next, 3);
  for (Eigen::Index r = 0; r < rows; ++r)
    if (find(r) == r && number[static_cast<size_t>(r)] >= 0) {
      out.rest.row(number[static_cast<size_t>(r)]) = lattice.rest.row(r);
      out.points.row(number[static_cast<size_t>(r)]) = lattice.points.row(r);
    }
  out.chunks = lattice.chunks;
  for (auto& chunk : out.chunks)
    for (int& index : chunk) index = number[static_cast<size_t>(find(index))];
  return out;
}

}  // namespace clay::deform
