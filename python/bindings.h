/** @file bindings.h
 *  @brief Shared helpers of the pybind11 module `uwbtdoa._uwbtdoa`: numpy <-> Eigen conversion of whole arrays
 *  (no per-sample Python calls) with argument checks that raise ValueError, and the per-module bind functions.
 *
 *  Conventions at the Python boundary: arrays are float64 (int32 for anchor ids), one row per sample;
 *  3-vectors are (N, 3); quaternions are (N, 4) in (x, y, z, w) order (the UTIL column order, as scipy).
 */
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>

#include "uwb/core/Strings.h"
#include "uwb/core/Types.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/Estimator.h"
#include "uwb/io/Flight.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb::python {

namespace py = pybind11;

using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using DArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IArray = py::array_t<int, py::array::c_style | py::array::forcecast>;

/// obj as an Array (array_t, converted from any array-like); std::invalid_argument "NAME: expected WHAT" when it
/// cannot be converted.
template <class Array>
Array ensureArray(const py::handle& obj, const char* name, const char* what) {
  Array a;
  try {
    a = Array::ensure(obj);
  } catch (const py::error_already_set&) {
    throw std::invalid_argument(std::string(name) + ": expected " + what);
  }
  if (!a) throw std::invalid_argument(std::string(name) + ": expected " + what);
  return a;
}

/// Converts any array-like to float64 and checks its shape: (N, cols), or (cols,) which is read as one row
/// (when allow_row is true). cols == 0 means a 1-D array (N,). Throws std::invalid_argument (→ ValueError).
inline RowMat toMatrix(const py::handle& obj, py::ssize_t cols, const char* name, bool allow_row = true) {
  const DArray a = ensureArray<DArray>(obj, name, "a numeric array");
  if (cols == 0) {
    if (a.ndim() == 0) {
      RowMat m(1, 1);
      m(0, 0) = *a.data();
      return m;
    }
    if (a.ndim() != 1) {
      throw std::invalid_argument(std::string(name) + ": expected a 1-D array, got " + std::to_string(a.ndim()) +
                                  " dimensions");
    }
    return Eigen::Map<const RowMat>(a.data(), a.shape(0), 1);
  }
  if (a.ndim() == 1 && allow_row && a.shape(0) == cols) return Eigen::Map<const RowMat>(a.data(), 1, cols);
  if (a.ndim() != 2 || a.shape(1) != cols) {
    std::string dims;
    for (py::ssize_t d = 0; d < a.ndim(); ++d) uwb::appendToList(&dims, std::to_string(a.shape(d)));
    std::string shape = "(";
    shape += dims;
    shape += a.ndim() == 1 ? ",)" : ")";
    throw std::invalid_argument(std::string(name) + ": expected shape (N, " + std::to_string(cols) + "), got " +
                                shape);
  }
  return Eigen::Map<const RowMat>(a.data(), a.shape(0), cols);
}

/// 1-D int array.
inline Eigen::VectorXi toIntVector(const py::handle& obj, const char* name) {
  const IArray a = ensureArray<IArray>(obj, name, "an integer array");
  if (a.ndim() == 0) return Eigen::VectorXi::Constant(1, *a.data());
  if (a.ndim() != 1) throw std::invalid_argument(std::string(name) + ": expected a 1-D integer array");
  return Eigen::Map<const Eigen::VectorXi>(a.data(), a.shape(0));
}

/// Number of rows after broadcasting single rows; throws when lengths differ.
inline Eigen::Index commonRows(std::initializer_list<std::pair<Eigen::Index, const char*>> sizes) {
  Eigen::Index n = 1;
  const char* who = nullptr;
  for (const auto& [rows, name] : sizes) {
    if (rows == 1) continue;
    if (n != 1 && rows != n) {
      throw std::invalid_argument(std::string("length mismatch: ") + who + " has " + std::to_string(n) + " rows, " +
                                  name + " has " + std::to_string(rows));
    }
    n = rows;
    who = name;
  }
  return n;
}

inline Vec3 row3(const RowMat& m, Eigen::Index i) {
  const Eigen::Index r = m.rows() == 1 ? 0 : i;
  return Vec3(m(r, 0), m(r, 1), m(r, 2));
}
/// Quaternion from an (x, y, z, w) row.
inline Quat rowQuat(const RowMat& m, Eigen::Index i) {
  const Eigen::Index r = m.rows() == 1 ? 0 : i;
  return Quat(m(r, 3), m(r, 0), m(r, 1), m(r, 2));
}

