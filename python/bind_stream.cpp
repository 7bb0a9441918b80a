/** @file bind_stream.cpp
 *  @brief Python bindings of the online estimator: `uwbtdoa.Estimator`, events pushed one at a time in time order,
 *         the current estimate read as a dict of numpy arrays (docs/python.md, "Online estimation").
 */
#include "bindings.h"
#include "uwb/filter/Estimator.h"

namespace uwb::python {
namespace {

AnchorTable anchorTableFromDict(const py::dict& anchors, double sigma_m) {
  AnchorTable table;
  for (const auto& [key, value] : anchors) {
    const int id = py::cast<int>(key);
    const RowMat p = toMatrix(value, 3, "anchors");
    table.set(id, Vec3(row3(p, 0)), sigma_m);
  }
  return table;
}

Vec3 vec3(const py::handle& v, const char* name) { return Vec3(row3(toMatrix(v, 3, name), 0)); }

py::dict estimateDict(const LocalizerEstimate& e) {
  py::dict d;
  const Quat& q = e.x.w_q_b;
  d["t"] = e.t_s;
  d["p"] = toNumpy(e.x.w_p_b, true);
  d["q"] = toNumpy(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()), true);
  d["v"] = toNumpy(e.x.w_v_b, true);
  d["sigma_p"] = toNumpy(e.sigma_p_m, true);
  d["cov_pose"] = toNumpy(e.cov_pose);
  d["phase"] = toString(e.phase);
  return d;
}

}  // namespace

void bindStream(py::module_& m) {
  py::class_<Estimator>(m, "Estimator",
                        "The online estimator (C++ uwb::Estimator): push sensor events in time order, read the\n"
                        "current estimate. The same events in the same order give localize_flight's estimates.")
      .def(py::init([](const py::dict& params, const py::dict& anchors, const std::string& preset) {
             const EkfParams p = ekfParamsFromPython(preset, params);
             return std::make_unique<Estimator>(p, anchorTableFromDict(anchors, p.anchor_sigma_m));
           }),
           py::arg("params") = py::dict(), py::arg("anchors") = py::dict(), py::arg("preset") = "defaults",
           "params: EkfParams overrides as in localize_flight; anchors: {id: (x, y, z)} [m], at least 4.")
      .def(
          "add_imu",
          [](Estimator& e, double t_s, const py::handle& acc, const py::handle& gyro) {
            ImuReading imu;
            imu.b_acc_mps2 = vec3(acc, "acc");
            imu.b_gyro_radps = vec3(gyro, "gyro");
            e.addImu(t_s, imu);
          },
          py::arg("t"), py::arg("acc"), py::arg("gyro"),
          "One IMU sample: specific force [m/s²] and angular rate [rad/s], body frame.")
      .def(
          "add_tdoa",
          [](Estimator& e, double t_s, int id_a, int id_b, double tdoa_m) { e.addTdoa({t_s, id_a, id_b, tdoa_m}); },
          py::arg("t"), py::arg("id_a"), py::arg("id_b"), py::arg("tdoa_m"),
          "One TDoA: ‖p − a_idB‖ − ‖p − a_idA‖ [m].")
      .def(
          "add_tof", [](Estimator& e, double t_s, double range_m) { e.addTof({t_s, range_m}); }, py::arg("t"),
          py::arg("range_m"), "One downward range [m] (used with params fuse_tof).")
      .def_property_readonly("ready", &Estimator::ready, "The position is known (estimates are meaningful).")
      .def_property_readonly("time", &Estimator::time, "Stamp of the latest event [s].")
      .def_property_readonly(
          "summary", [](const Estimator& e) { return summaryDict(e.summary(), e.params()); },
          "The counts so far, as localize_flight's summary; sensor_range: the samples skipped outside the sensors'\n"
          "physical ranges (filter.md F31), sensor_range_warnings: one sentence per sensor.")
      .def(
          "estimate", [](const Estimator& e) { return estimateDict(e.estimate()); },
          "{t, p (3,), q (4,) w x y z, v (3,), sigma_p (3,), cov_pose (6, 6) of (δp, δθ), phase}. t is the\n"
          "latest event's stamp.");
}

}  // namespace uwb::python
