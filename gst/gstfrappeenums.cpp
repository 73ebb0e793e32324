/* SPDX-License-Identifier: MIT
 *
 * gstfrappeenums.cpp: the enum types of frappedetect's properties.
 */
#include "gstfrappeenums.h"

#include <algorithm>
#include <cstddef>
#include <string>

#include <frappe/dictionary.h>

GType gst_frappe_mode_get_type(void)
{
	static GType type = 0;
	static const GEnumValue values[] = {
		{ GST_FRAPPE_MODE_NORMAL, "Every frame at full resolution", "normal" },
		{ GST_FRAPPE_MODE_ASCALE,
		  "Scale frames down from the size of the markers of the previous frame", "ascale" },
		{ GST_FRAPPE_MODE_TRACK,
		  "Search around the markers of the last frames and a band of the rest of the frame", "track" },
		{ 0, nullptr, nullptr },
	};
	if (g_once_init_enter(&type)) {
		GType t = g_enum_register_static("GstFrappeMode", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

GType gst_frappe_backend_get_type(void)
{
	static GType type = 0;
	static const GEnumValue values[] = {
		{ GST_FRAPPE_BACKEND_AUTO,
		  "The Raspberry Pi's QPUs when they can be used, else the CPU (with one warning on a Pi)", "auto" },
		{ GST_FRAPPE_BACKEND_CPU, "The reference CPU front end", "cpu" },
		{ GST_FRAPPE_BACKEND_VC4, "The QPU kernels on the VideoCore IV GPU (Pi Zero, 1, 2, 3)", "vc4" },
		{ GST_FRAPPE_BACKEND_VC4_EMU,
		  "The QPU kernels on an emulator: bit-exact with vc4, slow; for testing", "vc4-emu" },
		{ 0, nullptr, nullptr },
	};
	if (g_once_init_enter(&type)) {
		GType t = g_enum_register_static("GstFrappeBackend", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

GType gst_frappe_overlap_get_type(void)
{
	static GType type = 0;
	static const GEnumValue values[] = {
		{ GST_FRAPPE_OVERLAP_AUTO,
		  "stages when the front end runs on the QPUs (vc4, vc4-emu, auto that found them), else frames",
		  "auto" },
		{ GST_FRAPPE_OVERLAP_FRAMES, "Two whole frames at once, each on a detector and a thread of its own",
		  "frames" },
		{ GST_FRAPPE_OVERLAP_STAGES,
		  "One detector: the next frame's front end (the QPU passes) while this frame is traced", "stages" },
		{ 0, nullptr, nullptr },
	};
	if (g_once_init_enter(&type)) {
		GType t = g_enum_register_static("GstFrappeOverlap", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

/* Value names are the library's dictionary names ("apriltag_36h11"), nicks
 * the same with dashes ("apriltag-36h11"): GStreamer parses an enum by name
 * or by nick, so `dictionary=` takes both spellings. */
GType gst_frappe_dictionary_get_type(void)
{
	static GType type = 0;
	if (g_once_init_enter(&type)) {
		const auto dicts = frappe::dictionaries();
		GEnumValue *values = g_new0(GEnumValue, dicts.size() + 1);
		for (std::size_t i = 0; i < dicts.size(); ++i) {
			const std::string name(dicts[i].name);
			std::string nick = name;
			std::replace(nick.begin(), nick.end(), '_', '-');
			values[i].value = static_cast<gint>(i);
			values[i].value_name = g_intern_string(name.c_str());
			values[i].value_nick = g_intern_string(nick.c_str());
		}
		GType t = g_enum_register_static("GstFrappeDictionary", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

gint gst_frappe_dictionary_index(const char *name)
{
	const auto dicts = frappe::dictionaries();
	for (std::size_t i = 0; i < dicts.size(); ++i)
		if (dicts[i].name == name)
			return static_cast<gint>(i);
	return 0;
}

GstFrappeMode gst_frappe_mode_from_library(frappe::Mode mode)
{
	switch (mode) {
	case frappe::Mode::AScale: return GST_FRAPPE_MODE_ASCALE;
	case frappe::Mode::Track: return GST_FRAPPE_MODE_TRACK;
	default: return GST_FRAPPE_MODE_NORMAL;
	}
}

frappe::Mode gst_frappe_mode_to_library(GstFrappeMode mode)
{
	switch (mode) {
	case GST_FRAPPE_MODE_ASCALE: return frappe::Mode::AScale;
	case GST_FRAPPE_MODE_TRACK: return frappe::Mode::Track;
	default: return frappe::Mode::Normal;
	}
}

const char *gst_frappe_backend_nick(GstFrappeBackend backend)
{
	GEnumClass *klass = G_ENUM_CLASS(g_type_class_ref(GST_TYPE_FRAPPE_BACKEND));
	const GEnumValue *v = g_enum_get_value(klass, backend);
	const char *name = v ? v->value_nick : "auto";
	g_type_class_unref(klass);
	return name;
}
