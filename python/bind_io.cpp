/** @file bind_io.cpp
 *  @brief Python bindings of uwb/io: flights (each stream as a dict of numpy arrays, SI units) and anchor surveys.
 *
 *  Stream dicts (one row per sample; time t in seconds on the drone's clock):
 *    tdoa: t, id_a, id_b (int32), tdoa [m] (= |p_tag − a_idB| − |p_tag − a_idA|)
 *    twr:  t, anchor_id (int32), range [m]
 *    acc:  t, value (N, 3) [m/s², body frame]        gyro: t, value (N, 3) [rad/s, body frame]
 *    tof:  t, value [m]      baro: t, value [m above sea level]      flow: t, delta_x, delta_y [counts]
 *    pose: t, p (N, 3) [m, world], q (N, 4) body→world quaternion (x, y, z, w)
 */
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "bindings.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/io/SurveyCheck.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/io/UsdImport.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/TdoaResiduals.h"

namespace uwb::python {
namespace {

struct StreamName {
  Stream stream;
  const char* name;
};
constexpr std::array<StreamName, 8> kStreams{{{Stream::kTdoa, "tdoa"},
                                              {Stream::kTwr, "twr"},
                                              {Stream::kAcc, "acc"},
                                              {Stream::kGyro, "gyro"},
                                              {Stream::kTof, "tof"},
                                              {Stream::kFlow, "flow"},
                                              {Stream::kBaro, "baro"},
                                              {Stream::kPose, "pose"}}};

Stream streamFromName(const std::string& name) {
  for (const auto& s : kStreams)
    if (name == s.name) return s.stream;
  throw std::invalid_argument("unknown stream '" + name + "' (expected tdoa, twr, acc, gyro, tof, flow, baro, pose)");
}

template <class Sample>
py::array_t<double> times(const std::vector<Sample>& v) {
  auto out = newArray(static_cast<Eigen::Index>(v.size()));
  auto o = out.template mutable_unchecked<1>();
  for (std::size_t i = 0; i < v.size(); ++i) o(i) = v[i].t_s;
  return out;
}

/// Runs `read(report)` without the GIL; the flight, or (flight, to_dict(report)) when with_report.
template <class Report, class Read, class ToDict>
py::object flightWithReport(bool with_report, Read&& read, ToDict&& to_dict) {
  Report report;
  Flight f;
  {
    py::gil_scoped_release release;
    f = read(report);
  }
  if (!with_report) return py::cast(std::move(f));
  return py::make_tuple(std::move(f), to_dict(report));
}

// ---- C++ → numpy (one pass per stream) ----
py::dict tdoaDict(const std::vector<TdoaMeasurement>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  auto a = newIntArray(n), b = newIntArray(n);
  auto z = newArray(n);
  auto ma = a.mutable_unchecked<1>(), mb = b.mutable_unchecked<1>();
  auto mz = z.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    ma(i) = v[i].id_a;
    mb(i) = v[i].id_b;
    mz(i) = v[i].tdoa_m;
  }
  py::dict d;
  d["t"] = times(v), d["id_a"] = a, d["id_b"] = b, d["tdoa"] = z;
  return d;
}

py::dict twrDict(const std::vector<TwrMeasurement>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  auto id = newIntArray(n);
  auto r = newArray(n);
  auto mi = id.mutable_unchecked<1>();
  auto mr = r.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) mi(i) = v[i].anchor_id, mr(i) = v[i].range_m;
  py::dict d;
  d["t"] = times(v), d["anchor_id"] = id, d["range"] = r;
  return d;
}

py::dict imuDict(const std::vector<ImuSample>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  auto x = newArray(n, 3);
  auto mx = x.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) mx(i, k) = v[i].b_value[k];
  py::dict d;
  d["t"] = times(v), d["value"] = x;
  return d;
}

py::dict scalarDict(const std::vector<ScalarSample>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  auto x = newArray(n);
  auto mx = x.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) mx(i) = v[i].value;
  py::dict d;
  d["t"] = times(v), d["value"] = x;
  return d;
}

py::dict flowDict(const std::vector<FlowSample>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  auto x = newArray(n), y = newArray(n);
  auto mx = x.mutable_unchecked<1>(), my = y.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) mx(i) = v[i].delta_x, my(i) = v[i].delta_y;
  py::dict d;
  d["t"] = times(v), d["delta_x"] = x, d["delta_y"] = y;
  return d;
}

