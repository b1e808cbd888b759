#pragma once
// Shared by the binding's sources: NumPy <-> Eigen without copies, and the typed exceptions.
//
// The rules (docs/python.md): bulk inputs are NumPy float64 arrays in C order, read in place; a
// wrong dtype or order raises TypeError naming the argument and the fix, never a silent copy.
// Bulk outputs are NumPy arrays that own the C++ result (moved, not copied), and the control
// points of curves, surfaces and lattices are writable views into the object's own storage.
#include <clay/error.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/SparseCore>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace clay::python {

namespace py = pybind11;
using surface::Points3;

/// True for native float64 (NumPy's equivalence of types: an unpickled array's dtype is another
/// object than np.float64's).
inline bool is_float64(const py::array& a) { return py::isinstance<py::array_t<double>>(a); }

/// A C-contiguous float64 array of shape (n, 3), read in place. Throws TypeError for another
/// dtype, order or type, ValueError for another shape.
inline Eigen::Map<const Points3> points_in(const py::handle& obj, const std::string& what) {
  if (!py::isinstance<py::array>(obj))
    throw py::type_error(what + ": expected a NumPy float64 array of shape (n, 3), got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))) +
                         "; give np.asarray(" + what + ", dtype=np.float64)");
  const auto a = py::reinterpret_borrow<py::array>(obj);
  if (!is_float64(a))
    throw py::type_error(what + ": expected dtype float64, got " + std::string(py::str(a.dtype())) +
                         "; convert with " + what +
                         ".astype(np.float64) (Clayform never converts silently)");
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(what + ": expected shape (n, 3), got " +
                          std::string(py::str(a.attr("shape"))));
  if (!(a.flags() & py::array::c_style))
    throw py::type_error(what + ": expected a C-contiguous array (row-major), got strides " +
                         std::string(py::str(a.attr("strides"))) + "; give np.ascontiguousarray(" +
                         what + ") (Clayform never copies silently)");
  return {static_cast<const double*>(a.data()), a.shape(0), 3};
}

/// A C-contiguous float64 array of any shape, read in place (parameters): its values in order.
inline std::span<const double> values_in(const py::array& a, const std::string& what) {
  if (!is_float64(a))
    throw py::type_error(what + ": expected dtype float64, got " + std::string(py::str(a.dtype())) +
                         "; convert with " + what + ".astype(np.float64)");
  if (!(a.flags() & py::array::c_style))
    throw py::type_error(what + ": expected a C-contiguous array; give np.ascontiguousarray(" +
                         what + ")");
  return {static_cast<const double*>(a.data()), static_cast<std::size_t>(a.size())};
}

/// A writable C-contiguous float64 (n, 3) array (an `out=` argument), written in place.
inline Eigen::Map<Points3> points_out_arg(const py::handle& obj, const std::string& what) {
  const auto in = points_in(obj, what);
  const auto a = py::reinterpret_borrow<py::array>(obj);
  if (!a.writeable()) throw py::value_error(what + ": the array is read-only");
  return {const_cast<double*>(in.data()), in.rows(), 3};
}

/// The matrix as a NumPy array that owns it (moved onto the heap; no copy of the data).
inline py::array_t<double> owned(Points3&& m) {
  auto* heap = new Points3(std::move(m));
  py::capsule free(heap, [](void* p) { delete static_cast<Points3*>(p); });
  return py::array_t<double>(
      {heap->rows(), Eigen::Index{3}},
      {static_cast<Eigen::Index>(3 * sizeof(double)), static_cast<Eigen::Index>(sizeof(double))},
      heap->data(), free);
}

/// A vector as a NumPy array that owns it.
inline py::array_t<double> owned(std::vector<double>&& v) {
  auto* heap = new std::vector<double>(std::move(v));
  py::capsule free(heap, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>({static_cast<py::ssize_t>(heap->size())}, {sizeof(double)},
                             heap->data(), free);
}

/// A writable (rows, 3) view into `data`, kept alive by `owner` (the Python object holding it).
inline py::array_t<double> view(double* data, Eigen::Index rows, const py::handle& owner) {
  return py::array_t<double>(
      {rows, Eigen::Index{3}},
      {static_cast<Eigen::Index>(3 * sizeof(double)), static_cast<Eigen::Index>(sizeof(double))},
      data, owner);
}

/// A read-only copy of a small vector (knots): changing them in place would break invariants.
inline py::array_t<double> frozen_copy(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// An (n, 3) array or a 3-sequence as a point.
inline Eigen::Vector3d vec3(const py::handle& obj, const std::string& what) {
  // A string is a sequence too (of characters), and a failed cast was a bare RuntimeError: both
  // are named as the wrong type (issue #36).
  std::optional<std::vector<double>> seq;
  if (!py::isinstance<py::str>(obj) && !py::isinstance<py::bytes>(obj)) try {
      seq = py::cast<std::vector<double>>(obj);
    } catch (const py::cast_error&) {
    }
  if (!seq)
    throw py::type_error(what + ": expected 3 numbers (x, y, z), got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))) + " " +
                         std::string(py::repr(obj)).substr(0, 60));
  if (seq->size() != 3)
    throw py::value_error(what + ": expected 3 coordinates, got " + std::to_string(seq->size()));
  const Eigen::Vector3d x((*seq)[0], (*seq)[1], (*seq)[2]);
  if (!x.allFinite())
    throw py::value_error(what + ": the coordinates must be finite, got " +
                          std::string(py::str(py::make_tuple(x[0], x[1], x[2]))));
  return x;
}

/// Every value finite: NaN or infinite points passed through deformations unchanged and
/// unreported (issue #36). ValueError naming the first row that is not.
inline void require_finite(const Eigen::Ref<const Points3>& p, const std::string& what) {
  for (Eigen::Index r = 0; r < p.rows(); ++r)
    if (!p.row(r).allFinite())
      throw py::value_error(what + ": row " + std::to_string(r) + " is not finite (" +
                            std::string(py::str(py::make_tuple(p(r, 0), p(r, 1), p(r, 2)))) +
                            "); remove or repair it");
}

/// A fixed-size array as a Python tuple (std::array alone becomes a list).
template <class T, std::size_t N>
py::tuple tuple_of(const std::array<T, N>& a) {
  py::tuple t(N);
  for (std::size_t i = 0; i < N; ++i) t[i] = py::cast(a[i]);
  return t;
}
inline py::tuple tuple_of(const Eigen::Vector3d& p) { return py::make_tuple(p.x(), p.y(), p.z()); }

/// A row-major Eigen sparse matrix as a scipy.sparse CSR matrix (copied).
inline py::object scipy_csr(Eigen::SparseMatrix<double, Eigen::RowMajor> m) {
  m.makeCompressed();
  py::array_t<double> data(m.nonZeros(), m.valuePtr());
  py::array_t<int> indices(m.nonZeros(), m.innerIndexPtr());
  py::array_t<int> indptr(m.outerSize() + 1, m.outerIndexPtr());
  return py::module_::import("scipy.sparse")
      .attr("csr_matrix")(py::make_tuple(data, indices, indptr),
                          py::make_tuple(m.rows(), m.cols()));
}

void register_errors(py::module_& m);
void bind_geometry(py::module_& m);
void bind_deform(py::module_& m);
void bind_sketch(py::module_& m);
void bind_recipe(py::module_& m);
void bind_model(py::module_& m);
void bind_stack(py::module_& m);
void bind_optimisation(py::module_& m);

}  // namespace clay::python
