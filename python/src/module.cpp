// The extension module clayform._clayform (issue #22). The Python package clayform re-exports
// it with the pure-Python parts (errors, sweeps); docs/python.md is the user's guide.
#include "common.hpp"

namespace clay::python {

namespace {

/// The Python class of each clay::Error category, defined in clayform/errors.py.
const char* error_class(ErrorCategory c) {
  switch (c) {
    case ErrorCategory::InvalidArgument:
      return "InvalidArgumentError";
    case ErrorCategory::InvalidGeometry:
      return "InvalidGeometryError";
    case ErrorCategory::OutOfDomain:
      return "OutOfDomainError";
    case ErrorCategory::DegreeLimit:
      return "DegreeLimitError";
    case ErrorCategory::Io:
      return "IoError";
    case ErrorCategory::Exchange:
      return "ExchangeError";
    case ErrorCategory::Document:
      return "DocumentError";
    case ErrorCategory::ToleranceNotMet:
      return "ToleranceNotMetError";
    case ErrorCategory::Internal:
      return "InternalError";
  }
  return "InternalError";
}

void raise(const char* cls, const std::string& message) {
  const py::object type = py::module_::import("clayform.errors").attr(cls);
  PyErr_SetString(type.ptr(), message.c_str());
}

}  // namespace

void register_errors(py::module_& m) {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      raise(error_class(e.category()), e.message());
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (TypeError, ValueError, ...): translated by pybind11
    } catch (const py::error_already_set&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError, by pybind11
    } catch (const std::exception& e) {
      raise("InternalError", std::string("a C++ exception escaped the kernel (") + e.what() +
                                 "); please report it with the input that caused it");
    } catch (...) {
      // Not a std::exception: in practice an OpenCASCADE Standard_Failure that a kernel call did
      // not wrap. Never "unknown exception".
      raise("InternalError",
            "a non-standard C++ exception (an OpenCASCADE failure) escaped the kernel; please "
            "report it with the input that caused it");
    }
  });
  m.def(
      "_raise_error",
      [](const std::string& category, const std::string& message) {
        static const std::pair<const char*, ErrorCategory> names[] = {
            {"invalid_argument", ErrorCategory::InvalidArgument},
            {"invalid_geometry", ErrorCategory::InvalidGeometry},
            {"out_of_domain", ErrorCategory::OutOfDomain},
            {"degree_limit", ErrorCategory::DegreeLimit},
            {"io", ErrorCategory::Io},
            {"exchange", ErrorCategory::Exchange},
            {"document", ErrorCategory::Document},
            {"tolerance_not_met", ErrorCategory::ToleranceNotMet},
            {"internal", ErrorCategory::Internal}};
        for (const auto& [name, c] : names)
          if (category == name) throw Error(c, message);
        throw Error(ErrorCategory::InvalidArgument,
                    "_raise_error: no category \"" + category + "\"");
      },
      "Raises clay::Error of the category from C++ (tests the translation of every category).");
}

}  // namespace clay::python

PYBIND11_MODULE(_clayform, m) {
  m.doc() = "Clayform's C++ kernel (the clayform package re-exports it; see docs/python.md).";
  clay::python::register_errors(m);
  clay::python::bind_geometry(m);
  clay::python::bind_deform(m);
  clay::python::bind_sketch(m);
  clay::python::bind_stack(m);
  clay::python::bind_model(m);
  clay::python::bind_recipe(m);
  clay::python::bind_optimisation(m);
}