py::dict poseDict(const std::vector<PoseSample>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  auto p = newArray(n, 3), q = newArray(n, 4);
  auto mp = p.mutable_unchecked<2>(), mq = q.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) mp(i, k) = v[i].w_p_b[k];
    mq(i, 0) = v[i].w_q_b.x(), mq(i, 1) = v[i].w_q_b.y(), mq(i, 2) = v[i].w_q_b.z(), mq(i, 3) = v[i].w_q_b.w();
  }
  py::dict d;
  d["t"] = times(v), d["p"] = p, d["q"] = q;
  return d;
}

// ---- numpy → C++ ----
Eigen::VectorXd column(const py::dict& d, const char* key, const char* what, Eigen::Index n = -1) {
  const RowMat m = toMatrix(requireKey(d, key, what), 0, (std::string(what) + "['" + key + "']").c_str());
  if (n >= 0 && m.rows() != n) {
    throw std::invalid_argument(std::string(what) + "['" + key + "']: " + std::to_string(m.rows()) +
                                " rows, expected " + std::to_string(n) + " (as 't')");
  }
  return m.col(0);
}
RowMat block(const py::dict& d, const char* key, const char* what, Eigen::Index cols, Eigen::Index n) {
  const std::string name = std::string(what) + "['" + key + "']";
  RowMat m = toMatrix(requireKey(d, key, what), cols, name.c_str(), /*allow_row=*/false);
  if (m.rows() != n) {
    throw std::invalid_argument(name + ": " + std::to_string(m.rows()) + " rows, expected " + std::to_string(n) +
                                " (as 't')");
  }
  return m;
}
Eigen::VectorXi intColumn(const py::dict& d, const char* key, const char* what, Eigen::Index n) {
  const std::string name = std::string(what) + "['" + key + "']";
  Eigen::VectorXi v = toIntVector(requireKey(d, key, what), name.c_str());
  if (v.size() != n) {
    throw std::invalid_argument(name + ": " + std::to_string(v.size()) + " rows, expected " + std::to_string(n) +
                                " (as 't')");
  }
  return v;
}

std::vector<TdoaMeasurement> tdoaFrom(const py::dict& d) {
  const Eigen::VectorXd t = column(d, "t", "tdoa");
  const auto n = t.size();
  const Eigen::VectorXi a = intColumn(d, "id_a", "tdoa", n), b = intColumn(d, "id_b", "tdoa", n);
  const Eigen::VectorXd z = column(d, "tdoa", "tdoa", n);
  std::vector<TdoaMeasurement> v(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) v[i] = {t(i), a(i), b(i), z(i)};
  return v;
}
std::vector<TwrMeasurement> twrFrom(const py::dict& d) {
  const Eigen::VectorXd t = column(d, "t", "twr");
  const auto n = t.size();
  const Eigen::VectorXi id = intColumn(d, "anchor_id", "twr", n);
  const Eigen::VectorXd r = column(d, "range", "twr", n);
  std::vector<TwrMeasurement> v(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) v[i] = {t(i), id(i), r(i)};
  return v;
}
std::vector<ImuSample> imuFrom(const py::dict& d, const char* what) {
  const Eigen::VectorXd t = column(d, "t", what);
  const RowMat x = block(d, "value", what, 3, t.size());
  std::vector<ImuSample> v(static_cast<std::size_t>(t.size()));
  for (Eigen::Index i = 0; i < t.size(); ++i) v[i] = {t(i), row3(x, i)};
  return v;
}
std::vector<ScalarSample> scalarFrom(const py::dict& d, const char* what) {
  const Eigen::VectorXd t = column(d, "t", what);
  const Eigen::VectorXd x = column(d, "value", what, t.size());
  std::vector<ScalarSample> v(static_cast<std::size_t>(t.size()));
  for (Eigen::Index i = 0; i < t.size(); ++i) v[i] = {t(i), x(i)};
  return v;
}
std::vector<FlowSample> flowFrom(const py::dict& d) {
  const Eigen::VectorXd t = column(d, "t", "flow");
  const Eigen::VectorXd x = column(d, "delta_x", "flow", t.size()), y = column(d, "delta_y", "flow", t.size());
  std::vector<FlowSample> v(static_cast<std::size_t>(t.size()));
  for (Eigen::Index i = 0; i < t.size(); ++i) v[i] = {t(i), x(i), y(i)};
  return v;
}
std::vector<PoseSample> poseFrom(const py::dict& d) {
  const Eigen::VectorXd t = column(d, "t", "pose");
  const RowMat p = block(d, "p", "pose", 3, t.size());
  RowMat q;
  if (d.contains("q")) {
    q = block(d, "q", "pose", 4, t.size());
  } else {
    q = RowMat::Zero(1, 4);
    q(0, 3) = 1.0;
  }
  std::vector<PoseSample> v(static_cast<std::size_t>(t.size()));
  for (Eigen::Index i = 0; i < t.size(); ++i) v[i] = {t(i), row3(p, i), rowQuat(q, i)};
  return v;
}

