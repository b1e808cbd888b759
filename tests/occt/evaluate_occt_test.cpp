// Our evaluation against OpenCASCADE's own Geom_BSplineSurface::D2 / Geom_BSplineCurve::D2, an
// independent implementation, on random rational objects of degrees 1..7.
#include <catch2/catch.hpp>

#include <clay/surface/evaluate.hpp>

#include <random>

#include "occt_reference.hpp"
#include "random_geometry.hpp"

using namespace clay::surface;

namespace {
/// |a - b| relative to max(|b|, floor): the floor keeps near-zero derivatives from dividing by 0.
double rel(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double floor) {
  return (a - b).norm() / std::max(b.norm(), floor);
}
}  // namespace

TEST_CASE("surface points and derivatives agree with OpenCASCADE D2 to 1e-12", "[evaluate][occt]") {
  std::mt19937 rng(61);
  double worst[6] = {0, 0, 0, 0, 0, 0};
  for (int p = 1; p <= 7; ++p) {
    for (int q : {1, 3, 7}) {
      for (bool clamped : {true, false}) {
        const BSplineSurface s =
            clay::test::random_surface(rng, p, q, p + 4, q + 3, true, clamped, 2);
        const auto [ua, ub] = s.u.domain();
        const auto [va, vb] = s.v.domain();
        std::uniform_real_distribution<double> U(ua, ub), V(va, vb);
        std::vector<std::pair<double, double>> params = {{ua, va}, {ub, vb}, {ua, vb}};
        for (int k = 0; k < 40; ++k) params.emplace_back(U(rng), V(rng));
        for (const auto& [u, v] : params) {
          const SurfaceDerivatives ours = derivatives(s, u, v);
          const SurfaceDerivatives occt = occt_reference::surface_d2(s, u, v);
          // Derivatives scale with 1/span^k; the floor is the size of the point itself.
          const double floor = std::max(1.0, occt.point.norm());
          worst[0] = std::max(worst[0], rel(ours.point, occt.point, floor));
          worst[1] = std::max(worst[1], rel(ours.du, occt.du, floor));
          worst[2] = std::max(worst[2], rel(ours.dv, occt.dv, floor));
          worst[3] = std::max(worst[3], rel(ours.duu, occt.duu, floor));
          worst[4] = std::max(worst[4], rel(ours.duv, occt.duv, floor));
          worst[5] = std::max(worst[5], rel(ours.dvv, occt.dvv, floor));
        }
      }
    }
  }
  INFO("relative differences: S " << worst[0] << ", Su " << worst[1] << ", Sv " << worst[2]
                                  << ", Suu " << worst[3] << ", Suv " << worst[4] << ", Svv "
                                  << worst[5]);
  for (double w : worst) CHECK(w < 1e-12);
}

TEST_CASE("curve points and derivatives agree with OpenCASCADE D2 to 1e-12", "[evaluate][occt]") {
  std::mt19937 rng(62);
  double worst = 0;
  for (int p = 1; p <= 7; ++p) {
    for (bool clamped : {true, false}) {
      const BSplineCurve c = clay::test::random_curve(rng, p, p + 6, true, clamped, p);
      const auto [a, b] = c.basis.domain();
      for (double t : linspace(a, b, 57)) {
        const CurveDerivatives ours = derivatives(c, t);
        const CurveDerivatives occt = occt_reference::curve_d2(c, t);
        const double floor = std::max(1.0, occt.point.norm());
        worst = std::max({worst, rel(ours.point, occt.point, floor), rel(ours.d1, occt.d1, floor),
                          rel(ours.d2, occt.d2, floor)});
      }
    }
  }
  INFO("largest relative difference " << worst);
  CHECK(worst < 1e-12);
}
