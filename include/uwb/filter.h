/** @file filter.h
 *  @brief Umbrella header of the filter module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/filter/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/filter/AnchorRangeBias.h"
#include "uwb/filter/AntennaBias.h"
#include "uwb/filter/BiasFloor.h"
#include "uwb/filter/BiasLevel.h"
#include "uwb/filter/BiasGuard.h"
#include "uwb/filter/CooperativeRange.h"
#include "uwb/filter/DescentBound.h"
#include "uwb/filter/Ekf.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/FlightMode.h"
#include "uwb/filter/FloorLevelAnchors.h"
#include "uwb/filter/InMotionAlignment.h"
#include "uwb/filter/Multilateration.h"
#include "uwb/filter/NavState.h"
#include "uwb/filter/OutlierGate.h"
#include "uwb/filter/QuadImuProcess.h"
#include "uwb/filter/RestDetector.h"
#include "uwb/filter/RestGyroWindow.h"
#include "uwb/filter/SensorEvents.h"
#include "uwb/filter/SensorRange.h"
#include "uwb/filter/StartReplay.h"
#include "uwb/filter/StartUp.h"
#include "uwb/filter/StateIndex.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/filter/TofUpdate.h"
