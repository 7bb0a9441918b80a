/** @file io.h
 *  @brief Umbrella header of the io module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/io/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/io/Airborne.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/Flight.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/JsonFile.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/io/ResidualStats.h"
#include "uwb/io/SurveyCheck.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/io/UsdImport.h"
#include "uwb/io/UsdLog.h"
#include "uwb/io/UtilCsv.h"