py::dict allStreams(const Flight& f) {
  py::dict d;
  if (f.has(Stream::kTdoa)) d["tdoa"] = tdoaDict(f.tdoa);
  if (f.has(Stream::kTwr)) d["twr"] = twrDict(f.twr);
  if (f.has(Stream::kAcc)) d["acc"] = imuDict(f.acc);
  if (f.has(Stream::kGyro)) d["gyro"] = imuDict(f.gyro);
  if (f.has(Stream::kTof)) d["tof"] = scalarDict(f.tof);
  if (f.has(Stream::kFlow)) d["flow"] = flowDict(f.flow);
  if (f.has(Stream::kBaro)) d["baro"] = scalarDict(f.baro);
  if (f.has(Stream::kPose)) d["pose"] = poseDict(f.pose);
  return d;
}

void setStream(Flight& f, const std::string& name, const py::dict& d) {
  switch (streamFromName(name)) {
    case Stream::kTdoa: f.tdoa = tdoaFrom(d); break;
    case Stream::kTwr: f.twr = twrFrom(d); break;
    case Stream::kAcc: f.acc = imuFrom(d, "acc"); break;
    case Stream::kGyro: f.gyro = imuFrom(d, "gyro"); break;
    case Stream::kTof: f.tof = scalarFrom(d, "tof"); break;
    case Stream::kFlow: f.flow = flowFrom(d); break;
    case Stream::kBaro: f.baro = scalarFrom(d, "baro"); break;
    case Stream::kPose:
      f.pose = poseFrom(d);
      f.pose_has_orientation = d.contains("q");
      break;
  }
}

AnchorSurvey surveyFromArrays(const py::handle& ids, const py::handle& positions, const py::object& quaternions,
                              const std::string& source) {
  const Eigen::VectorXi id = toIntVector(ids, "ids");
  const RowMat p = toMatrix(positions, 3, "positions", /*allow_row=*/false);
  if (p.rows() != id.size()) {
    throw std::invalid_argument("positions: " + std::to_string(p.rows()) + " rows, expected " +
                                std::to_string(id.size()) + " (as ids)");
  }
  RowMat q;
  if (!quaternions.is_none()) {
    q = toMatrix(quaternions, 4, "quaternions", /*allow_row=*/false);
    if (q.rows() != id.size()) throw std::invalid_argument("quaternions: row count differs from ids");
  }
  AnchorSurvey s;
  s.source = source;
  for (Eigen::Index i = 0; i < id.size(); ++i) {
    Anchor a;
    a.id = id(i);
    a.w_p = row3(p, i);
    if (q.size()) a.w_q = rowQuat(q, i);
    s.anchors.push_back(a);
  }
  std::sort(s.anchors.begin(), s.anchors.end(), [](const Anchor& x, const Anchor& y) { return x.id < y.id; });
  for (std::size_t i = 1; i < s.anchors.size(); ++i)
    if (s.anchors[i].id == s.anchors[i - 1].id)
      throw std::invalid_argument("ids: duplicate anchor id " + std::to_string(s.anchors[i].id));
  return s;
}

py::dict residualArrays(const std::vector<TdoaResidual>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  py::array_t<std::int64_t> index(static_cast<py::ssize_t>(n));
  auto ia = newIntArray(n), ib = newIntArray(n);
  py::array_t<bool> airborne(static_cast<py::ssize_t>(n));
  RowMat x(n, 4), p(n, 3), q(n, 4);
  auto mi = index.mutable_unchecked<1>();
  auto ma = ia.mutable_unchecked<1>(), mb = ib.mutable_unchecked<1>();
  auto mair = airborne.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    const TdoaResidual& r = v[i];
    mi(i) = static_cast<std::int64_t>(r.index), ma(i) = r.id_a, mb(i) = r.id_b, mair(i) = r.airborne;
    x.row(i) << r.t_s, r.measured_m, r.predicted_m, r.residual_m;
    p.row(i) = r.w_p_b.transpose();
    q.row(i) << r.w_q_b.x(), r.w_q_b.y(), r.w_q_b.z(), r.w_q_b.w();
  }
  py::dict d;
  d["index"] = index, d["t"] = toNumpy(x.col(0), true), d["id_a"] = ia, d["id_b"] = ib;
  d["measured"] = toNumpy(x.col(1), true), d["predicted"] = toNumpy(x.col(2), true);
  d["residual"] = toNumpy(x.col(3), true), d["w_p_b"] = toNumpy(p), d["w_q_b"] = toNumpy(q);
  d["airborne"] = airborne;
  return d;
}

