// SPDX-License-Identifier: MIT
// frappe/frappe.h: the whole public API of frappe-core.
#pragma once

#include "frappe/camera.h"
#include "frappe/candidate_warp.h"
#include "frappe/config.h"
#include "frappe/detector.h"
#include "frappe/dictionary.h"
#include "frappe/edge_map.h"
#include "frappe/homography.h"
#include "frappe/image.h"
#include "frappe/marker.h"
#include "frappe/pipeline.h"
#include "frappe/pose.h"
#include "frappe/render.h"
#include "frappe/marker_record.h"
#include "frappe/version.h"
#include "frappe/settings.h"
