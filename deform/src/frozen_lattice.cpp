// Fast FFD evaluation: power-basis coefficients per Bézier cell and nested Horner evaluation
// (Güdükbay–Özgüç 1990 §3.2) on blocks of W points in structure-of-arrays form. The block loops
// are written so that GCC vectorizes them across the W points with the coefficients broadcast;
// the hot functions are compiled three times (AVX-512, AVX2+FMA, baseline x86-64) and the best
// one is picked at load time (target_clones, an ifunc), so the library stays portable.
#include <clay/deform/frozen_lattice.hpp>

#include <clay/error.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "bernstein.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define CLAY_DEFORM_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define CLAY_DEFORM_CLONES
#endif

namespace clay::deform {

namespace {

constexpr int W = 8;                      // points per block (one AVX-512 register of doubles)
constexpr std::size_t chunk_points = 8192;  // B-spline lattices: points sorted by cell at a time
constexpr std::size_t min_points_per_thread = 16384;

/// Everything the kernels read, as plain pointers and numbers.
struct Kernel {
  double origin[3];
  double dual[3][3];  // row d: the vector whose dot product with X − X0 is local coordinate d
  double center[3];
  int deg[3];
  int cells[3];
  bool uniform[3];
  const double* breaks[3];
  const double* inverse_width[3];
  const double* coef;     // per cell: 3 coordinates x (l+1)(m+1)(n+1) power coefficients
  std::size_t cell_size;  // doubles per cell
  int cell_count;
};

/// Input and output points: coordinate d of point i at in[d][i * stride].
struct Io {
  const double* in[3];
  double* out[3];
};

/// Per-thread scratch of the B-spline path (allocated once per call, never per point).
struct Scratch {
  std::vector<double> s, t, u;
  std::vector<std::int32_t> cell, order, count;
};

// ---- block kernels (always inlined into the cloned drivers below) ---------------------------

template <int Stride>
[[gnu::always_inline]] inline void load_block(const Io& io, std::size_t first, double* x, double* y,
                                              double* z) {
  for (int q = 0; q < W; ++q) {
    x[q] = io.in[0][(first + q) * Stride];
    y[q] = io.in[1][(first + q) * Stride];
    z[q] = io.in[2][(first + q) * Stride];
  }
}

/// Local coordinates (eq. (1) through the dual vectors), clamped to [0, 1]; inside flags.
[[gnu::always_inline]] inline void local_block(const Kernel& K, const double* x, const double* y,
                                               const double* z, double* s, double* t, double* u,
                                               int* in) {
  constexpr double lo = -face_tolerance, hi = 1 + face_tolerance;
  for (int q = 0; q < W; ++q) {
    const double dx = x[q] - K.origin[0], dy = y[q] - K.origin[1], dz = z[q] - K.origin[2];
    const double ls = K.dual[0][0] * dx + K.dual[0][1] * dy + K.dual[0][2] * dz;
    const double lt = K.dual[1][0] * dx + K.dual[1][1] * dy + K.dual[1][2] * dz;
    const double lu = K.dual[2][0] * dx + K.dual[2][1] * dy + K.dual[2][2] * dz;
    in[q] = (ls >= lo) & (ls <= hi) & (lt >= lo) & (lt <= hi) & (lu >= lo) & (lu <= hi);
    s[q] = ls < 0 ? 0.0 : (ls > 1 ? 1.0 : ls);
    t[q] = lt < 0 ? 0.0 : (lt > 1 ? 1.0 : lt);
    u[q] = lu < 0 ? 0.0 : (lu > 1 ? 1.0 : lu);
  }
}

/// Nested Horner in u, t, s of the three coordinate polynomials of one cell; r[c * W + q].
/// L, M, N >= 0 fix the degrees at compile time (fully unrolled); -1 reads them from K.
template <int L, int M, int N>
[[gnu::always_inline]] inline void horner_block(const Kernel& K, const double* coef, const double* s,
                                                const double* t, const double* u, double* r) {
  const int l = L >= 0 ? L : K.deg[0];
  const int m = M >= 0 ? M : K.deg[1];
  const int n = N >= 0 ? N : K.deg[2];
  const int Q = m + 1, R = n + 1;
  const int per_coordinate = (l + 1) * Q * R;
  for (int c = 0; c < 3; ++c) {
    const double* a = coef + c * per_coordinate;
    double as[W];
    for (int q = 0; q < W; ++q) as[q] = 0;
    for (int i = l; i >= 0; --i) {
      double at[W];
      for (int q = 0; q < W; ++q) at[q] = 0;
      for (int j = m; j >= 0; --j) {
        const double* ak = a + (i * Q + j) * R;
        double au[W];
        for (int q = 0; q < W; ++q) au[q] = ak[n];
        for (int k = n - 1; k >= 0; --k)
          for (int q = 0; q < W; ++q) au[q] = au[q] * u[q] + ak[k];
        for (int q = 0; q < W; ++q) at[q] = at[q] * t[q] + au[q];
      }
      for (int q = 0; q < W; ++q) as[q] = as[q] * s[q] + at[q];
    }
    for (int q = 0; q < W; ++q) r[c * W + q] = as[q] + K.center[c];
  }
}

// ---- Bézier lattice: one cell, no sorting ---------------------------------------------------

template <int L, int M, int N, int Stride>
[[gnu::always_inline]] inline void bezier_range(const Kernel& K, const Io& io, std::size_t begin,
                                                std::size_t end) {
  alignas(64) double x[W], y[W], z[W], s[W], t[W], u[W], r[3 * W];
  alignas(64) int in[W];
  for (std::size_t b = begin; b < end; b += W) {
    const std::size_t count = std::min<std::size_t>(W, end - b);
    if (count == W) {
      load_block<Stride>(io, b, x, y, z);
    } else {  // tail: pad with the last point (valid data, results discarded)
      for (int q = 0; q < W; ++q) {
        const std::size_t i = b + std::min<std::size_t>(static_cast<std::size_t>(q), count - 1);
        x[q] = io.in[0][i * Stride];
        y[q] = io.in[1][i * Stride];
        z[q] = io.in[2][i * Stride];
      }
    }
    local_block(K, x, y, z, s, t, u, in);
    horner_block<L, M, N>(K, K.coef, s, t, u, r);
    if (count == W) {
      for (int q = 0; q < W; ++q) {
        io.out[0][(b + q) * Stride] = in[q] ? r[q] : x[q];
        io.out[1][(b + q) * Stride] = in[q] ? r[W + q] : y[q];
        io.out[2][(b + q) * Stride] = in[q] ? r[2 * W + q] : z[q];
      }
    } else {
      for (std::size_t q = 0; q < count; ++q) {
        io.out[0][(b + q) * Stride] = in[q] ? r[q] : x[q];
        io.out[1][(b + q) * Stride] = in[q] ? r[W + q] : y[q];
        io.out[2][(b + q) * Stride] = in[q] ? r[2 * W + q] : z[q];
      }
    }
  }
}

// ---- B-spline lattice: per chunk, a counting sort by cell, then blocks of one cell -----------

/// Cell index along direction d and the local coordinate inside the cell.
[[gnu::always_inline]] inline int cell_of(const Kernel& K, int d, double v, double& local) {
  const int n = K.cells[d];
  int c;
  if (K.uniform[d]) {
    const double f = v * n;
    c = std::min(static_cast<int>(f), n - 1);
    local = f - c;
    return c;
  }
  const double* br = K.breaks[d];
  c = static_cast<int>(std::upper_bound(br + 1, br + n, v) - (br + 1));
  local = (v - br[c]) * K.inverse_width[d][c];
  return c;
}

template <int L, int M, int N, int Stride>
[[gnu::always_inline]] inline void bspline_range(const Kernel& K, const Io& io, std::size_t begin,
                                                 std::size_t end, Scratch& sc) {
  alignas(64) double x[W], y[W], z[W], s[W], t[W], u[W], r[3 * W];
  alignas(64) int in[W];
  double* S = sc.s.data();
  double* T = sc.t.data();
  double* U = sc.u.data();
  std::int32_t* cell = sc.cell.data();
  std::int32_t* order = sc.order.data();
  std::int32_t* count = sc.count.data();  // cell_count + 2 entries
  const int outside = K.cell_count;
  for (std::size_t c0 = begin; c0 < end; c0 += chunk_points) {
    const std::size_t n = std::min(chunk_points, end - c0);
    // 1. Local coordinates (vectorized) and cells.
    for (std::size_t b = 0; b < n; b += W) {
      const std::size_t cnt = std::min<std::size_t>(W, n - b);
      for (int q = 0; q < W; ++q) {
        const std::size_t i = c0 + b + std::min<std::size_t>(static_cast<std::size_t>(q), cnt - 1);
        x[q] = io.in[0][i * Stride];
        y[q] = io.in[1][i * Stride];
        z[q] = io.in[2][i * Stride];
      }
      local_block(K, x, y, z, s, t, u, in);
      for (std::size_t q = 0; q < cnt; ++q) {
        double ls, lt, lu;
        const int a = cell_of(K, 0, s[q], ls);
        const int bb = cell_of(K, 1, t[q], lt);
        const int cc = cell_of(K, 2, u[q], lu);
        S[b + q] = ls;
        T[b + q] = lt;
        U[b + q] = lu;
        cell[b + q] = in[q] ? (a * K.cells[1] + bb) * K.cells[2] + cc : outside;
      }
    }
    // 2. Counting sort of the chunk's points by cell.
    std::fill(count, count + outside + 2, 0);
    for (std::size_t i = 0; i < n; ++i) ++count[cell[i] + 1];
    for (int c = 0; c <= outside; ++c) count[c + 1] += count[c];  // count[c] = start of cell c
    for (std::size_t i = 0; i < n; ++i) order[count[cell[i]]++] = static_cast<std::int32_t>(i);
    // Now count[c] = end of cell c = start of cell c + 1.
    // 3. Blocks of one cell: coefficients broadcast, coordinates gathered, results scattered.
    int start = 0;
    for (int c = 0; c < outside; ++c) {
      const int stop = count[c];
      const double* coef = K.coef + static_cast<std::size_t>(c) * K.cell_size;
      for (int b = start; b < stop; b += W) {
        const int cnt = std::min(W, stop - b);
        for (int q = 0; q < W; ++q) {
          const std::int32_t i = order[b + std::min(q, cnt - 1)];
          s[q] = S[i];
          t[q] = T[i];
          u[q] = U[i];
        }
        horner_block<L, M, N>(K, coef, s, t, u, r);
        for (int q = 0; q < cnt; ++q) {
          const std::size_t i = c0 + static_cast<std::size_t>(order[b + q]);
          io.out[0][i * Stride] = r[q];
          io.out[1][i * Stride] = r[W + q];
          io.out[2][i * Stride] = r[2 * W + q];
        }
      }
      start = stop;
    }
    // 4. Points outside the lattice are copied unchanged.
    for (int b = start; b < count[outside]; ++b) {
      const std::size_t i = c0 + static_cast<std::size_t>(order[b]);
      for (int d = 0; d < 3; ++d) io.out[d][i * Stride] = io.in[d][i * Stride];
    }
  }
}

// ---- drivers: compiled per instruction set, chosen at load time ------------------------------

template <int Stride>
[[gnu::always_inline]] inline void bezier_dispatch(const Kernel& K, const Io& io, std::size_t b,
                                                   std::size_t e) {
  const int l = K.deg[0], m = K.deg[1], n = K.deg[2];
  if (l == 3 && m == 3 && n == 3) return bezier_range<3, 3, 3, Stride>(K, io, b, e);
  if (l == 2 && m == 2 && n == 2) return bezier_range<2, 2, 2, Stride>(K, io, b, e);
  if (l == 1 && m == 1 && n == 1) return bezier_range<1, 1, 1, Stride>(K, io, b, e);
  return bezier_range<-1, -1, -1, Stride>(K, io, b, e);
}

template <int Stride>
[[gnu::always_inline]] inline void bspline_dispatch(const Kernel& K, const Io& io, std::size_t b,
                                                    std::size_t e, Scratch& sc) {
  const int l = K.deg[0], m = K.deg[1], n = K.deg[2];
  if (l == 3 && m == 3 && n == 3) return bspline_range<3, 3, 3, Stride>(K, io, b, e, sc);
  if (l == 2 && m == 2 && n == 2) return bspline_range<2, 2, 2, Stride>(K, io, b, e, sc);
  if (l == 1 && m == 1 && n == 1) return bspline_range<1, 1, 1, Stride>(K, io, b, e, sc);
  return bspline_range<-1, -1, -1, Stride>(K, io, b, e, sc);
}

CLAY_DEFORM_CLONES void run_bezier_rows(const Kernel& K, const Io& io, std::size_t b, std::size_t e) {
  bezier_dispatch<3>(K, io, b, e);
}
CLAY_DEFORM_CLONES void run_bezier_columns(const Kernel& K, const Io& io, std::size_t b,
                                           std::size_t e) {
  bezier_dispatch<1>(K, io, b, e);
}
CLAY_DEFORM_CLONES void run_bspline_rows(const Kernel& K, const Io& io, std::size_t b, std::size_t e,
                                         Scratch& sc) {
  bspline_dispatch<3>(K, io, b, e, sc);
}
CLAY_DEFORM_CLONES void run_bspline_columns(const Kernel& K, const Io& io, std::size_t b,
                                            std::size_t e, Scratch& sc) {
  bspline_dispatch<1>(K, io, b, e, sc);
}

}  // namespace

// ---- FrozenLattice ----------------------------------------------------------------------------

struct FrozenLatticeAccess {
  static Kernel kernel(const FrozenLattice& f) {
    Kernel K{};
    for (int d = 0; d < 3; ++d) {
      K.origin[d] = f.frame_.origin[d];
      K.center[d] = f.center_[d];
      for (int e = 0; e < 3; ++e) K.dual[d][e] = f.dual_[static_cast<size_t>(d)][e];
      K.deg[d] = f.degrees_[static_cast<size_t>(d)];
      K.cells[d] = static_cast<int>(f.breaks_[static_cast<size_t>(d)].size()) - 1;
      K.uniform[d] = f.uniform_[static_cast<size_t>(d)];
      K.breaks[d] = f.breaks_[static_cast<size_t>(d)].data();
      K.inverse_width[d] = f.inverse_width_[static_cast<size_t>(d)].data();
    }
    K.coef = f.coefficients_.data();
    K.cell_size = 3 * static_cast<std::size_t>(K.deg[0] + 1) * (K.deg[1] + 1) * (K.deg[2] + 1);
    K.cell_count = K.cells[0] * K.cells[1] * K.cells[2];
    return K;
  }