PoseTrackParams poseTrackParams(const py::dict& overrides) {
  PoseTrackParams p;
  for (const auto& [key, value] : overrides) {
    const std::string name = py::str(key);
    const double v = py::cast<double>(value);
    if (name == "max_gap_s") p.max_gap_s = v;
    else if (name == "max_attitude_jump_rad") p.max_attitude_jump_rad = v;
    else if (name == "max_angular_rate_radps") p.max_angular_rate_radps = v;
    else if (name == "max_glitch_run_s") p.max_glitch_run_s = v;
    else if (name == "max_position_jump_m") p.max_position_jump_m = v;
    else throw std::invalid_argument("unknown PoseTrack parameter '" + name + "'");
  }
  p.validate();
  return p;
}

}  // namespace

py::dict poseSamplesToDict(const std::vector<PoseSample>& samples) { return poseDict(samples); }

py::dict trajectoryToDict(const Trajectory& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  RowMat t(n, 1), p(n, 3), q(n, 4), s(n, 3), vel(n, 3), ba(n, 3), bg(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    t(i, 0) = v[i].t_s;
    p.row(i) = v[i].w_p_b.transpose();
    q.row(i) << v[i].w_q_b.x(), v[i].w_q_b.y(), v[i].w_q_b.z(), v[i].w_q_b.w();
    s.row(i) = v[i].sigma_p_m.transpose();
    vel.row(i) = v[i].w_v_b.transpose();
    ba.row(i) = v[i].b_acc_bias.transpose();
    bg.row(i) = v[i].b_gyro_bias.transpose();
  }
  py::dict d;
  d["t"] = toNumpy(t, true), d["p"] = toNumpy(p), d["q"] = toNumpy(q), d["sigma_p"] = toNumpy(s);
  d["v"] = toNumpy(vel), d["acc_bias"] = toNumpy(ba), d["gyro_bias"] = toNumpy(bg);
  return d;
}

Trajectory trajectoryFromDict(const py::dict& d) {
  const Eigen::VectorXd t = column(d, "t", "trajectory");
  const auto n = t.size();
  const RowMat p = block(d, "p", "trajectory", 3, n);
  const RowMat q = d.contains("q") ? block(d, "q", "trajectory", 4, n) : RowMat();
  const RowMat s = d.contains("sigma_p") ? block(d, "sigma_p", "trajectory", 3, n) : RowMat();
  const RowMat vel = d.contains("v") ? block(d, "v", "trajectory", 3, n) : RowMat();
  const RowMat ba = d.contains("acc_bias") ? block(d, "acc_bias", "trajectory", 3, n) : RowMat();
  const RowMat bg = d.contains("gyro_bias") ? block(d, "gyro_bias", "trajectory", 3, n) : RowMat();
  Trajectory out(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    out[i].t_s = t(i);
    out[i].w_p_b = row3(p, i);
    if (q.size()) out[i].w_q_b = rowQuat(q, i);
    if (s.size()) out[i].sigma_p_m = row3(s, i);
    if (vel.size()) out[i].w_v_b = row3(vel, i);
    if (ba.size()) out[i].b_acc_bias = row3(ba, i);
    if (bg.size()) out[i].b_gyro_bias = row3(bg, i);
  }
  return out;
}

/// Positions of the anchors of each id in `ids` (N, 3); KeyError naming the id when absent.
RowMat anchorPositions(const AnchorSurvey& survey, const Eigen::VectorXi& ids) {
  RowMat out(ids.size(), 3);
  for (Eigen::Index i = 0; i < ids.size(); ++i) out.row(i) = survey.position(ids(i)).transpose();
  return out;
}

