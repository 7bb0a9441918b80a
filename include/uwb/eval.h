/** @file eval.h
 *  @brief Umbrella header of the eval module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/eval/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/eval/BiasCalibration.h"
#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/EstimateChecks.h"
#include "uwb/eval/Evaluation.h"
#include "uwb/eval/EvaluationTable.h"
#include "uwb/eval/FaultInjection.h"
#include "uwb/eval/FlightSummary.h"
#include "uwb/eval/Localization.h"
#include "uwb/eval/LocalizationJson.h"
#include "uwb/eval/ProtocolScenarios.h"
#include "uwb/eval/RunDiagnostics.h"
#include "uwb/eval/SignatureMatrix.h"
#include "uwb/eval/SwarmLocalization.h"
#include "uwb/eval/TrajectoryMetrics.h"