  /// Sets the frame data and appends the power coefficients of one Bézier cell.
  static void set_frame(FrozenLattice& f, const Frame& frame) {
    f.frame_ = frame;
    const Eigen::Vector3d tu = frame.t.cross(frame.u), us = frame.u.cross(frame.s),
                          st = frame.s.cross(frame.t);
    f.dual_ = {tu / tu.dot(frame.s), us / us.dot(frame.t), st / st.dot(frame.u)};
    f.center_ = frame.point(0.5, 0.5, 0.5);
  }
  static void add_cell(FrozenLattice& f, const Points3& bezier_points) {
    const auto& deg = f.degrees_;
    const size_t per = static_cast<size_t>(bezier_points.rows());
    std::vector<double> b(per * 3);
    for (size_t r = 0; r < per; ++r)
      for (int c = 0; c < 3; ++c)
        b[r * 3 + static_cast<size_t>(c)] = bezier_points(static_cast<Eigen::Index>(r), c) - f.center_[c];
    const std::vector<double> a = detail::bernstein_to_power(b, deg, 3);
    // Kernel layout: coordinate-major, then s-major coefficient index.
    for (int c = 0; c < 3; ++c)
      for (size_t r = 0; r < per; ++r) f.coefficients_.push_back(a[r * 3 + static_cast<size_t>(c)]);
  }
  static void set_breaks(FrozenLattice& f, int d, std::vector<double> breaks) {
    const size_t n = breaks.size() - 1;
    auto& inv = f.inverse_width_[static_cast<size_t>(d)];
    inv.resize(n);
    bool uniform = true;
    for (size_t c = 0; c < n; ++c) {
      inv[c] = 1.0 / (breaks[c + 1] - breaks[c]);
      const double expected = static_cast<double>(c) / static_cast<double>(n);
      if (std::abs(breaks[c] - expected) > 4e-16) uniform = false;
    }
    f.uniform_[static_cast<size_t>(d)] = uniform;
    f.breaks_[static_cast<size_t>(d)] = std::move(breaks);
  }
};

FrozenLattice::FrozenLattice(const BezierLattice& lattice) {
  validate(lattice);
  FrozenLatticeAccess::set_frame(*this, lattice.frame);
  degrees_ = lattice.degrees;
  for (int d = 0; d < 3; ++d) FrozenLatticeAccess::set_breaks(*this, d, {0.0, 1.0});
  FrozenLatticeAccess::add_cell(*this, lattice.points);
}

FrozenLattice::FrozenLattice(const BSplineLattice& lattice) {
  validate(lattice);
  FrozenLatticeAccess::set_frame(*this, lattice.frame);
  degrees_ = {lattice.bases[0].degree, lattice.bases[1].degree, lattice.bases[2].degree};
  std::array<std::vector<detail::SpanExtraction>, 3> spans;
  for (int d = 0; d < 3; ++d) {
    spans[static_cast<size_t>(d)] = detail::extract_spans(lattice.bases[static_cast<size_t>(d)]);
    std::vector<double> breaks;
    for (const auto& e : spans[static_cast<size_t>(d)]) breaks.push_back(e.a);
    breaks.push_back(spans[static_cast<size_t>(d)].back().b);
    FrozenLatticeAccess::set_breaks(*this, d, std::move(breaks));
  }
  for (const auto& ea : spans[0])
    for (const auto& eb : spans[1])
      for (const auto& ec : spans[2])
        FrozenLatticeAccess::add_cell(*this, detail::cell_points(lattice, ea, eb, ec));
}

namespace {

void run(const FrozenLattice& lattice, const Io& io, std::size_t n, bool rows,
         const DeformOptions& options) {
  options.validate();
  const Kernel K = FrozenLatticeAccess::kernel(lattice);
  const bool bezier = K.cell_count == 1;
  std::size_t threads = options.threads > 0 ? static_cast<std::size_t>(options.threads)
                                            : std::max(1u, std::thread::hardware_concurrency());
  threads = std::max<std::size_t>(1, std::min(threads, n / min_points_per_thread));
  std::vector<Scratch> scratch(bezier ? 0 : threads);
  for (auto& sc : scratch) {
    const std::size_t c = std::min(chunk_points, n);
    sc.s.resize(c);
    sc.t.resize(c);
    sc.u.resize(c);
    sc.cell.resize(c);
    sc.order.resize(c);
    sc.count.resize(static_cast<std::size_t>(K.cell_count) + 2);
  }
  auto work = [&](std::size_t part) {
    // Contiguous ranges, block-aligned.
    const std::size_t blocks = (n + W - 1) / W;
    const std::size_t b = std::min(n, blocks * part / threads * W);
    const std::size_t e = std::min(n, blocks * (part + 1) / threads * W);
    if (b >= e) return;
    if (bezier) {
      if (rows) run_bezier_rows(K, io, b, e);
      else run_bezier_columns(K, io, b, e);
    } else {
      if (rows) run_bspline_rows(K, io, b, e, scratch[part]);
      else run_bspline_columns(K, io, b, e, scratch[part]);
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (std::size_t part = 1; part < threads; ++part) pool.emplace_back(work, part);
  work(0);
  for (auto& th : pool) th.join();
}

}  // namespace

Eigen::Vector3d deform_point(const FrozenLattice& lattice, const Eigen::Vector3d& x) {
  Eigen::Vector3d out;
  const Io io{{&x[0], &x[1], &x[2]}, {&out[0], &out[1], &out[2]}};
  run(lattice, io, 1, false, DeformOptions{1});
  return out;
}

Points3 deform_points(const FrozenLattice& lattice, const Points3& points,
                      const DeformOptions& options) {
  Points3 out(points.rows(), 3);
  const double* in = points.data();
  double* o = out.data();
  run(lattice, Io{{in, in + 1, in + 2}, {o, o + 1, o + 2}}, static_cast<std::size_t>(points.rows()),
      true, options);
  return out;
}

void deform_points(const FrozenLattice& lattice, PointColumns in, MutablePointColumns out,
                   const DeformOptions& options) {
  const std::size_t n = in.x.size();
  if (in.y.size() != n || in.z.size() != n || out.x.size() != n || out.y.size() != n ||
      out.z.size() != n)
    throw Error(ErrorCategory::InvalidArgument,
                "deform_points: point columns of sizes in " + std::to_string(in.x.size()) + "/" +
                    std::to_string(in.y.size()) + "/" + std::to_string(in.z.size()) + ", out " +
                    std::to_string(out.x.size()) + "/" + std::to_string(out.y.size()) + "/" +
                    std::to_string(out.z.size()) + "; give six columns of the same size");
  run(lattice, Io{{in.x.data(), in.y.data(), in.z.data()}, {out.x.data(), out.y.data(), out.z.data()}},
      n, false, options);
}

Points3 deform_points(const BezierLattice& lattice, const Points3& points,
                      const DeformOptions& options) {
  options.validate();
  return deform_points(FrozenLattice(lattice), points, options);
}

Points3 deform_points(const BSplineLattice& lattice, const Points3& points,
                      const DeformOptions& options) {
  options.validate();
  return deform_points(FrozenLattice(lattice), points, options);
}

}  // namespace clay::deform
