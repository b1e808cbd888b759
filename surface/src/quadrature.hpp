#pragma once
// Gauss–Legendre quadrature (internal): arc lengths in the sweep's path table and the
// self-intersection search.
#include <array>
#include <cstddef>

namespace clay::surface::detail {

/// 8-point Gauss–Legendre nodes and weights on [-1, 1].
inline constexpr std::array<double, 8> gauss_x = {
    -0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
    0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
inline constexpr std::array<double, 8> gauss_w = {
    0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
    0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

/// The integral of f over [a, b] by the 8-point Gauss–Legendre rule (exact for degree 15).
template <class F>
double gauss_legendre_8(double a, double b, F f) {
  double sum = 0;
  for (size_t g = 0; g < gauss_x.size(); ++g)
    sum += gauss_w[g] * f(0.5 * (a + b) + 0.5 * (b - a) * gauss_x[g]);
  return 0.5 * (b - a) * sum;
}

}  // namespace clay::surface::detail