namespace {

// ------------------------------------------------------------------------------------------ surveys
py::array_t<int> surveyIds(const AnchorSurvey& s) {
  auto out = newIntArray(static_cast<Eigen::Index>(s.anchors.size()));
  auto o = out.mutable_unchecked<1>();
  for (std::size_t i = 0; i < s.anchors.size(); ++i) o(i) = s.anchors[i].id;
  return out;
}

py::array_t<double> surveyPositions(const AnchorSurvey& s) {
  RowMat p(static_cast<Eigen::Index>(s.anchors.size()), 3);
  for (std::size_t i = 0; i < s.anchors.size(); ++i) p.row(i) = s.anchors[i].w_p;
  return toNumpy(p);
}

py::array_t<double> surveyQuaternions(const AnchorSurvey& s) {
  RowMat q(static_cast<Eigen::Index>(s.anchors.size()), 4);
  for (std::size_t i = 0; i < s.anchors.size(); ++i) {
    const Quat& w_q = s.anchors[i].w_q;
    q.row(i) << w_q.x(), w_q.y(), w_q.z(), w_q.w();
  }
  return toNumpy(q);
}

void bindAnchorSurvey(py::module_& m) {
  py::class_<AnchorSurvey>(m, "AnchorSurvey",
                           "Surveyed UWB anchors: ids, world positions [m] and orientations (x, y, z, w).")
      .def(py::init([](const py::handle& ids, const py::handle& positions, const py::object& quaternions,
                       const std::string& source) { return surveyFromArrays(ids, positions, quaternions, source); }),
           py::arg("ids"), py::arg("positions"), py::arg("quaternions") = py::none(), py::arg("source") = "",
           "Builds a survey from ids (N,), positions (N, 3) [m] and optional quaternions (N, 4) (x, y, z, w).")
      .def_property_readonly("ids", &surveyIds, "(N,) anchor ids, ascending")
      .def_property_readonly("positions", &surveyPositions,
                             "(N, 3) anchor positions in the world frame [m], in the order of ids")
      .def_property_readonly("quaternions", &surveyQuaternions, "(N, 4) anchor orientations (x, y, z, w)")
      .def_readwrite("source", &AnchorSurvey::source, "the file it was read from (named in messages)")
      .def("position", [](const AnchorSurvey& s, int id) { return toNumpy(s.position(id), true); }, py::arg("id"),
           "World position [m] of one anchor; KeyError when the id is absent.")
      .def("positions_of",
           [](const AnchorSurvey& s, const py::handle& ids) {
             return toNumpy(anchorPositions(s, toIntVector(ids, "ids")));
           },
           py::arg("ids"), "(N, 3) positions [m] of the anchors with the given ids (vectorized lookup).")
      .def("__contains__", &AnchorSurvey::contains)
      .def("__len__", [](const AnchorSurvey& s) { return s.anchors.size(); })
      .def("__repr__", [](const AnchorSurvey& s) {
        return "<AnchorSurvey " + std::to_string(s.anchors.size()) + " anchors from '" + s.source + "'>";
      });
}

// ------------------------------------------------------------------------------------------ flights
/// A stream of the flight as a read/write property: reading converts the whole stream to a dict (to_dict),
/// assigning a dict replaces it (setStream).
template <class Sample>
void defStream(py::class_<Flight>& c, const char* name, std::vector<Sample> Flight::*stream,
               py::dict (*to_dict)(const std::vector<Sample>&), const char* doc) {
  c.def_property(
      name, [stream, to_dict](const Flight& f) { return to_dict(f.*stream); },
      [name](Flight& f, const py::dict& d) { setStream(f, name, d); }, doc);
}

std::string flightRepr(const Flight& f) {
  std::string r = "<Flight '" + f.source + "'";
  for (const auto& s : kStreams) {
    if (!f.has(s.stream)) continue;
    std::size_t n = 0;
    switch (s.stream) {
      case Stream::kTdoa: n = f.tdoa.size(); break;
      case Stream::kTwr: n = f.twr.size(); break;
      case Stream::kAcc: n = f.acc.size(); break;
      case Stream::kGyro: n = f.gyro.size(); break;
      case Stream::kTof: n = f.tof.size(); break;
      case Stream::kFlow: n = f.flow.size(); break;
      case Stream::kBaro: n = f.baro.size(); break;
      case Stream::kPose: n = f.pose.size(); break;
    }
    r += std::string(" ") + s.name + "=" + std::to_string(n);
  }
  const auto [t0, t1] = f.timeSpan();
  return r + " t=[" + std::to_string(t0) + ", " + std::to_string(t1) + "] s>";
}

void bindFlight(py::module_& m) {
  py::class_<Flight> c(m, "Flight",
                       "A flight: every sensor stream as a dict of numpy arrays in SI units (see docs/python.md).\n"
                       "Reading a stream property converts the whole stream at once; assigning a dict replaces it.");
  c.def(py::init([](const py::kwargs& streams) {
          Flight f;
          for (const auto& [key, value] : streams) setStream(f, py::str(key), py::cast<py::dict>(value));
          return f;
        }),
        "Flight(tdoa={...}, acc={...}, ...): builds a flight from stream dicts.");
  defStream(c, "tdoa", &Flight::tdoa, &tdoaDict,
            "dict: t [s], id_a, id_b (int32), tdoa [m] = |p_tag − a_idB| − |p_tag − a_idA|");
  defStream(c, "twr", &Flight::twr, &twrDict, "dict: t [s], anchor_id, range [m]");
  defStream(c, "acc", &Flight::acc, &imuDict, "dict: t [s], value (N, 3) specific force [m/s², body]");
  defStream(c, "gyro", &Flight::gyro, &imuDict, "dict: t [s], value (N, 3) angular rate [rad/s, body]");
  defStream(c, "tof", &Flight::tof, &scalarDict, "dict: t [s], value [m]");
  defStream(c, "flow", &Flight::flow, &flowDict, "dict: t [s], delta_x, delta_y [counts]");
  defStream(c, "baro", &Flight::baro, &scalarDict, "dict: t [s], value [m above sea level]");
  defStream(c, "pose", &Flight::pose, &poseDict, "dict: t [s], p (N, 3) [m, world], q (N, 4) body→world (x, y, z, w)");
  c.def_readwrite("pose_has_orientation", &Flight::pose_has_orientation,
                  "the pose stream carries a quaternion (False: position only)")
      .def_readwrite("columns", &Flight::columns, "header columns of the source file (the writer reproduces them)")
      .def_readwrite("source", &Flight::source, "the file it was read from (named in messages)")
      .def("streams", &allStreams, "All non-empty streams: {name: stream dict}.")
      .def_property_readonly("present",
                             [](const Flight& f) {
                               std::vector<std::string> names;
                               for (const auto& s : kStreams)
                                 if (f.has(s.stream)) names.emplace_back(s.name);
                               return names;
                             },
                             "names of the non-empty streams")
      .def("time_span", &Flight::timeSpan, "(first, last) sample time over all streams [s]")
      .def(
          "window",
          [](const Flight& f, double t0, double t1) { return sliceFlight(f, t0, t1); },  // ValueError unless t0 < t1
          py::arg("t0"), py::arg("t1"),
          "The flight between the stamps t0 and t1 [s], every stream cut there (stamps kept): the log as a recording "
          "started at t0, e.g. in the air, and stopped at t1 would hold it (`uwbtdoa localize --window`).")
      .def("__repr__", &flightRepr);
}

// ------------------------------------------------------------------------------------- ground truth
py::dict interpolateTrack(const PoseTrack& track, const py::handle& t) {
  const RowMat ts = toMatrix(t, 0, "t");
  const Eigen::Index n = ts.rows();
  RowMat p = RowMat::Constant(n, 3, std::numeric_limits<double>::quiet_NaN());
  RowMat q = RowMat::Constant(n, 4, std::numeric_limits<double>::quiet_NaN());
  py::array_t<bool> valid(static_cast<py::ssize_t>(n));
  auto mv = valid.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto s = track.interpolate(ts(i, 0));
    mv(i) = s.has_value();
    if (!s) continue;
    p.row(i) = s->w_p_b.transpose();
    q.row(i) << s->w_q_b.x(), s->w_q_b.y(), s->w_q_b.z(), s->w_q_b.w();
  }
  py::dict d;
  d["t"] = toNumpy(ts.col(0), true), d["p"] = toNumpy(p), d["q"] = toNumpy(q), d["valid"] = valid;
  return d;
}

