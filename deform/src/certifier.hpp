#pragma once
// What the certified refit needs of a deformation (internal to clay_deform): its point map and,
// where derivative bounds are known, sup ||D'|| and sup ||D''|| over the convex hull of some
// points, with the lattice planes the hull crosses (refit.cpp uses them; certifier.cpp builds
// them per deformation).
#include <clay/deform/deformation.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/refit.hpp>
#include <clay/deform/stack.hpp>

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace clay::deform::detail {

/// sup ||D'|| (operator norm) and sup ||D''|| (|D''[a, a]| <= second |a|^2) over a region;
/// second = inf where D' is not Lipschitz there (a kink of D crosses the region).
struct Bounds {
  double first = std::numeric_limits<double>::infinity();
  double second = std::numeric_limits<double>::infinity();
};

/// A plane of a lattice crossed by a region.
struct Plane {
  int step = 0;
  int axis = 0;
  double value = 0;
};

struct HullInfo {
  Bounds bounds;
  std::vector<Plane> planes;
};

/// What the refit needs of a deformation: the map, and (when certifiable) bounds over the convex
/// hull of a set of points.
struct Certifier {
  std::string name;
  PointMap map;
  std::function<HullInfo(const Points3& hull)> info;  // empty: not certifiable
  std::string why_not;                                // why `info` is empty
};

/// The certifier of each deformation kind: the map, and the bounds over a hull where known.
Certifier certifier(const Taper& d);
Certifier certifier(const Twist& d);
Certifier certifier(const Bend& d);
Certifier certifier(const BezierLattice& d);
Certifier certifier(const BSplineLattice& d);
/// Not certifiable: evaluated through Newton-frozen chunk coordinates (why_not says so).
Certifier certifier(const ExtendedLattice& d);
/// The enabled steps chained: (D2 ∘ D1)'' [a, a] = D2''[D1' a, D1' a] + D2' D1''[a, a].
Certifier certifier(const DeformationStack& stack);

}  // namespace clay::deform::detail