inline py::array_t<double> newArray(Eigen::Index n) { return py::array_t<double>(static_cast<py::ssize_t>(n)); }
inline py::array_t<double> newArray(Eigen::Index n, Eigen::Index cols) {
  return py::array_t<double>({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(cols)});
}
inline py::array_t<int> newIntArray(Eigen::Index n) { return py::array_t<int>(static_cast<py::ssize_t>(n)); }

/// Copies an Eigen matrix into a fresh numpy array (2-D; 1-D when as_vector).
template <class Derived>
py::array_t<double> toNumpy(const Eigen::MatrixBase<Derived>& m, bool as_vector = false) {
  if (as_vector) {
    py::array_t<double> out = newArray(m.size());
    auto o = out.mutable_unchecked<1>();
    for (Eigen::Index i = 0; i < m.size(); ++i) o(i) = m(i);
    return out;
  }
  py::array_t<double> out = newArray(m.rows(), m.cols());
  auto o = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) o(i, j) = m(i, j);
  return out;
}

/// Fetches a required key of a dict of arrays; KeyError-like message as ValueError.
inline py::object requireKey(const py::dict& d, const char* key, const char* what) {
  if (!d.contains(key)) throw std::invalid_argument(std::string(what) + ": missing key '" + key + "'");
  return d[key];
}

/// Trajectory ↔ dict {t (N,), p (N, 3), q (N, 4) (x, y, z, w), sigma_p (N, 3), v (N, 3)} (bind_io.cpp).
py::dict trajectoryToDict(const Trajectory& trajectory);
/// The run summary as localize_flight returns it ("summary"): the keys of `localize --json`, with the sensor
/// ranges' counts and warnings (filter.md F31) (bind_eval.cpp).
py::dict summaryDict(const LocalizerSummary& s, const EkfParams& params);
Trajectory trajectoryFromDict(const py::dict& d);
/// Pose samples → {t, p, q} (bind_io.cpp).
py::dict poseSamplesToDict(const std::vector<PoseSample>& samples);

void bindCore(py::module_& m);
void bindIo(py::module_& m);
void bindModel(py::module_& m);
void bindGp(py::module_& m);
void bindSim(py::module_& m);
void bindGpTrain(py::module_& m);
void bindEval(py::module_& m);
void bindStream(py::module_& m);

/// EkfParams from a preset ("defaults" | "crazyflie" | "tdoa-only") and a dict of field overrides (validated).
EkfParams ekfParamsFromPython(const std::string& preset, const py::dict& overrides);

/// Feature dict (one row per measurement: id_a, id_b, yaw_a, yaw_b, b_p_a, b_p_b, w_p_b, w_p_anchor_a, w_p_anchor_b)
/// of TdoaFeature rows; bind_eval.cpp.
py::dict featuresToDict(const std::vector<const TdoaFeature*>& fs);

// ------------------------------------------------------------------------------- parameter structs from dicts
/// name → setter for one field of a parameter struct (EkfParams, SimParams, ...).
template <class T>
using Setters = std::map<std::string, std::function<void(T&, const py::handle&)>>;

/// Registers the plain field `field` under `name`; the value is cast with pybind11.
template <class T, class F>
void addField(Setters<T>& s, const std::string& name, F T::*field) {
  s[name] = [field](T& obj, const py::handle& v) { obj.*field = py::cast<F>(v); };
}

/// Applies {name: value} overrides; an unknown name raises ValueError listing the known ones, a value of the wrong
/// type raises ValueError naming the parameter. `what` names the struct in messages ("filter", "simulation").
template <class T>
void applyOverrides(T& obj, const Setters<T>& setters, const py::dict& overrides, const std::string& what) {
  for (const auto& [key, value] : overrides) {
    const std::string name = py::str(key);
    const auto it = setters.find(name);
    if (it == setters.end()) {
      std::string known;
      for (const auto& [n, _] : setters) uwb::appendToList(&known, n);
      throw std::invalid_argument("unknown " + what + " parameter '" + name + "' (known: " + known + ")");
    }
    try {
      it->second(obj, value);
    } catch (const py::cast_error&) {
      throw std::invalid_argument(what + " parameter '" + name + "': wrong type");
    }
  }
}

}  // namespace uwb::python
