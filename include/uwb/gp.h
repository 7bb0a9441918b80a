/** @file gp.h
 *  @brief Umbrella header of the gp module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/gp/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/gp/Kernel.h"
#include "uwb/gp/PredictTile.h"
#include "uwb/gp/Svgp.h"
#include "uwb/gp/SvgpTrainer.h"
