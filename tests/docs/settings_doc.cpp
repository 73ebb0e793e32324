// SPDX-License-Identifier: MIT
// frappe-settings-doc: prints what the settings table (frappe/settings.h)
// makes of the committed files' generated blocks: `pyi` the keywords of
// frappe.Detector in python/frappe/__init__.pyi, `markdown` the table of
// docs/settings.md. scripts/generated.py puts them in (--write) or checks
// them (--check, the test generated-files).
#include <cstdio>
#include <string>
#include <string_view>

#include <frappe/settings.h>

namespace {

std::string pythonDefault(const frappe::Setting &s, const frappe::Config &c)
{
	if (s.isChoice()) {
		/* Appended, not "\"" + text: GCC 12's -Wrestrict misreads that. */
		std::string quoted = "\"";
		quoted += s.text(c);
		quoted += '"';
		return quoted;
	}
	std::string t = s.text(c);
	/* A float default reads as a float: 28 -> 28.0. */
	if (!s.isInteger() && t.find_first_of(".e") == std::string::npos)
		t += ".0";
	return t;
}

const char *pythonType(const frappe::Setting &s)
{
	return s.isChoice() ? "str" : s.isInteger() ? "int" : "float";
}

std::string surfaces(const frappe::Setting &s)
{
	std::string out = "C++";
	if (s.surfaces & frappe::kOnElement)
		out += ", element";
	if (s.surfaces & frappe::kOnCli)
		out += ", CLI";
	if (s.surfaces & frappe::kOnPython)
		out += ", Python";
	return out;
}

} // namespace

int main(int argc, char **argv)
{
	const std::string_view what = argc > 1 ? argv[1] : "";
	const frappe::Config defaults;
	if (what == "pyi") {
		for (const frappe::Setting &s : frappe::settings()) {
			if ((s.surfaces & frappe::kOnPython) && s.name != "dictionary")
				std::printf("        %s: %s = %s,\n", std::string(s.name).c_str(), pythonType(s),
					    pythonDefault(s, defaults).c_str());
		}
		return 0;
	}
	if (what == "markdown") {
		std::printf("| C++, Python | element, CLI | type | default | range | what it does | where |\n");
		std::printf("|---|---|---|---|---|---|---|\n");
		for (const frappe::Setting &s : frappe::settings()) {
			std::string range = s.rangeText();
			if (s.name == "dictionary")
				range = "`frappe-detect --dictionaries`";
			std::printf("| `%s` | `%s` | %s | `%s` | %s | %s | %s |\n", std::string(s.name).c_str(),
				    s.kebabName().c_str(), s.isChoice() ? "name" : pythonType(s),
				    s.text(defaults).c_str(), range.c_str(), std::string(s.doc).c_str(),
				    surfaces(s).c_str());
		}
		return 0;
	}
	std::fprintf(stderr, "usage: frappe-settings-doc pyi|markdown\n");
	return 2;
}
