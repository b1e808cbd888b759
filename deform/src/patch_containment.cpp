// Containment of a composed patch in a lattice cell (patch_containment.hpp): a maximum search
// on the Bernstein form, certified by subdivision and the convex hull property.
#include "patch_containment.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <utility>
#include <vector>

namespace clay::deform::detail {

namespace {

/// g with its first and second partial derivatives, for the maximum search on one cell.
struct Derivatives {
  Poly g, gx, gy, gxx, gxy, gyy;
  explicit Derivatives(Poly g_)
      : g(std::move(g_)),
        gx(derivative(g, 0)),
        gy(derivative(g, 1)),
        gxx(derivative(gx, 0)),
        gxy(derivative(gx, 1)),
        gyy(derivative(gy, 1)) {}
};

/// A local maximiser of g on [0, 1]^2 (projected Newton with an active set, from the Greville
/// point of the largest coefficient). Only the tightness of the certificate below depends on it.
std::pair<double, double> maximiser(const Derivatives& d) {
  const Poly& g = d.g;
  size_t best = 0;
  for (size_t k = 1; k < g.c.size(); ++k)
    if (g.c[k] > g.c[best]) best = k;
  const int bi = static_cast<int>(best) / (g.dv + 1), bj = static_cast<int>(best) % (g.dv + 1);
  double x = g.du > 0 ? static_cast<double>(bi) / g.du : 0.5,
         y = g.dv > 0 ? static_cast<double>(bj) / g.dv : 0.5;
  for (int it = 0; it < 40; ++it) {
    const double gx = value_at(d.gx, x, y), gy = value_at(d.gy, x, y);
    const double gxx = value_at(d.gxx, x, y), gxy = value_at(d.gxy, x, y),
                 gyy = value_at(d.gyy, x, y);
    // A coordinate on the cell's edge whose gradient points out of the cell stays there.
    const bool free_x = g.du > 0 && !((x <= 0 && gx < 0) || (x >= 1 && gx > 0));
    const bool free_y = g.dv > 0 && !((y <= 0 && gy < 0) || (y >= 1 && gy > 0));
    double sx = 0, sy = 0;
    if (free_x && free_y) {
      const double det = gxx * gyy - gxy * gxy;
      if (!(gxx < 0 && det > 0)) break;  // not concave here: the subdivision decides
      sx = -(gyy * gx - gxy * gy) / det;
      sy = -(gxx * gy - gxy * gx) / det;
    } else if (free_x) {
      if (!(gxx < 0)) break;
      sx = -gx / gxx;
    } else if (free_y) {
      if (!(gyy < 0)) break;
      sy = -gy / gyy;
    } else {
      break;
    }
    const double nx = std::clamp(x + sx, 0.0, 1.0), ny = std::clamp(y + sy, 0.0, 1.0);
    const double moved = std::abs(nx - x) + std::abs(ny - y);
    x = nx, y = ny;
    if (moved <= 1e-15) break;
  }
  return {x, y};
}

enum class Verdict { inside, outside, undecided };

/// Decides g <= 0 on [0, 1]^2 for a dim-1 Bernstein poly g, or finds a point with g > 0:
/// - inside when every coefficient is <= 0 (convex hull);
/// - outside at a point (a corner, or a maximiser) where g > 0;
/// - inside when g is certified concave on the cell (∂xx g <= A <= 0, ∂yy g <= B <= 0,
///   |∂xy g| <= C with C^2 <= A B, from the coefficients of the second derivatives: the Hessian
///   is negative semidefinite everywhere) and its tangent plane at the maximiser x*, an upper
///   bound of a concave function, stays <= 0 at the four corners: g(x) <= g(x*) + ∇g(x*)·(x − x*).
///   This decides a surface that touches the plane (true maximum exactly on it), where the convex
///   hull only approaches the maximum as the cell shrinks;
/// - undecided otherwise: subdivide.
Verdict decide(const Poly& g, double& px, double& py) {
  if (max_coefficient(g) <= 0) return Verdict::inside;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      if (g.at(a ? g.du : 0, b ? g.dv : 0) > 0) {
        px = a, py = b;
        return Verdict::outside;
      }
  const Derivatives d(g);
  const auto [x, y] = maximiser(d);
  const double top = value_at(g, x, y);
  if (top > 0) {
    px = x, py = y;
    return Verdict::outside;
  }
  const double A = max_coefficient(d.gxx), B = max_coefficient(d.gyy),
               C = max_abs_coefficient(d.gxy);
  if (A <= 0 && B <= 0 && C * C <= A * B) {
    const double gx = value_at(d.gx, x, y), gy = value_at(d.gy, x, y);
    double bound = -std::numeric_limits<double>::infinity();
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) bound = std::max(bound, top + gx * (a - x) + gy * (b - y));
    if (bound <= 0) return Verdict::inside;
  }
  return Verdict::undecided;
}

}  // namespace

