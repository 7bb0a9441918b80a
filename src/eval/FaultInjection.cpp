/** @file FaultInjection.cpp
 *  @brief Fault injection into recorded flights.
 */
#include "uwb/eval/FaultInjection.h"

#include <algorithm>
#include <random>

namespace uwb {

std::string toString(FaultKind kind) {
  switch (kind) {
    case FaultKind::kOutlierBurst: return "outliers 20% ±5 m, 5 s";
    case FaultKind::kGarbageTdoa: return "garbage TDoA, 5 s";
    case FaultKind::kDeadAnchor: return "anchor dead, 10 s";
    case FaultKind::kAnchorSurveyOff: return "anchor surveyed 1 m off";
    case FaultKind::kImuDropout: return "IMU dropout 0.5 s";
    case FaultKind::kAccClipping: return "acc clipped at 1.2 g, 2 s";
    case FaultKind::kClockJumpTdoa: return "TDoA clock +0.5 s";
    case FaultKind::kClockJumpAll: return "all clocks +5 s";
    case FaultKind::kClockOffsetTdoa: return "TDoA clock 0.5 s late, whole flight";
    case FaultKind::kSurveyShifted: return "survey shifted 10 m";
    case FaultKind::kSurveyOtherArena: return "survey of another arena (ids on other anchors)";
  }
  return "unknown";
}

std::vector<FaultSpec> standardFaults(double t_air0_s, double t_air1_s, int anchor_id) {
  const double tm = 0.5 * (t_air0_s + t_air1_s);
  return {
      {FaultKind::kOutlierBurst, tm - 2.5, tm + 2.5, anchor_id, 1},
      {FaultKind::kGarbageTdoa, tm - 2.5, tm + 2.5, anchor_id, 2},
      {FaultKind::kDeadAnchor, tm - 5.0, tm + 5.0, anchor_id, 3},
      {FaultKind::kAnchorSurveyOff, t_air0_s, t_air1_s, anchor_id, 4},
      {FaultKind::kImuDropout, tm, tm + 0.5, anchor_id, 5},
      {FaultKind::kAccClipping, tm - 1.0, tm + 1.0, anchor_id, 6},
      {FaultKind::kClockJumpTdoa, tm, tm, anchor_id, 7},
      {FaultKind::kClockJumpAll, tm, tm, anchor_id, 8},
      {FaultKind::kClockOffsetTdoa, t_air0_s, t_air1_s, anchor_id, 9},
      {FaultKind::kSurveyShifted, t_air0_s, t_air1_s, anchor_id, 10},
      {FaultKind::kSurveyOtherArena, t_air0_s, t_air1_s, anchor_id, 11},
  };
}

void injectFault(const FaultSpec& f, Flight& flight, AnchorSurvey& survey) {
  std::mt19937_64 rng(f.seed);
  const auto inside = [&](double t) { return t >= f.t0_s && t <= f.t1_s; };
  switch (f.kind) {
    case FaultKind::kOutlierBurst: {
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (TdoaMeasurement& m : flight.tdoa)
        if (inside(m.t_s) && u(rng) < 0.2) m.tdoa_m += u(rng) < 0.5 ? -5.0 : 5.0;
      break;
    }
    case FaultKind::kGarbageTdoa: {
      std::uniform_real_distribution<double> u(-10.0, 10.0);
      for (TdoaMeasurement& m : flight.tdoa)
        if (inside(m.t_s)) m.tdoa_m = u(rng);
      break;
    }
    case FaultKind::kDeadAnchor:
      std::erase_if(flight.tdoa, [&](const TdoaMeasurement& m) {
        return inside(m.t_s) && (m.id_a == f.anchor_id || m.id_b == f.anchor_id);
      });
      break;
    case FaultKind::kAnchorSurveyOff:
      for (Anchor& a : survey.anchors)
        if (a.id == f.anchor_id) a.w_p += Vec3(1.0, 0.0, 0.0);
      break;
    case FaultKind::kImuDropout:
      std::erase_if(flight.acc, [&](const ImuSample& s) { return inside(s.t_s); });
      std::erase_if(flight.gyro, [&](const ImuSample& s) { return inside(s.t_s); });
      break;
    case FaultKind::kAccClipping: {
      const double lim = 1.2 * kGravity_mps2;
      for (ImuSample& s : flight.acc)
        if (inside(s.t_s)) s.b_value = s.b_value.cwiseMax(-lim).cwiseMin(lim);
      break;
    }
    case FaultKind::kClockJumpTdoa:
      for (TdoaMeasurement& m : flight.tdoa)
        if (m.t_s >= f.t0_s) m.t_s += 0.5;
      break;
    case FaultKind::kClockJumpAll: {
      const auto shift = [&](auto& stream) {
        for (auto& s : stream)
          if (s.t_s >= f.t0_s) s.t_s += 5.0;
      };
      shift(flight.tdoa), shift(flight.acc), shift(flight.gyro), shift(flight.tof), shift(flight.flow);
      shift(flight.baro), shift(flight.pose);
      break;
    }
    case FaultKind::kClockOffsetTdoa:
      for (TdoaMeasurement& m : flight.tdoa) m.t_s += 0.5;
      break;
    case FaultKind::kSurveyShifted:
      for (Anchor& a : survey.anchors) a.w_p += Vec3(10.0, 0.0, 0.0);
      break;
    case FaultKind::kSurveyOtherArena: {
      // each id gets the next anchor's position: the same kind of constellation, not this one (a rigid motion
      // of the whole survey would leave every TDoA unchanged)
      if (survey.anchors.size() < 2) break;
      const Vec3 first = survey.anchors.front().w_p;
      for (std::size_t i = 0; i + 1 < survey.anchors.size(); ++i) survey.anchors[i].w_p = survey.anchors[i + 1].w_p;
      survey.anchors.back().w_p = first;
      break;
    }
  }
}

}  // namespace uwb
