// SPDX-License-Identifier: MIT
// frappe/backend.h: the second tier of the public headers (frappe/frappe.h
// lists the three): what a backend implements to run a stage elsewhere
// than on the CPU (vc4/ does, on the Raspberry Pi's QPUs): the front end's
// interface and its edge map, the warp's batch interface, the warp's
// integer arithmetic every backend must reproduce bit for bit, and the
// plane-to-plane maps it is built on. Detector::setFrontEnd() and
// setWarper() take the implementations.
#pragma once

#include "frappe/candidate_warp.h"
#include "frappe/edge_map.h"
#include "frappe/fixed_warp.h"
#include "frappe/homography.h"