std::optional<Violation> leaves(const Poly& cw, double lo, double hi, double tol) {
  constexpr int max_depth = 48;
  constexpr int budget = 2048;
  std::optional<Violation> undecided;
  for (int side = 0; side < 2; ++side) {
    const double limit = side == 0 ? hi + tol : lo - tol;
    struct Cell {
      Poly cw;
      double x0, x1, y0, y1;
      int depth;
    };
    // Breadth first: a clear violation in one cell is found before the budget goes on refining a
    // near-touch in another.
    std::deque<Cell> queue{{cw, 0, 1, 0, 1, 0}};
    int visited = 0;
    while (!queue.empty()) {
      Cell cell = std::move(queue.front());
      queue.pop_front();
      Poly g(cell.cw.du, cell.cw.dv, 1);
      for (int i = 0; i <= g.du; ++i)
        for (int j = 0; j <= g.dv; ++j) {
          const double c = cell.cw.at(i, j, 0), w = cell.cw.at(i, j, 1);
          g.at(i, j) = side == 0 ? c - limit * w : limit * w - c;
        }
      double px = 0, py = 0;
      const Verdict v = decide(g, px, py);
      if (v == Verdict::inside) continue;
      if (v == Verdict::outside) {
        const double value = value_at(cell.cw, px, py, 0) / value_at(cell.cw, px, py, 1);
        return Violation{cell.x0 + px * (cell.x1 - cell.x0), cell.y0 + py * (cell.y1 - cell.y0),
                         value, true};
      }
      if (cell.depth >= max_depth || ++visited > budget) {
        if (!undecided) {
          double bound = side == 0 ? -std::numeric_limits<double>::infinity()
                                   : std::numeric_limits<double>::infinity();
          for (int i = 0; i <= g.du; ++i)
            for (int j = 0; j <= g.dv; ++j) {
              const double r = cell.cw.at(i, j, 0) / cell.cw.at(i, j, 1);
              bound = side == 0 ? std::max(bound, r) : std::min(bound, r);
            }
          undecided = Violation{0.5 * (cell.x0 + cell.x1), 0.5 * (cell.y0 + cell.y1), bound, false};
        }
        if (visited > budget) break;
        continue;
      }
      const double xm = 0.5 * (cell.x0 + cell.x1), ym = 0.5 * (cell.y0 + cell.y1);
      auto [left, right] = halve(cell.cw, 0);
      for (int a = 0; a < 2; ++a) {
        auto [bottom, top] = halve(a ? right : left, 1);
        queue.push_back(
            {std::move(bottom), a ? xm : cell.x0, a ? cell.x1 : xm, cell.y0, ym, cell.depth + 1});
        queue.push_back(
            {std::move(top), a ? xm : cell.x0, a ? cell.x1 : xm, ym, cell.y1, cell.depth + 1});
      }
    }
  }
  return undecided;
}

}  // namespace clay::deform::detail
