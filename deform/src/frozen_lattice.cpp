// Fast FFD evaluation: power-basis coefficients per Bézier cell and nested Horner evaluation
// (Güdükbay–Özgüç 1990 §3.2) on blocks of W points in structure-of-arrays form. The block loops
// are written so that GCC vectorizes them across the W points with the coefficients broadcast;
// the hot functions are compiled three times (AVX-512, AVX2+FMA, baseline x86-64) and the best
// one is picked at load time (target_clones, an ifunc), so the library stays portable.
#include <clay/deform/frozen_lattice.hpp>

#include <clay/error.hpp>
#include <clay/internal/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "bernstein.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define CLAY_DEFORM_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define CLAY_DEFORM_CLONES
#endif

// Hides a value's origin from the optimizer (see the B-spline evaluation loop).
#if defined(__GNUC__)
#define CLAY_OPAQUE(x) asm("" : "+r"(x))
#else
#define CLAY_OPAQUE(x) (void)(x)
#endif

namespace clay::deform {

namespace {

constexpr int W = 8;  // points per block (one AVX-512 register of doubles)
// B-spline lattices: points sorted by cell at a time. 32 bytes of scratch per point, 1 MB per
// worker, in a 2 MB L2; with 8 x 8 x 8 cells about 64 points per cell, so the partly filled last
// block of each cell wastes about 5 % of the evaluation (11 % at 16,384; 65,536 spills L2 and
// was slower).
constexpr std::size_t chunk_points = 32768;
constexpr std::size_t min_points_per_thread = 16384;

/// Everything the kernels read, as plain pointers and numbers.
struct Kernel {
  double origin[3];
  double dual[3][3];  // row d: the vector whose dot product with X − X0 is local coordinate d
  double center[3];
  int deg[3];
  int cells[3];
  bool uniform[3];
  bool all_uniform;  // uniform[0] && uniform[1] && uniform[2]
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
//
// A block is W = 8 points held in GCC vector-extension values (one zmm register under AVX-512,
// two ymm under AVX2, four xmm otherwise); scalars in arithmetic with them are broadcast. Vectors
// are passed by reference only (no vector in a function's ABI).

using vd = double __attribute__((vector_size(W * sizeof(double))));
using vi = long long __attribute__((vector_size(W * sizeof(long long))));
using vi32 = std::int32_t __attribute__((vector_size(W * sizeof(std::int32_t))));

// Lanes of a then b picked by constant indices: GCC's __builtin_shuffle takes the indices as a
// vector, Clang has only __builtin_shufflevector (the same meaning, the indices as arguments).
#if defined(__clang__)
#define CLAY_SHUFFLE(a, b, ...) __builtin_shufflevector(a, b, __VA_ARGS__)
#else
#define CLAY_SHUFFLE(a, b, ...) __builtin_shuffle(a, b, vi{__VA_ARGS__})
#endif

[[gnu::always_inline]] inline void load(vd& v, const double* p) { std::memcpy(&v, p, sizeof v); }

[[gnu::always_inline]] inline void store(double* p, const vd& v) { std::memcpy(p, &v, sizeof v); }

/// x, y, z of 8 consecutive points from 24 doubles stored x0 y0 z0 x1 y1 z1 ... (row-major N x 3).
[[gnu::always_inline]] inline void load_rows(const double* p, vd& x, vd& y, vd& z) {
  vd a, b, c;
  load(a, p);
  load(b, p + W);
  load(c, p + 2 * W);
  x = CLAY_SHUFFLE(CLAY_SHUFFLE(a, b, 0, 3, 6, 9, 12, 15, 0, 0), c, 0, 1, 2, 3, 4, 5, 10, 13);
  y = CLAY_SHUFFLE(CLAY_SHUFFLE(a, b, 1, 4, 7, 10, 13, 0, 0, 0), c, 0, 1, 2, 3, 4, 8, 11, 14);
  z = CLAY_SHUFFLE(CLAY_SHUFFLE(a, b, 2, 5, 8, 11, 14, 0, 0, 0), c, 0, 1, 2, 3, 4, 9, 12, 15);
}

/// The inverse of load_rows.
[[gnu::always_inline]] inline void store_rows(double* p, const vd& x, const vd& y, const vd& z) {
  // a = x0 y0 z0 x1 y1 z1 x2 y2, b = z2 x3 y3 z3 x4 y4 z4 x5, c = y5 z5 x6 y6 z6 x7 y7 z7
  const vd xy = CLAY_SHUFFLE(x, y, 0, 8, 0, 1, 9, 0, 2, 10);
  const vd a = CLAY_SHUFFLE(xy, z, 0, 1, 8, 3, 4, 9, 6, 7);
  const vd zx = CLAY_SHUFFLE(z, x, 2, 11, 0, 3, 12, 0, 4, 13);
  const vd b = CLAY_SHUFFLE(zx, y, 0, 1, 11, 3, 4, 12, 6, 7);
  const vd yz = CLAY_SHUFFLE(y, z, 5, 13, 0, 6, 14, 0, 7, 15);
  const vd c = CLAY_SHUFFLE(yz, x, 0, 1, 14, 3, 4, 15, 6, 7);
  store(p, a);
  store(p + W, b);
  store(p + 2 * W, c);
}

/// Points ahead of the block being computed whose input is prefetched (hardware prefetchers
/// lag behind on six streams).
constexpr std::size_t prefetch_distance = 64;

template <int Stride>
[[gnu::always_inline]] inline void prefetch_block(const Io& io, std::size_t first) {
  if constexpr (Stride == 3) {
    __builtin_prefetch(io.in[0] + first * 3);
    __builtin_prefetch(io.in[0] + first * 3 + W);
    __builtin_prefetch(io.in[0] + first * 3 + 2 * W);
  } else {
    __builtin_prefetch(io.in[0] + first);
    __builtin_prefetch(io.in[1] + first);
    __builtin_prefetch(io.in[2] + first);
  }
}

/// Output of a block ahead, fetched for writing (the stores then do not wait for the lines).
template <int Stride>
[[gnu::always_inline]] inline void prefetch_output(const Io& io, std::size_t first) {
  if constexpr (Stride == 3) {
    __builtin_prefetch(io.out[0] + first * 3, 1);
    __builtin_prefetch(io.out[0] + first * 3 + W, 1);
    __builtin_prefetch(io.out[0] + first * 3 + 2 * W, 1);
  } else {
    __builtin_prefetch(io.out[0] + first, 1);
    __builtin_prefetch(io.out[1] + first, 1);
    __builtin_prefetch(io.out[2] + first, 1);
  }
}

/// Loads block [first, first + 8) (Stride 3: rows, 1: columns).
template <int Stride>
[[gnu::always_inline]] inline void load_block(const Io& io, std::size_t first, vd& x, vd& y,
                                              vd& z) {
  if constexpr (Stride == 3) {
    load_rows(io.in[0] + first * 3, x, y, z);
  } else {
    load(x, io.in[0] + first);
    load(y, io.in[1] + first);
    load(z, io.in[2] + first);
  }
}

template <int Stride>
[[gnu::always_inline]] inline void store_block(const Io& io, std::size_t first, const vd& x,
                                               const vd& y, const vd& z) {
  if constexpr (Stride == 3) {
    store_rows(io.out[0] + first * 3, x, y, z);
  } else {
    store(io.out[0] + first, x);
    store(io.out[1] + first, y);
    store(io.out[2] + first, z);
  }
}

/// Local coordinates (eq. (1) through the dual vectors), clamped to [0, 1], and how far outside
/// the unit cube the point is (|ls − s| + |lt − t| + |lu − u|: inside when <= face_tolerance,
/// outside also when NaN). One comparison per block instead of six keeps GCC on mask registers.
[[gnu::always_inline]] inline void local_block(const Kernel& K, const vd& x, const vd& y,
                                               const vd& z, vd& s, vd& t, vd& u, vd& outside) {
  const vd zero = {}, one = zero + 1.0;
  const vd dx = x - K.origin[0], dy = y - K.origin[1], dz = z - K.origin[2];
  const vd ls = K.dual[0][0] * dx + K.dual[0][1] * dy + K.dual[0][2] * dz;
  const vd lt = K.dual[1][0] * dx + K.dual[1][1] * dy + K.dual[1][2] * dz;
  const vd lu = K.dual[2][0] * dx + K.dual[2][1] * dy + K.dual[2][2] * dz;
  s = ls < zero ? zero : (ls > one ? one : ls);
  t = lt < zero ? zero : (lt > one ? one : lt);
  u = lu < zero ? zero : (lu > one ? one : lu);
  const vd ds = ls - s, dt = lt - t, du = lu - u;
  outside = (ds < zero ? -ds : ds) + (dt < zero ? -dt : dt) + (du < zero ? -du : du);
}

/// Nested Horner in u, t, s of the three coordinate polynomials of one cell, plus the center.
/// L, M, N >= 0 fix the degrees at compile time (fully unrolled); -1 reads them from K.
template <int L, int M, int N>
[[gnu::always_inline]] inline void horner_block(const Kernel& K, const double* coef, const vd& s,
                                                const vd& t, const vd& u, vd* r) {
  const int l = L >= 0 ? L : K.deg[0];
  const int m = M >= 0 ? M : K.deg[1];
  const int n = N >= 0 ? N : K.deg[2];
  const int Q = m + 1, R = n + 1;
  const int per_coordinate = (l + 1) * Q * R;
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
    const double* a = coef + c * per_coordinate;
    vd as = {};
    for (int i = l; i >= 0; --i) {
      vd at = {};
      for (int j = m; j >= 0; --j) {
        const double* ak = a + (i * Q + j) * R;
        vd au = u * ak[n] + ak[n - 1];
        for (int k = n - 2; k >= 0; --k) au = au * u + ak[k];
        at = j == m ? au : at * t + au;
      }
      as = i == l ? at : as * s + at;
    }
    r[c] = as + K.center[c];
  }
}

// ---- Bézier lattice: one cell, no sorting ---------------------------------------------------

template <int L, int M, int N, int Stride>
[[gnu::always_inline]] inline void bezier_range(const Kernel& K, const Io& io, std::size_t begin,
                                                std::size_t end) {
  vd x, y, z, s, t, u, r[3], out;
  std::size_t b = begin;
  for (; b + W <= end; b += W) {
    prefetch_block<Stride>(io, b + prefetch_distance);
    prefetch_output<Stride>(io, b + prefetch_distance);
    load_block<Stride>(io, b, x, y, z);
    local_block(K, x, y, z, s, t, u, out);
    horner_block<L, M, N>(K, K.coef, s, t, u, r);
    const vd tol = vd{} + face_tolerance;
    store_block<Stride>(io, b, out <= tol ? r[0] : x, out <= tol ? r[1] : y, out <= tol ? r[2] : z);
  }
  if (b < end) {  // tail: pad with the last point (valid data, results discarded)
    const std::size_t count = end - b;
    for (std::size_t q = 0; q < W; ++q) {
      const std::size_t i = b + std::min(q, count - 1);
      x[q] = io.in[0][i * Stride];
      y[q] = io.in[1][i * Stride];
      z[q] = io.in[2][i * Stride];
    }
    local_block(K, x, y, z, s, t, u, out);
    horner_block<L, M, N>(K, K.coef, s, t, u, r);
    for (std::size_t q = 0; q < count; ++q) {
      const bool in = out[q] <= face_tolerance;
      io.out[0][(b + q) * Stride] = in ? r[0][q] : x[q];
      io.out[1][(b + q) * Stride] = in ? r[1][q] : y[q];
      io.out[2][(b + q) * Stride] = in ? r[2][q] : z[q];
    }
  }
}

// ---- B-spline lattice: per chunk, a counting sort by cell, then blocks of one cell -----------

/// Cell index along direction d and the local coordinate inside the cell (one point).
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

/// Cells and in-cell coordinates of W points, one at a time through cell_of, for lattices whose
/// breaks are not all uniform. On entry S, T, U hold the clamped lattice coordinates and cell[q]
/// is nonzero for points inside. Out of line and scalar: inlined, its lane-by-lane access kept
/// the vectors of the uniform path in memory (four zmm spills per block in every B-spline loop).
[[gnu::noinline]] void cells_by_search(const Kernel& K, double* S, double* T, double* U,
                                       std::int32_t* cell) {
  for (int q = 0; q < W; ++q) {
    double ls, lt, lu;
    const int a = cell_of(K, 0, S[q], ls);
    const int b = cell_of(K, 1, T[q], lt);
    const int c = cell_of(K, 2, U[q], lu);
    S[q] = ls;
    T[q] = lt;
    U[q] = lu;
    cell[q] = cell[q] != 0 ? (a * K.cells[1] + b) * K.cells[2] + c : K.cell_count;
  }
}

/// Pass 1 for one block: in-cell coordinates into S, T, U and the cells into cell (input order).
/// Uniform breaks in every direction: vectorized (cell = floor(v n) by truncation, v >= 0);
/// otherwise cells_by_search. Points outside the lattice get cell K.cell_count.
[[gnu::always_inline]] inline void locate_block(const Kernel& K, const vd& x, const vd& y,
                                                const vd& z, double* S, double* T, double* U,
                                                std::int32_t* cell) {
  vd s, t, u, out;
  local_block(K, x, y, z, s, t, u, out);
  const vd tol = vd{} + face_tolerance;
  if (!K.all_uniform) {
    store(S, s);
    store(T, t);
    store(U, u);
    const vi32 inside = __builtin_convertvector(out <= tol, vi32);  // -1 inside, 0 outside
    std::memcpy(cell, &inside, sizeof inside);
    cells_by_search(K, S, T, U, cell);
    return;
  }
  const vd fs = s * K.cells[0], ft = t * K.cells[1], fu = u * K.cells[2];
  vi a = __builtin_convertvector(fs, vi), b = __builtin_convertvector(ft, vi),
     c = __builtin_convertvector(fu, vi);
  const vi la = vi{} + (K.cells[0] - 1), lb = vi{} + (K.cells[1] - 1), lc = vi{} + (K.cells[2] - 1);
  a = a > la ? la : a;
  b = b > lb ? lb : b;
  c = c > lc ? lc : c;
  store(S, fs - __builtin_convertvector(a, vd));
  store(T, ft - __builtin_convertvector(b, vd));
  store(U, fu - __builtin_convertvector(c, vd));
  // The cell number in doubles (exact: small integers), then one conversion.
  const vd id =
      (__builtin_convertvector(a, vd) * K.cells[1] + __builtin_convertvector(b, vd)) * K.cells[2] +
      __builtin_convertvector(c, vd);
  const vi32 narrow = __builtin_convertvector(
      __builtin_convertvector(out <= tol ? id : vd{} + K.cell_count, vi), vi32);
  std::memcpy(cell, &narrow, sizeof narrow);
}

/// Counting sort of a chunk's indices by cell, from the histogram count[c + 1] = points in cell
/// c; after it count[c] is the end of cell c, and W spare entries repeat the last index. Its own
/// function (scalar code, not cloned): inside the large driver its pointers were kept on the stack.
[[gnu::noinline]] void counting_sort(const std::int32_t* __restrict cell,
                                     std::int32_t* __restrict order, std::int32_t* __restrict count,
                                     std::size_t n, int outside) {
  for (int c = 0; c <= outside; ++c) count[c + 1] += count[c];  // count[c] = start of cell c
  for (std::size_t i = 0; i < n; ++i) order[count[cell[i]]++] = static_cast<std::int32_t>(i);
  for (std::size_t p = n; p < n + W; ++p) order[p] = order[n - 1];  // spare lanes
}

template <int L, int M, int N, int Stride>
[[gnu::always_inline]] inline void bspline_range(const Kernel& K, const Io& io, std::size_t begin,
                                                 std::size_t end, Scratch& sc) {
  vd x, y, z;
  // In-cell coordinates of the chunk in input order, overwritten by each point's result; cells;
  // the order sorted by cell (W spare entries for the last cell's partial block).
  // Restrict: the arrays never overlap, which lets the sort keep its pointers in registers.
  double* __restrict S = sc.s.data();
  double* __restrict T = sc.t.data();
  double* __restrict U = sc.u.data();
  std::int32_t* __restrict cell = sc.cell.data();
  std::int32_t* __restrict order = sc.order.data();
  std::int32_t* __restrict count = sc.count.data();  // cell_count + 2 entries
  const int outside = K.cell_count;
  // The two lambdas are always inlined: a lambda is not cloned per instruction set, inlined it is
  // compiled for the clone it is in.
  // 1. Local coordinates and cells of input points [first + from, first + n) into scratch
  // [from, n), a block at a time, and the histogram of cells. Whole blocks, then a tail padded
  // with the last point (only its cnt entries counted). Element access goes through arrays: on a
  // vector variable it would keep the vector in memory.
  auto locate_range = [&](std::size_t first, std::size_t from, std::size_t n)
      __attribute__((always_inline)) {
    std::size_t b = from;
    for (; b + W <= n; b += W) {
      prefetch_block<Stride>(io, first + b + prefetch_distance);
      load_block<Stride>(io, first + b, x, y, z);
      locate_block(K, x, y, z, S + b, T + b, U + b, cell + b);
      for (std::size_t q = 0; q < W; ++q) ++count[cell[b + q] + 1];
    }
    if (b < n) {
      const std::size_t cnt = n - b;
      double px[W], py[W], pz[W];
      for (std::size_t q = 0; q < W; ++q) {
        const std::size_t i = first + b + std::min(q, cnt - 1);
        px[q] = io.in[0][i * Stride];
        py[q] = io.in[1][i * Stride];
        pz[q] = io.in[2][i * Stride];
      }
      load(x, px), load(y, py), load(z, pz);
      locate_block(K, x, y, z, S + b, T + b, U + b, cell + b);
      for (std::size_t q = 0; q < cnt; ++q) ++count[cell[b + q] + 1];
    }
  };
  // 5. Results of scratch [from, n) out to points [first + from, first + n), in input order.
  auto output_range = [&](std::size_t first, std::size_t from, std::size_t n)
      __attribute__((always_inline)) {
    std::size_t b = from;
    for (; b + W <= n; b += W) {
      load(x, S + b);
      load(y, T + b);
      load(z, U + b);
      prefetch_output<Stride>(io, first + b + prefetch_distance);
      store_block<Stride>(io, first + b, x, y, z);
    }
    for (; b < n; ++b) {
      io.out[0][(first + b) * Stride] = S[b];
      io.out[1][(first + b) * Stride] = T[b];
      io.out[2][(first + b) * Stride] = U[b];
    }
  };
  std::size_t c0 = begin;
  std::fill(count, count + outside + 2, 0);
  locate_range(c0, 0, std::min(chunk_points, end - c0));
  for (; c0 < end; c0 += chunk_points) {
    const std::size_t n = std::min(chunk_points, end - c0);
    // 2. Counting sort by cell (indices only: one store per point into a small array).
    counting_sort(cell, order, count, n, outside);
    // Now count[c] = end of cell c. 3. Blocks within one cell, coefficients broadcast; a last
    // partial block reads (but does not write) points of the next cell, not yet evaluated.
    int start = 0;
    for (int c = 0; c < outside; ++c) {
      const int stop = count[c];
      const double* coef = K.coef + static_cast<std::size_t>(c) * K.cell_size;
      for (int p = start; p < stop; p += W) {
        // Both pointers are made opaque to GCC for each block. Otherwise it hoists the 48
        // coefficient addresses (coef + constant) out of the block loop and keeps the gather's
        // 24 lane addresses alive across Horner, parking both in vector registers: about 70
        // extra register moves per block (+2-4 % once the lanes are prefetched, below).
        const double* cf = coef;
        const std::int32_t* lanes = order + p;
        CLAY_OPAQUE(cf);
        // The next block's lanes, fetched into L1 while this one is evaluated (the scratch
        // lives in L2; +3-9 % in A/B runs, two threads).
        for (int q = 0; q < W; ++q) {
          const std::int32_t i = lanes[W + q];
          __builtin_prefetch(S + i);
          __builtin_prefetch(T + i);
          __builtin_prefetch(U + i);
        }
        vd s, t, u, r[3];
        for (int q = 0; q < W; ++q) {
          const std::int32_t i = lanes[q];
          s[q] = S[i];
          t[q] = T[i];
          u[q] = U[i];
        }
        horner_block<L, M, N>(K, cf, s, t, u, r);
        CLAY_OPAQUE(lanes);
        // The result replaces the point's coordinates. Lanes taken from registers (a lane
        // reloaded from a vector just stored would wait for the store to reach the cache).
        if (stop - p >= W) {
#pragma GCC unroll 8
          for (int q = 0; q < W; ++q) {
            const std::int32_t i = lanes[q];
            S[i] = r[0][q];
            T[i] = r[1][q];
            U[i] = r[2][q];
          }
        } else {
          for (int q = 0; q < stop - p; ++q) {
            const std::int32_t i = lanes[q];
            S[i] = r[0][q];
            T[i] = r[1][q];
            U[i] = r[2][q];
          }
        }
      }
      start = stop;
    }
    // 4. Points outside (sorted last) get their own coordinates back, read before this chunk's
    // output is written (so `out` may be `in`).
    for (int p = start; p < count[outside]; ++p) {
      const std::size_t i = static_cast<std::size_t>(order[p]);
      S[i] = io.in[0][(c0 + i) * Stride];
      T[i] = io.in[1][(c0 + i) * Stride];
      U[i] = io.in[2][(c0 + i) * Stride];
    }
    // 5. The results go out in input order, and the next chunk is located into the same scratch
    // entries in the same pass: one loop with a write stream and a read stream keeps more memory
    // requests in flight than two loops with one each. (Block b of the next chunk overwrites
    // block b of this one only after it went out; the chunks are disjoint ranges of the points,
    // so `out` may still be `in`.)
    const std::size_t c1 = c0 + chunk_points;
    if (c1 >= end) {
      output_range(c0, 0, n);
      break;
    }
    const std::size_t n1 = std::min(chunk_points, end - c1);  // <= n
    std::fill(count, count + outside + 2, 0);
    std::size_t b = 0;
    for (; b + W <= n1; b += W) {
      // The next chunk's input is loaded first: its loads wait on memory, the output's stores
      // do not (+0.5-5 % in A/B runs).
      vd x1, y1, z1;
      prefetch_block<Stride>(io, c1 + b + prefetch_distance);
      load_block<Stride>(io, c1 + b, x1, y1, z1);
      load(x, S + b);
      load(y, T + b);
      load(z, U + b);
      prefetch_output<Stride>(io, c0 + b + prefetch_distance);
      store_block<Stride>(io, c0 + b, x, y, z);
      locate_block(K, x1, y1, z1, S + b, T + b, U + b, cell + b);
      for (std::size_t q = 0; q < W; ++q) ++count[cell[b + q] + 1];
    }
    output_range(c0, b, n);
    locate_range(c1, b, n1);
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

CLAY_DEFORM_CLONES void run_bezier_rows(const Kernel& K, const Io& io, std::size_t b,
                                        std::size_t e) {
  bezier_dispatch<3>(K, io, b, e);
}
CLAY_DEFORM_CLONES void run_bezier_columns(const Kernel& K, const Io& io, std::size_t b,
                                           std::size_t e) {
  bezier_dispatch<1>(K, io, b, e);
}
CLAY_DEFORM_CLONES void run_bspline_rows(const Kernel& K, const Io& io, std::size_t b,
                                         std::size_t e, Scratch& sc) {
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
    K.all_uniform = K.uniform[0] && K.uniform[1] && K.uniform[2];
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
        b[r * 3 + static_cast<size_t>(c)] =
            bezier_points(static_cast<Eigen::Index>(r), c) - f.center_[c];
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
    spans[static_cast<size_t>(d)] =
        surface::bezier_extraction(lattice.bases[static_cast<size_t>(d)]);
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
  const std::size_t threads = internal::part_count(options.threads, n, min_points_per_thread);
  std::vector<Scratch> scratch(bezier ? 0 : threads);
  for (auto& sc : scratch) {
    // Whole blocks plus W spare entries (the last partial block of a cell spills over); the
    // order has W more, read (stale indices will do) by the prefetch one block ahead.
    const std::size_t c = (std::min(chunk_points, n) + W - 1) / W * W + W;
    for (auto* v : {&sc.s, &sc.t, &sc.u}) v->resize(c);
    sc.cell.resize(c);
    sc.order.resize(c + W);
    sc.count.resize(static_cast<std::size_t>(K.cell_count) + 2);
  }
  auto work = [&](std::size_t part) {
    // Contiguous ranges, block-aligned.
    const std::size_t blocks = (n + W - 1) / W;
    const std::size_t b = std::min(n, blocks * part / threads * W);
    const std::size_t e = std::min(n, blocks * (part + 1) / threads * W);
    if (b >= e) return;
    if (bezier) {
      if (rows)
        run_bezier_rows(K, io, b, e);
      else
        run_bezier_columns(K, io, b, e);
    } else {
      if (rows)
        run_bspline_rows(K, io, b, e, scratch[part]);
      else
        run_bspline_columns(K, io, b, e, scratch[part]);
    }
  };
  internal::run_parts(threads, options.executor, work);
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
  deform_points(lattice, points, out, options);
  return out;
}

void deform_points(const FrozenLattice& lattice, const Points3& points, Points3& out,
                   const DeformOptions& options) {
  if (&out != &points && out.rows() != points.rows()) out.resize(points.rows(), 3);
  const double* in = points.data();
  double* o = out.data();
  run(lattice, Io{{in, in + 1, in + 2}, {o, o + 1, o + 2}}, static_cast<std::size_t>(points.rows()),
      true, options);
}

void deform_points(const FrozenLattice& lattice, std::span<const double> in, std::span<double> out,
                   const DeformOptions& options) {
  if (in.size() != out.size() || in.size() % 3 != 0)
    throw Error(
        ErrorCategory::InvalidArgument,
        "deform_points: interleaved points of " + std::to_string(in.size()) + " in and " +
            std::to_string(out.size()) +
            " out coordinates; give x, y, z per point (a multiple of 3), as many out as in");
  const double* i = in.data();
  double* o = out.data();
  run(lattice, Io{{i, i + 1, i + 2}, {o, o + 1, o + 2}}, in.size() / 3, true, options);
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
  run(lattice,
      Io{{in.x.data(), in.y.data(), in.z.data()}, {out.x.data(), out.y.data(), out.z.data()}}, n,
      false, options);
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
