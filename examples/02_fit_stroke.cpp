// Example 02 — fit a noisy hand-drawn stroke with B-spline curves and print the report.
//
//   example_02_fit_stroke
//
// The stroke: 400 points drawn along a 3D path that runs smoothly, turns a sharp corner and runs
// on, with 0.1 mm of noise per coordinate (a tracked pen). fit_stroke splits it at the corner and
// fits each part with a few control points. Exits non-zero if the fit did not converge or the
// corner was missed.
#include <clay/sketch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

using namespace clay::sketch;

namespace {

/// Standard normal deviates (Box–Muller on std::mt19937, the same on every platform).
double gaussian(std::mt19937& rng) {
  const double u1 = (static_cast<double>(rng()) + 1.0) / 4294967296.0;
  const double u2 = static_cast<double>(rng()) / 4294967296.0;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// A wave rising out of the xy plane for 200 points, a corner, then a straight climb.
Stroke drawn_stroke() {
  std::mt19937 rng(2);
  Stroke stroke;
  stroke.points.resize(400, 3);
  for (int i = 0; i < 400; ++i) {
    Eigen::Vector3d p;
    if (i < 200) {
      const double s = i / 199.0;
      p = {100.0 * s, 12.0 * std::sin(2.0 * std::numbers::pi * s), 15.0 * s * s};
    } else {
      const double s = (i - 199) / 200.0;
      p = Eigen::Vector3d(100.0, 0.0, 15.0) + s * Eigen::Vector3d(-20.0, 60.0, 10.0);
    }
    for (int c = 0; c < 3; ++c) p[c] += 0.1 * gaussian(rng);
    stroke.points.row(i) = p.transpose();
  }
  return stroke;
}

}  // namespace

int main() {
  try {
    const Stroke stroke = drawn_stroke();
    FitOptions options;
    options.tolerance_mm = 0.3;  // three times the noise

    const auto t0 = std::chrono::steady_clock::now();
    const StrokeFit fit = fit_stroke(stroke, options);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

    std::printf("stroke: %ld points, %.1f mm long\n", static_cast<long>(stroke.points.rows()),
                length(stroke));
    std::printf("corners at points:");
    for (auto c : fit.corners) std::printf(" %ld", static_cast<long>(c));
    std::printf("\n");
    for (size_t k = 0; k < fit.curves.size(); ++k) {
      const FittedCurve& c = fit.curves[k];
      std::printf("curve %zu: points %ld..%ld, degree %d, %d control points%s\n", k,
                  static_cast<long>(c.first_point), static_cast<long>(c.last_point),
                  c.curve.basis.degree, c.control_points, c.closed ? ", closed" : "");
      std::printf("  max deviation %.3f mm, rms %.3f mm, noise %.3f mm, fairness %.0e\n",
                  c.max_deviation_mm, c.rms_deviation_mm, c.noise, c.fairness);
      std::printf("  %s\n", c.summary.brief().c_str());
    }
    std::printf("fit: %s (%.1f ms)\n", fit.summary.brief().c_str(), ms);
    return fit.summary.converged() && fit.curves.size() == 2 ? 0 : 1;
  } catch (const clay::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
