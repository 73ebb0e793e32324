// SPDX-License-Identifier: MIT
// frappe/frappe.h: the user's API of frappe-core, the first of the public
// headers' three tiers (docs/install.md):
//   1. the user's API, here: detect, configure, pose, render, write;
//   2. what a backend implements, frappe/backend.h: the front end's and the
//      warp's interfaces and their shared arithmetic (vc4/ implements them);
//   3. test helpers and the stages' internals: frappe::detail in src/ and
//      tests/support, linked through frappe-core-internal, never installed.
#pragma once

#include "frappe/bundle.h"
#include "frappe/camera.h"
#include "frappe/config.h"
#include "frappe/detector.h"
#include "frappe/dictionary.h"
#include "frappe/image.h"
#include "frappe/layout.h"
#include "frappe/marker.h"
#include "frappe/marker_record.h"
#include "frappe/pipeline.h"
#include "frappe/pose.h"
#include "frappe/render.h"
#include "frappe/settings.h"
#include "frappe/version.h"
