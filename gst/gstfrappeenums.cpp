/* SPDX-License-Identifier: MIT
 *
 * gstfrappeenums.cpp: the enum types of frappedetect's properties.
 */
#include "gstfrappeenums.h"

#include <cstddef>
#include <string>

#include <frappe/marker_record.h>

#include "frappe_backend.h"

/* Made from frappe::backendNames(), the one list of the names: the enum's
 * values are its indices (GST_FRAPPE_BACKEND_AUTO ... _VC4_EMU). */
GType gst_frappe_backend_get_type(void)
{
	static GType type = 0;
	if (g_once_init_enter(&type)) {
		const auto names = frappe::backendNames();
		GEnumValue *values = g_new0(GEnumValue, names.size() + 1);
		for (std::size_t i = 0; i < names.size(); ++i) {
			values[i].value = static_cast<gint>(i);
			values[i].value_name = g_intern_string(std::string(names[i].doc).c_str());
			values[i].value_nick = g_intern_string(std::string(names[i].name).c_str());
		}
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

/* Made from frappe::markerFieldNames(), the one list of a marker's
 * fields: flag 1 << i is name i, in kebab-case. */
GType gst_frappe_json_fields_get_type(void)
{
	static GType type = 0;
	if (g_once_init_enter(&type)) {
		const auto names = frappe::markerFieldNames();
		GFlagsValue *values = g_new0(GFlagsValue, names.size());
		for (std::size_t i = 1; i < names.size(); ++i) {
			std::string nick(names[i]);
			for (char &c : nick)
				c = c == '_' ? '-' : c;
			values[i - 1].value = 1u << i;
			values[i - 1].value_name = g_intern_string(("The marker's " + std::string(names[i])).c_str());
			values[i - 1].value_nick = g_intern_string(nick.c_str());
		}
		GType t = g_flags_register_static("GstFrappeJsonFields", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

const char *gst_frappe_backend_nick(GstFrappeBackend backend)
{
	GEnumClass *klass = G_ENUM_CLASS(g_type_class_ref(GST_TYPE_FRAPPE_BACKEND));
	const GEnumValue *v = g_enum_get_value(klass, backend);
	const char *name = v ? v->value_nick : "auto";
	g_type_class_unref(klass);
	return name;
}
