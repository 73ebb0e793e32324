# SPDX-License-Identifier: MIT
# Source this to use frappedetect from a build directory without installing:
#   . examples/env.sh [BUILD_DIR]          (default: ./build next to examples/)
# It points GStreamer at the plugin and keeps a private registry file so
# an installed copy of the plugin is never picked up by mistake.
_frappe_root="$(cd "$(dirname "${BASH_SOURCE[0]:-$0}")/.." && pwd)"
_frappe_build="${1:-${FRAPPE_BUILD_DIR:-$_frappe_root/build}}"
export GST_PLUGIN_PATH="$_frappe_build/gst${GST_PLUGIN_PATH:+:$GST_PLUGIN_PATH}"
export GST_REGISTRY="${GST_REGISTRY:-$_frappe_build/gst/registry.bin}"
export LD_LIBRARY_PATH="$_frappe_build/gst${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
unset _frappe_root _frappe_build