py::dict trackGlitches(const PoseTrack& t) {
  const auto& g = t.glitches();
  const auto n = static_cast<Eigen::Index>(g.size());
  py::array_t<std::int64_t> index(static_cast<py::ssize_t>(n));
  std::vector<std::string> kind;
  RowMat x(n, 2);
  auto mi = index.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    mi(i) = static_cast<std::int64_t>(g[i].index);
    x.row(i) << g[i].t_s, g[i].magnitude;
    kind.push_back(g[i].kind == PoseGlitchKind::kAttitude ? "attitude" : "position");
  }
  py::dict d;
  d["index"] = index, d["t"] = toNumpy(x.col(0), true);
  d["magnitude"] = toNumpy(x.col(1), true), d["kind"] = kind;
  return d;
}

void bindPoseTrack(py::module_& m) {
  py::class_<PoseTrack>(m, "PoseTrack",
                        "Ground truth as a function of time: the flight's pose samples minus detected glitches;\n"
                        "linear position / slerp attitude interpolation.")
      .def(py::init([](const Flight& f, const py::dict& params) { return PoseTrack(f, poseTrackParams(params)); }),
           py::arg("flight"), py::arg("params") = py::dict(),
           "params: overrides of PoseTrackParams (max_gap_s, max_attitude_jump_rad, max_angular_rate_radps,\n"
           "max_glitch_run_s, max_position_jump_m).")
      .def("interpolate", &interpolateTrack, py::arg("t"),
           "Pose at times t (N,): {t, p (N, 3), q (N, 4), valid (N,) bool}; NaN where there is no ground truth.")
      .def_property_readonly("samples", [](const PoseTrack& t) { return poseDict(t.samples()); },
                             "accepted samples {t, p, q}")
      .def_property_readonly("glitches", &trackGlitches,
                             "rejected samples {index, t, kind ('attitude'|'position'), magnitude}")
      .def_property_readonly("start_time", &PoseTrack::startTime, "first pose time [s]")
      .def_property_readonly("end_time", &PoseTrack::endTime, "last pose time [s]")
      .def_property_readonly("has_orientation", &PoseTrack::hasOrientation, "the track carries attitudes")
      .def("__len__", [](const PoseTrack& t) { return t.samples().size(); });
}

