/** @file bind_sim.cpp
 *  @brief Python bindings of uwb/sim: simulate a whole Crazyflie flight (UTIL layout) with its truth.
 *
 *  Parameters are passed as plain dicts of overrides (field names of TrajectoryParams, SimParams and its
 *  sub-structs, as in the C++ headers), so every knob is reachable without a Python class per struct.
 */
#include <functional>
#include <map>

#include "bindings.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"
#include "uwb/sim/SimParams.h"
#include "uwb/sim/Trajectory.h"

namespace uwb::python {
namespace {

using namespace uwb::sim;

Setters<TrajectoryParams> trajectorySetters() {
  Setters<TrajectoryParams> s;
  using P = TrajectoryParams;
  for (const auto& [n, f] : std::vector<std::pair<std::string, double P::*>>{
           {"duration_s", &P::duration_s}, {"ground_before_s", &P::ground_before_s},
           {"ground_after_s", &P::ground_after_s}, {"takeoff_s", &P::takeoff_s}, {"landing_s", &P::landing_s},
           {"speed_ramp_s", &P::speed_ramp_s}, {"ground_z_m", &P::ground_z_m}, {"radius_m", &P::radius_m},
           {"height_m", &P::height_m}, {"omega_rps", &P::omega_rps}, {"sine_amplitude_m", &P::sine_amplitude_m},
           {"sine_omega_ratio", &P::sine_omega_ratio}, {"figure8_half_length_m", &P::figure8_half_length_m},
           {"figure8_half_width_m", &P::figure8_half_width_m}, {"figure8_omega_rps", &P::figure8_omega_rps},
           {"zigzag_half_x_m", &P::zigzag_half_x_m}, {"zigzag_half_y_m", &P::zigzag_half_y_m},
           {"zigzag_z_min_m", &P::zigzag_z_min_m}, {"zigzag_z_max_m", &P::zigzag_z_max_m},
           {"zigzag_speed_mps", &P::zigzag_speed_mps}, {"zigzag_sweep_ratio", &P::zigzag_sweep_ratio},
           {"yaw0_rad", &P::yaw0_rad}, {"yaw_rate_rps", &P::yaw_rate_rps}})
    addField(s, n, f);
  s["shape"] = [](P& p, const py::handle& v) { p.shape = parseTrajectoryShape(py::cast<std::string>(v)); };
  s["yaw_mode"] = [](P& p, const py::handle& v) {
    const auto m = py::cast<std::string>(v);
    if (m == "constant-rate") p.yaw_mode = YawMode::kConstantRate;
    else if (m == "constant") p.yaw_mode = YawMode::kConstant;
    else throw std::invalid_argument("yaw_mode: expected 'constant-rate' or 'constant', got '" + m + "'");
  };
  s["w_center_xy"] = [](P& p, const py::handle& v) {
    const RowMat c = toMatrix(v, 2, "w_center_xy");
    p.w_center_xy = Vec2(c(0, 0), c(0, 1));
  };
  return s;
}

Setters<SimParams> simSetters() {
  Setters<SimParams> s;
  const auto sub = [&s](const std::string& prefix, auto member, auto fields) {
    for (const auto& field : fields) {  // no structured binding: clang 14 cannot capture one in the lambda
      const auto f = field.second;
      s[prefix + field.first] = [member, f](SimParams& p, const py::handle& v) {  // cast errors: applyOverrides
        (p.*member).*f = py::cast<std::remove_reference_t<decltype((p.*member).*f)>>(v);
      };
    }
  };
  using I = ImuParams;
  sub("imu.", &SimParams::imu,
      std::vector<std::pair<std::string, double I::*>>{{"rate_hz", &I::rate_hz},
                                                       {"acc_noise_std_mps2", &I::acc_noise_std_mps2},
                                                       {"acc_bias_std_mps2", &I::acc_bias_std_mps2},
                                                       {"acc_bias_rw_mps2_sqrt_s", &I::acc_bias_rw_mps2_sqrt_s},
                                                       {"gyro_noise_std_rps", &I::gyro_noise_std_rps},
                                                       {"gyro_bias_std_rps", &I::gyro_bias_std_rps},
                                                       {"gyro_bias_rw_rps_sqrt_s", &I::gyro_bias_rw_rps_sqrt_s}});
  using Po = PoseParams;
  sub("pose.", &SimParams::pose,
      std::vector<std::pair<std::string, double Po::*>>{{"rate_hz", &Po::rate_hz},
                                                        {"position_quantum_m", &Po::position_quantum_m},
                                                        {"quat_quantum", &Po::quat_quantum}});
  using T = TdoaScheduleParams;
  sub("tdoa.", &SimParams::tdoa,
      std::vector<std::pair<std::string, double T::*>>{{"rate_hz", &T::rate_hz},
                                                       {"jitter_fraction", &T::jitter_fraction}});
  sub("tdoa.", &SimParams::tdoa, std::vector<std::pair<std::string, bool T::*>>{{"tdoa3", &T::tdoa3}});
  using B = BiasParams;
  sub("bias.", &SimParams::bias,
      std::vector<std::pair<std::string, double B::*>>{
          {"antenna_rms_m", &B::antenna_rms_m}, {"anchor_pattern_rms_m", &B::anchor_pattern_rms_m},
          {"anchor_offset_std_m", &B::anchor_offset_std_m}, {"nlos_bias_m", &B::nlos_bias_m},
          {"nlos_elevation_rad", &B::nlos_elevation_rad}, {"nlos_width_rad", &B::nlos_width_rad},
          {"nlos_azimuth_gain", &B::nlos_azimuth_gain}, {"nlos_azimuth_rad", &B::nlos_azimuth_rad},
          {"multipath_std_m", &B::multipath_std_m}, {"multipath_length_m", &B::multipath_length_m},
          {"noise_std_m", &B::noise_std_m}, {"outlier_probability", &B::outlier_probability},
          {"outlier_scale_m", &B::outlier_scale_m}, {"outlier_dof", &B::outlier_dof},
          {"outlier_max_m", &B::outlier_max_m}, {"burst_probability", &B::burst_probability},
          {"burst_length_s", &B::burst_length_s}, {"burst_scale_m", &B::burst_scale_m},
          {"ground_low_anchor_z_m", &B::ground_low_anchor_z_m},
          {"ground_low_min_m", &B::ground_low_min_m}, {"ground_low_max_m", &B::ground_low_max_m},
          {"ground_high_abs_m", &B::ground_high_abs_m}, {"ground_noise_std_m", &B::ground_noise_std_m},
          {"ground_blend_height_m", &B::ground_blend_height_m}});
  sub("bias.", &SimParams::bias,
      std::vector<std::pair<std::string, bool B::*>>{{"enabled", &B::enabled}, {"ground_effect", &B::ground_effect}});
  sub("bias.", &SimParams::bias,
      std::vector<std::pair<std::string, int B::*>>{{"antenna_degree", &B::antenna_degree},
                                                    {"multipath_features", &B::multipath_features}});
  s["b_t_tag"] = [](SimParams& p, const py::handle& v) { p.b_t_tag = row3(toMatrix(v, 3, "b_t_tag"), 0); };
  s["bias.field_seed"] = [](SimParams& p, const py::handle& v) { p.bias.field_seed = py::cast<std::uint64_t>(v); };
  s["write_full_util_header"] = [](SimParams& p, const py::handle& v) { p.write_full_util_header = py::cast<bool>(v); };
  return s;
}

py::dict poseArrays(const std::vector<PoseSample>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  RowMat t(n, 1), p(n, 3), q(n, 4);
  for (Eigen::Index i = 0; i < n; ++i) {
    t(i, 0) = v[i].t_s;
    p.row(i) = v[i].w_p_b.transpose();
    q.row(i) << v[i].w_q_b.x(), v[i].w_q_b.y(), v[i].w_q_b.z(), v[i].w_q_b.w();
  }
  py::dict d;
  d["t"] = toNumpy(t, true), d["p"] = toNumpy(p), d["q"] = toNumpy(q);
  return d;
}

py::dict tdoaTruthArrays(const std::vector<TdoaTruth>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  RowMat x(n, 6);
  py::array_t<bool> on_ground(static_cast<py::ssize_t>(n)), airborne(static_cast<py::ssize_t>(n));
  auto og = on_ground.mutable_unchecked<1>(), ab = airborne.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& e = v[i].error;
    x.row(i) << v[i].tdoa_true_m, e.pattern_m, e.multipath_m, e.noise_m, e.outlier_m, e.ground_m;
    og(i) = v[i].on_ground, ab(i) = v[i].airborne;
  }
  py::dict d;
  const char* names[] = {"tdoa_true", "pattern", "multipath", "noise", "outlier", "ground"};
  for (int k = 0; k < 6; ++k) d[names[k]] = toNumpy(x.col(k), true);
  d["error"] = toNumpy((x.col(1) + x.col(2) + x.col(3) + x.col(4) + x.col(5)).eval(), true);
  d["on_ground"] = on_ground, d["airborne"] = airborne;
  return d;
}

py::dict imuTruthArrays(const std::vector<ImuTruth>& v) {
  const auto n = static_cast<Eigen::Index>(v.size());
  RowMat f(n, 3), w(n, 3), ba(n, 3), bg(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    f.row(i) = v[i].b_specific_force.transpose(), w.row(i) = v[i].b_omega.transpose();
    ba.row(i) = v[i].b_acc_bias.transpose(), bg.row(i) = v[i].b_gyro_bias.transpose();
  }
  py::dict d;
  d["specific_force"] = toNumpy(f), d["omega"] = toNumpy(w), d["acc_bias"] = toNumpy(ba), d["gyro_bias"] = toNumpy(bg);
  return d;
}

}  // namespace

