/** @file sim.h
 *  @brief Umbrella header of the sim module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/sim/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/ImuSignature.h"
#include "uwb/sim/Kinematics.h"
#include "uwb/sim/ResidualProfile.h"
#include "uwb/sim/Scenario.h"
#include "uwb/sim/SimParams.h"
#include "uwb/sim/SimulatedBias.h"
#include "uwb/sim/Swarm.h"
#include "uwb/sim/TdoaResiduals.h"
#include "uwb/sim/Trajectory.h"