py::dict residuals(const Flight& flight, const AnchorSurvey& survey, const PoseTrack* track, const py::object& b_t_tag,
                   double airborne_min_z_m) {
  TdoaResidualParams params;
  if (!b_t_tag.is_none()) params.b_t_tag = row3(toMatrix(b_t_tag, 3, "b_t_tag"), 0);
  params.airborne_min_z_m = airborne_min_z_m;
  TdoaResidualReport report;
  std::vector<TdoaResidual> r;
  {
    py::gil_scoped_release release;
    const PoseTrack own = track ? PoseTrack() : PoseTrack(flight);
    r = tdoaResiduals(flight, survey, track ? *track : own, params, &report);
  }
  py::dict d = residualArrays(r);
  py::dict rep;
  rep["n_measurements"] = report.n_measurements, rep["n_residuals"] = report.n_residuals;
  rep["n_no_ground_truth"] = report.n_no_ground_truth, rep["n_unknown_anchor"] = report.n_unknown_anchor;
  d["report"] = rep;
  return d;
}

std::vector<std::string> surveyWarnings(const AnchorSurvey& survey, const Flight* flight, const py::object& positions) {
  std::vector<Vec3> p;
  if (!positions.is_none()) {
    const RowMat rows = toMatrix(positions, 3, "positions");
    for (Eigen::Index i = 0; i < rows.rows(); ++i) p.push_back(rows.row(i).transpose());
  } else if (flight) {
    for (const PoseSample& s : flight->pose) p.push_back(s.w_p_b);
  }
  const std::vector<InputIssue> issues =
      checkSurvey(survey, flight, p, !positions.is_none() ? "positions" : flight ? flight->source : "");
  throwOnError(issues);
  std::vector<std::string> out;
  for (const InputIssue& i : issues) out.push_back(i.text());
  return out;
}

void bindChecks(py::module_& m) {
  m.def("tdoa_residuals", &residuals, py::arg("flight"), py::arg("survey"), py::arg("track") = nullptr,
        py::arg("b_t_tag") = py::none(), py::arg("airborne_min_z_m") = 0.3,
        "TDoA residual r = measured − h(p_gt) of every measurement with ground truth (paper eq. 6, the GP target).\n"
        "track defaults to PoseTrack(flight). Returns arrays {index (into flight.tdoa), t, id_a, id_b, measured,\n"
        "predicted, residual, w_p_b (N, 3), w_q_b (N, 4), airborne} and report {n_measurements, n_residuals,\n"
        "n_no_ground_truth, n_unknown_anchor}.");
}

// --------------------------------------------------------------------------------------------- files
py::object readFlight(const std::string& path, const std::vector<std::string>& required, const AnchorSurvey* survey,
                      bool with_report) {
  FlightReadOptions options;
  for (const auto& name : required) options.required.push_back(streamFromName(name));
  options.survey = survey;
  return flightWithReport<ReadReport>(
      with_report, [&](ReadReport& report) { return readFlightCsv(path, options, &report); },
      [](const ReadReport& report) {
        py::dict r;
        r["n_rows"] = report.n_rows, r["n_bytes"] = report.n_bytes, r["notes"] = report.notes;
        return r;
      });
}

py::object importUsd(const std::string& path, bool salvage, bool with_report) {
  UsdReadOptions options;
  options.salvage = salvage;
  return flightWithReport<UsdImportReport>(
      with_report, [&](UsdImportReport& report) { return importUsdLog(path, options, &report); },
      [](const UsdImportReport& report) {
        py::list sources;
        for (const auto& s : report.sources) {
          py::dict d;
          d["stream"] = streamName(s.stream), d["event"] = s.event, d["fields"] = s.fields, d["count"] = s.count;
          sources.append(d);
        }
        py::dict r;
        r["sources"] = sources, r["notes"] = report.notes, r["t0_us"] = report.t0_us;
        return r;
      });
}

