/** @file core.h
 *  @brief Umbrella header of the core module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/core/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/core/Angle.h"
#include "uwb/core/Error.h"
#include "uwb/core/Smoothstep.h"
#include "uwb/core/Strings.h"
#include "uwb/core/Tdoa.h"
#include "uwb/core/Types.h"
