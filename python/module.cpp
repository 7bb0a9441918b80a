/** @file module.cpp
 *  @brief The pybind11 extension `uwbtdoa._uwbtdoa`: exception mapping and one bind function per library module.
 *  docs/python.md describes the Python API.
 */
#include <stdexcept>

#include "bindings.h"
#include "uwb/core/Error.h"

#ifndef UWB_VERSION
#define UWB_VERSION "0.0.0"
#endif

namespace uwb::python {

void bindCore(py::module_& m) {
  // Same messages as the CLI prints: the what() text, unchanged.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const uwb::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const uwb::FileError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::out_of_range& e) {
      PyErr_SetString(PyExc_KeyError, e.what());
    }
  });
  m.attr("GRAVITY_MPS2") = kGravity_mps2;
  m.attr("UTIL_TAG_OFFSET_B") = toNumpy(kUtilTagOffset_b, /*as_vector=*/true);
}

}  // namespace uwb::python

PYBIND11_MODULE(_uwbtdoa, m) {
  m.doc() = "uwbtdoa: UWB TDoA localization with sparse-GP bias correction (C++ core). See docs/python.md.";
  m.attr("__version__") = UWB_VERSION;
  uwb::python::bindCore(m);
  uwb::python::bindIo(m);
  uwb::python::bindModel(m);
  uwb::python::bindGp(m);
  uwb::python::bindGpTrain(m);
  uwb::python::bindSim(m);
  uwb::python::bindEval(m);
  uwb::python::bindStream(m);
}