void bindFlightFiles(py::module_& m) {
  m.def("read_flight_csv", &readFlight, py::arg("path"), py::arg("required") = std::vector<std::string>{},
        py::arg("survey") = nullptr, py::arg("with_report") = false,
        "Reads a UTIL flight CSV (SI units in memory). required: stream names that must be present; survey: every\n"
        "anchor id must be surveyed. with_report=True returns (flight, {n_rows, n_bytes, notes}).\n"
        "ValueError 'file:line:column (field): ...' on bad data, OSError when the file cannot be read.");
  m.def(
      "write_flight_csv",
      [](const Flight& f, const std::string& path) {
        py::gil_scoped_release release;
        writeFlightCsv(f, path);
      },
      py::arg("flight"), py::arg("path"), "Writes a flight in the UTIL layout (read_flight_csv reads it back exactly).");
  m.def("import_usd_log", &importUsd, py::arg("path"), py::arg("salvage") = false, py::arg("with_report") = false,
        "Imports a Crazyflie uSD-card event log (cfusdlog, versions 1 and 2) as a flight, with UTIL's event-type\n"
        "mapping and units (docs/io.md section 6). salvage=True reads a log whose writing was cut (no valid CRC).\n"
        "with_report=True returns (flight, {sources: [{stream, event, fields, count}], notes, t0_us}).\n"
        "ValueError 'file: byte B, event K (type.field): ...' on bad data, OSError when the file cannot be read.");
  m.def(
      "write_usd_log",
      [](const Flight& f, const std::string& path) {
        py::gil_scoped_release release;
        writeUsdLog(usdLogFromFlight(f), path);
      },
      py::arg("flight"), py::arg("path"),
      "Writes a flight as the events UTIL recorded (cfusdlog version 2, float32 values in the file units);\n"
      "import_usd_log reads it back within float32 precision.");
}

void bindTrajectoryFiles(py::module_& m) {
  m.def(
      "read_trajectory_csv", [](const std::string& path) { return trajectoryToDict(readTrajectoryCsv(path)); },
      py::arg("path"),
      "Reads an estimated trajectory (t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz) into\n"
      "{t, p (N, 3), q (N, 4), sigma_p (N, 3), v (N, 3)}.");
  m.def(
      "write_trajectory_csv",
      [](const py::dict& trajectory, const std::string& path) { writeTrajectoryCsv(trajectoryFromDict(trajectory), path); },
      py::arg("trajectory"), py::arg("path"),
      "Writes a trajectory dict {t, p[, q, sigma_p, v]} as the trajectory CSV (missing fields: identity / zeros).");
  m.def(
      "write_trajectory_tum",
      [](const py::dict& trajectory, const std::string& path) { writeTrajectoryTum(trajectoryFromDict(trajectory), path); },
      py::arg("trajectory"), py::arg("path"),
      "Writes the poses of a trajectory dict {t, p, q} as TUM text (timestamp tx ty tz qx qy qz qw, space-\n"
      "separated, shortest round-trip numbers): the format evo and the SLAM trajectory tools read.");
}

void bindSurveyFiles(py::module_& m) {
  m.def(
      "read_cfclient_anchors", &readCfclientAnchors, py::arg("path"),
      "Reads the anchor positions the Crazyflie client's Loco Positioning tab saves (YAML: one {x, y, z} per\n"
      "anchor id) as an AnchorSurvey (`uwbtdoa survey`, docs/crazyflie.md).");
  m.def("check_survey", &surveyWarnings, py::arg("survey"), py::arg("flight") = nullptr,
        py::arg("positions") = py::none(),
        "The checks of `uwbtdoa survey` as a list of warnings with their numbers: colocated anchors, anchors in one\n"
        "plane, ids of the flight's TDoA missing from the survey, positions (N, 3) (default: the flight's motion\n"
        "capture) outside the anchors' box. ValueError for a survey no position can be computed from.");
  m.def("read_anchor_survey", &readAnchorSurvey, py::arg("path"), "Reads a UTIL anchor survey text file.");
  m.def("write_anchor_survey", &writeAnchorSurvey, py::arg("survey"), py::arg("path"),
        "Writes a survey that read_anchor_survey reads back exactly.");
}

}  // namespace

void bindIo(py::module_& m) {
  bindAnchorSurvey(m);
  bindFlight(m);
  bindPoseTrack(m);
  bindChecks(m);
  bindFlightFiles(m);
  bindTrajectoryFiles(m);
  bindSurveyFiles(m);
}

}  // namespace uwb::python