void bindSim(py::module_& m) {
  m.def("anchor_preset_names", &anchorPresetNames, "Names anchor_preset accepts.");
  m.def("anchor_preset", &anchorPreset, py::arg("name"), py::arg("data_dir") = "",
        "Anchor constellation by name ('paper' built in; 'util-const1'..4 read below data_dir).");
  m.def(
      "simulate_flight",
      [](const std::string& shape, double duration_s, const py::object& anchors, std::uint64_t seed,
         const py::dict& trajectory, const py::dict& params, bool noise_free, const std::string& data_dir) {
        AnchorSurvey survey;
        if (anchors.is_none()) survey = paperAnchors();
        else if (py::isinstance<py::str>(anchors)) survey = anchorPreset(py::cast<std::string>(anchors), data_dir);
        else survey = py::cast<AnchorSurvey>(anchors);
        Scenario scenario = makeScenario(survey, parseTrajectoryShape(shape), duration_s);
        applyOverrides(scenario.trajectory, trajectorySetters(), trajectory, "trajectory");
        SimParams sp = noise_free ? SimParams::noiseFree() : SimParams{};
        applyOverrides(sp, simSetters(), params, "simulation");
        SimResult r;
        {
          py::gil_scoped_release release;
          r = simulateFlight(scenario, sp, seed);
        }
        py::dict out;
        out["tdoa_truth"] = tdoaTruthArrays(r.tdoa_truth);
        out["imu_truth"] = imuTruthArrays(r.imu_truth);
        out["pose_exact"] = poseArrays(r.pose_exact);
        out["survey"] = py::cast(std::move(r.survey));
        out["flight"] = py::cast(std::move(r.flight));
        return out;
      },
      py::arg("shape") = "circle", py::arg("duration_s") = 60.0, py::arg("anchors") = py::none(),
      py::arg("seed") = 1, py::arg("trajectory") = py::dict(), py::arg("params") = py::dict(),
      py::arg("noise_free") = false, py::arg("data_dir") = "",
      "Simulates a Crazyflie flight (IMU, Vicon pose, TDoA2 or TDoA3 with a pose-dependent bias) in the UTIL layout.\n"
      "shape: 'zigzag' | 'circle' | 'circle-sine' | 'figure8'; anchors: None ('paper'), a preset name or an\n"
      "AnchorSurvey; trajectory: overrides of TrajectoryParams fields (e.g. {'radius_m': 1.2}); params: overrides\n"
      "of SimParams as 'imu.rate_hz', 'bias.noise_std_m', ... Deterministic per seed. Returns a dict: flight,\n"
      "survey, tdoa_truth {tdoa_true, error, pattern, multipath, noise, outlier, ground, on_ground, airborne}\n"
      "(one entry per flight.tdoa row), imu_truth {specific_force, omega, acc_bias, gyro_bias}, pose_exact {t, p, q}.");
}

}  // namespace uwb::python
