/** @file model.h
 *  @brief Umbrella header of the model module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/model/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/model/TdoaFeature.h"
#include "uwb/model/TdoaLinearization.h"
#include "uwb/model/TdoaModel.h"
