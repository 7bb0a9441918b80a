/** @file graph.h
 *  @brief Umbrella header of the graph module (STYLE.md, as in albatross and Ceres): every public header of
 *         include/uwb/graph/, so that one include gives the whole module.
 */
#pragma once

#include "uwb/graph/Cooperative.h"
#include "uwb/graph/GaussianMessage.h"
#include "uwb/graph/HalfLine.h"
#include "uwb/graph/Nodes.h"
#include "uwb/graph/TdoaCorrection.h"
#include "uwb/graph/TdoaNode.h"
