// SPDX-License-Identifier: MIT
// Dictionaries of the user's own, read from a file: the built-in
// dictionaries' text format, or OpenCV's aruco YAML (or its XML twin).
#include "frappe/dictionary.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdio>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "small_file.h"
#include "utf8.h"

namespace frappe {

namespace {

constexpr std::size_t kMaxFileBytes = 64u << 20;
constexpr std::size_t kMaxLineBytes = 4096;
constexpr std::size_t kMaxNameBytes = 128;
/* The min_hamming check compares every pair of codes in 4 rotations: at
 * 4096 codes that is 34 million comparisons, a few tens of milliseconds. */
constexpr int kMaxCodes = 4096;
/* A layout family's file may hold a family as large as AprilTag 3's
 * (tagCircle49h12: 65535 codes); beyond kMaxCodes its header's distance
 * is taken, the codes only checked for repeats. */
constexpr int kMaxLayoutCodes = 65536;
constexpr int kMinSide = 3, kMaxSide = 8;

/* The storage a loaded Dictionary's name and codes point into, kept alive
 * by the shared_ptr that points at its `dict`. */
struct OwnedDictionary {
	std::string name;
	std::vector<std::uint64_t> codes;
	MarkerLayout layout;
	Dictionary dict;
};

/* One code as read, waiting for the side to be known. */
struct CodeLine {
	std::uint64_t code = 0;
	int digits = 0; /* hex digits, or '0'/'1' characters */
	int line = 0;
};

std::string_view trim(std::string_view s)
{
	while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
		s.remove_prefix(1);
	while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
		s.remove_suffix(1);
	return s;
}

std::optional<int> parseCount(std::string_view s)
{
	int v = 0;
	const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
	if (ec != std::errc() || end != s.data() + s.size() || s.empty() || v < 0)
		return std::nullopt;
	return v;
}

/* The text cut into lines, each checked, with what failed named by
 * `source` and the line's number. */
class Source {
public:
	Source(std::string_view text, std::string_view source, std::string_view caller)
		: text_(text), prefix_(std::string(caller) + ": " + detail::toUtf8(source, std::string::npos) + ":")
	{
		if (text_.starts_with("\xEF\xBB\xBF")) /* a UTF-8 byte-order mark */
			text_.remove_prefix(3);
	}

	/* The next line, trimmed; false at the end. */
	bool next(std::string_view &line)
	{
		if (pos_ >= text_.size())
			return false;
		const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
		line = text_.substr(pos_, end - pos_);
		pos_ = end + 1;
		++number_;
		if (line.size() > kMaxLineBytes)
			fail(number_, "a line longer than " + std::to_string(kMaxLineBytes) + " bytes");
		for (char c : line) {
			const auto u = static_cast<unsigned char>(c);
			if ((u < 0x20 && c != '\t' && c != '\r') || u == 0x7f)
				fail(number_, "not text (control character " + std::to_string(u) + ")");
		}
		line = trim(line);
		return true;
	}
	int line() const { return number_; }
	/* The last line (at least 1), for what concerns the whole file. */
	int lastLine() const { return std::max(1, number_); }

	[[noreturn]] void fail(int line, const std::string &what) const
	{
		throw std::invalid_argument(prefix_ + std::to_string(line) + ": " + what);
	}

private:
	std::string_view text_;
	std::string prefix_;
	std::size_t pos_ = 0;
	int number_ = 0;
};

void checkName(const Source &src, int line, std::string_view name)
{
	if (name.empty() || name.size() > kMaxNameBytes)
		src.fail(line, "a dictionary name must have 1 to " + std::to_string(kMaxNameBytes) + " bytes");
	/* The name goes into JSON, GStreamer structures and Python str, all
	 * UTF-8: a file in another encoding (Latin-1) is refused here. */
	if (const std::size_t at = detail::invalidUtf8At(name); at != std::string_view::npos) {
		char byte[8];
		std::snprintf(byte, sizeof(byte), "0x%02x", static_cast<unsigned char>(name[at]));
		src.fail(line, "the dictionary name is not UTF-8 text (byte " + std::string(byte) + " at its byte " +
				       std::to_string(at + 1) + "); save the file as UTF-8");
	}
}

/* The sides whose cells fit a 64-bit code and the detector's sample grid
 * (CandidateSamples::kMaxSide); below 3 a marker is hardly a code. */
void checkSide(const Source &src, int line, int n)
{
	if (n < kMinSide || n > kMaxSide)
		src.fail(line, "a marker side of " + std::to_string(n) + " bits; the detector reads " +
				       std::to_string(kMinSide) + " to " + std::to_string(kMaxSide));
}

/* What either format gives: the side, the codes by id, and the rest. */
struct Parsed {
	std::string name;
	int side = 0;
	int sideLine = 0;
	int opencvMaxCorrection = 0;
	std::vector<CodeLine> codes;
	/* `layout` rows, and the first one's line; a declared distance. */
	std::vector<std::string> layoutRows;
	int layoutLine = 0;
	std::optional<int> declaredHamming;
	int declaredHammingLine = 0;
};

/* "... min_hamming_distance 12, ..." in a `# layout:` header. */
std::optional<int> hammingInNote(std::string_view note)
{
	const std::string_view key = "min_hamming_distance";
	const std::size_t at = note.find(key);
	if (at == std::string_view::npos)
		return std::nullopt;
	std::string_view rest = trim(note.substr(at + key.size()));
	if (!rest.empty() && rest.front() == ':')
		rest = trim(rest.substr(1));
	return parseCount(rest.substr(0, rest.find_first_of(" \t,")));
}

/* The text format: `# key: value` headers, one 0x codeword a line. */
Parsed parseText(Source &src)
{
	Parsed p;
	std::optional<int> declared;
	int declaredLine = 0;
	std::string_view line;
	while (src.next(line)) {
		if (line.empty())
			continue;
		if (line.front() == '#') {
			const std::size_t colon = line.find(':');
			if (colon == std::string_view::npos)
				continue;
			const std::string_view key = trim(line.substr(1, colon - 1));
			std::string_view value = trim(line.substr(colon + 1));
			/* Headers carry a note after the value ("12   (over all ...)"). */
			const std::string_view word = value.substr(0, value.find_first_of(" \t"));
			if (key == "dictionary") {
				checkName(src, src.line(), value);
				p.name = std::string(value);
			} else if (key == "marker_side_bits") {
				const auto n = parseCount(word);
				if (!n)
					src.fail(src.line(), "marker_side_bits is not a number: '" + std::string(word) + "'");
				checkSide(src, src.line(), *n);
				p.side = *n;
				p.sideLine = src.line();
			} else if (key == "codes") {
				declared = parseCount(word);
				declaredLine = src.line();
				if (!declared)
					src.fail(src.line(), "codes is not a number: '" + std::string(word) + "'");
			} else if (key == "layout" || key == "min_hamming_distance") {
				if (const auto h = key == "layout" ? hammingInNote(value) : parseCount(word)) {
					p.declaredHamming = h;
					p.declaredHammingLine = src.line();
				}
			} else if (key.starts_with("opencv") && key.ends_with("max_correction_bits")) {
				const auto n = parseCount(word);
				if (!n || *n > 64)
					src.fail(src.line(), std::string(key) + " must be 0..64, got '" + std::string(word) + "'");
				p.opencvMaxCorrection = *n;
			}
			continue;
		}
		/* A row of the layout: `layout` and its cells. */
		if (line.starts_with("layout") && (line.size() == 6 || line[6] == ' ' || line[6] == '\t')) {
			if (!p.codes.empty())
				src.fail(src.line(), "a layout row after the codes (the layout comes first)");
			if (p.layoutRows.empty())
				p.layoutLine = src.line();
			p.layoutRows.emplace_back(trim(line.substr(6)));
			continue;
		}
		/* A codeword, then perhaps a comment. */
		const std::string_view token = line.substr(0, line.find_first_of(" \t#"));
		const std::string_view rest = trim(line.substr(token.size()));
		if (!rest.empty() && rest.front() != '#')
			src.fail(src.line(), "one codeword a line, found '" + std::string(rest.substr(0, 40)) + "' after it");
		if (!(token.starts_with("0x") || token.starts_with("0X")))
			src.fail(src.line(), "a codeword must be a 0x hex number, got '" +
						     std::string(token.substr(0, 40)) + "'");
		const std::string_view hex = token.substr(2);
		CodeLine c;
		const auto [end, ec] = std::from_chars(hex.data(), hex.data() + hex.size(), c.code, 16);
		if (hex.empty() || ec != std::errc() || end != hex.data() + hex.size())
			src.fail(src.line(), "a codeword must be a 0x hex number of at most 64 bits, got '" +
						     std::string(token.substr(0, 40)) + "'");
		const int limit = p.layoutRows.empty() ? kMaxCodes : kMaxLayoutCodes;
		if (static_cast<int>(p.codes.size()) == limit)
			src.fail(src.line(), "more than " + std::to_string(limit) + " codes");
		c.digits = static_cast<int>(hex.size());
		c.line = src.line();
		p.codes.push_back(c);
	}
	if (p.codes.empty())
		src.fail(src.lastLine(), "no codes (one 0x codeword a line, or OpenCV's YAML)");
	if (declared && *declared != static_cast<int>(p.codes.size()))
		src.fail(declaredLine, "the header says " + std::to_string(*declared) + " codes, the file has " +
					       std::to_string(p.codes.size()));
	if (!p.layoutRows.empty()) {
		if (p.sideLine)
			src.fail(p.sideLine, "marker_side_bits and layout rows: a layout gives the side");
		return p;
	}
	if (!p.sideLine) {
		/* No header: the side from the digits, zero-padded to
		 * ceil(n * n / 4) (3, 4, 7, 9, 13, 16 for n = 3..8). */
		for (int n = kMinSide; n <= kMaxSide; ++n) {
			if ((n * n + 3) / 4 == p.codes[0].digits)
				p.side = n;
		}
		p.sideLine = p.codes[0].line;
		if (!p.side)
			src.fail(p.sideLine, "no '# marker_side_bits: n' header, and " +
						     std::to_string(p.codes[0].digits) +
						     " hex digits are no side's ceil(n*n/4) for n in 3..8");
		for (const CodeLine &c : p.codes) {
			if (c.digits != p.codes[0].digits)
				src.fail(c.line, "without a '# marker_side_bits: n' header every codeword must have " +
							 std::to_string(p.codes[0].digits) + " hex digits, as the first");
		}
	}
	return p;
}

/* One `key: value` of OpenCV's YAML, or `<key>value</key>` of its XML;
 * false for the lines that carry none (the document markers, the root
 * element). */
bool keyValue(const Source &src, std::string_view line, bool xml, std::string_view &key, std::string_view &value)
{
	if (xml) {
		if (line.starts_with("<?xml") || line.starts_with("<!--") || line == "<opencv_storage>" ||
		    line == "</opencv_storage>")
			return false;
		const std::size_t close = line.find('>');
		if (!line.starts_with('<') || close == std::string_view::npos)
			src.fail(src.line(), "expected <key>value</key>, got '" + std::string(line.substr(0, 40)) + "'");
		key = line.substr(1, close - 1);
		const std::string end = "</" + std::string(key) + ">";
		if (!line.ends_with(end) || close + 1 > line.size() - end.size())
			src.fail(src.line(), "expected <" + std::string(key) + ">value" + end);
		value = trim(line.substr(close + 1, line.size() - end.size() - close - 1));
	} else {
		if (line.starts_with("%YAML") || line == "---" || line == "...")
			return false;
		const std::size_t colon = line.find(':');
		if (colon == std::string_view::npos)
			src.fail(src.line(), "expected 'key: value' (OpenCV's YAML) or a 0x codeword, got '" +
						     std::string(line.substr(0, 40)) + "'");
		key = trim(line.substr(0, colon));
		value = trim(line.substr(colon + 1));
	}
	const bool word = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
		return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
	});
	if (!word)
		src.fail(src.line(), "a key must be a word, got '" + std::string(key.substr(0, 40)) + "'");
	if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') && value.back() == value.front())
		value = value.substr(1, value.size() - 2);
	return true;
}

/* OpenCV's aruco dictionary as FileStorage writes it: nmarkers,
 * markersize, maxCorrectionBits, marker_0 .. marker_{N-1}. */
Parsed parseOpenCv(Source &src, bool xml)
{
	Parsed p;
	std::optional<int> count;
	int countLine = 0;
	std::vector<int> seen; /* line of marker_k, 0 when not yet */
	std::vector<bool> keys(3);
	auto number = [&](std::string_view key, std::string_view value, int max) {
		const auto n = parseCount(value);
		if (!n || *n > max)
			src.fail(src.line(), std::string(key) + " must be a number 0.." + std::to_string(max) + ", got '" +
						     std::string(value.substr(0, 40)) + "'");
		return *n;
	};
	auto once = [&](std::string_view key, std::size_t k) {
		if (keys[k])
			src.fail(src.line(), std::string(key) + " given twice");
		keys[k] = true;
	};
	std::string_view line, key, value;
	while (src.next(line)) {
		if (line.empty() || line.front() == '#' || !keyValue(src, line, xml, key, value))
			continue;
		if (key == "nmarkers") {
			once(key, 0);
			count = number(key, value, 1 << 30);
			countLine = src.line();
		} else if (key == "markersize") {
			once(key, 1);
			p.side = number(key, value, 1 << 30);
			p.sideLine = src.line();
			checkSide(src, p.sideLine, p.side);
		} else if (key == "maxCorrectionBits") {
			once(key, 2);
			p.opencvMaxCorrection = number(key, value, 64);
		} else if (key == "name") {
			if (!p.name.empty())
				src.fail(src.line(), "name given twice");
			checkName(src, src.line(), value);
			p.name = std::string(value);
		} else if (key.starts_with("marker_")) {
			const auto id = parseCount(key.substr(7));
			if (!id)
				src.fail(src.line(), "'" + std::string(key) + "' is no marker_<id>");
			if (*id >= kMaxCodes)
				src.fail(src.line(), std::string(key) + ": more than " + std::to_string(kMaxCodes) + " codes");
			if (value.empty() || value.size() > 64 ||
			    value.find_first_not_of("01") != std::string_view::npos)
				src.fail(src.line(), std::string(key) + " must be a string of n*n '0'/'1' characters, got '" +
							     std::string(value.substr(0, 40)) + "'");
			if (seen.size() <= static_cast<std::size_t>(*id)) {
				seen.resize(static_cast<std::size_t>(*id) + 1, 0);
				p.codes.resize(seen.size());
			}
			if (seen[static_cast<std::size_t>(*id)])
				src.fail(src.line(), std::string(key) + " given twice");
			seen[static_cast<std::size_t>(*id)] = src.line();
			CodeLine &c = p.codes[static_cast<std::size_t>(*id)];
			for (char bit : value)
				c.code = c.code << 1 | static_cast<std::uint64_t>(bit - '0');
			c.digits = static_cast<int>(value.size());
			c.line = src.line();
		} else {
			src.fail(src.line(), "unknown key '" + std::string(key) +
						     "' (an aruco dictionary has nmarkers, markersize, maxCorrectionBits, "
						     "marker_<id>)");
		}
	}
	if (!p.sideLine)
		src.fail(src.lastLine(), "no markersize");
	if (!count)
		src.fail(src.lastLine(), "no nmarkers");
	if (*count == 0)
		src.fail(countLine, "no codes (nmarkers is 0)");
	if (*count > kMaxCodes)
		src.fail(countLine, "more than " + std::to_string(kMaxCodes) + " codes");
	if (seen.size() > static_cast<std::size_t>(*count))
		src.fail(seen.back(), "marker_" + std::to_string(seen.size() - 1) + " beyond nmarkers " +
					      std::to_string(*count));
	seen.resize(static_cast<std::size_t>(*count), 0);
	const auto missing = std::find(seen.begin(), seen.end(), 0);
	if (missing != seen.end())
		src.fail(countLine, "nmarkers is " + std::to_string(*count) + " but marker_" +
					    std::to_string(missing - seen.begin()) + " is missing");
	for (const CodeLine &c : p.codes) {
		if (c.digits != p.side * p.side)
			src.fail(c.line, "a code of markersize " + std::to_string(p.side) + " has " +
						 std::to_string(p.side * p.side) + " bits, this one " +
						 std::to_string(c.digits));
	}
	return p;
}

std::array<std::uint64_t, 4> rotations(std::uint64_t code, const Dictionary &d)
{
	std::array<std::uint64_t, 4> r{ code };
	for (int k = 1; k < 4; ++k)
		r[k] = d.rotate(r[k - 1]);
	return r;
}

/* The distance between ids (a code and every rotation of another) and of
 * each code to its own rotations; two ids alike in some rotation could not
 * be told apart. */
int minHamming(const Source &src, const std::vector<CodeLine> &codes, const Dictionary &d)
{
	int best = d.codeBits();
	std::vector<std::array<std::uint64_t, 4>> turned;
	turned.reserve(codes.size());
	for (std::size_t j = 0; j < codes.size(); ++j) {
		turned.push_back(rotations(codes[j].code, d));
		const auto &r = turned.back();
		for (int k = 1; k < 4; ++k)
			best = std::min(best, std::popcount(r[0] ^ r[k]));
		for (std::size_t i = 0; i < j; ++i) {
			for (int k = 0; k < 4; ++k) {
				const int d = std::popcount(codes[i].code ^ r[k]);
				if (d == 0)
					src.fail(codes[j].line, "id " + std::to_string(j) + " has the code of id " +
									std::to_string(i) +
									(k ? " turned " + std::to_string(90 * k) + " degrees" : ""));
				best = std::min(best, d);
			}
		}
	}
	return best;
}

/* Too many codes to compare every pair: no two ids alike in any rotation
 * (each code's smallest rotation, sorted), the distance the file declares. */
int declaredHamming(const Source &src, const Parsed &p, const Dictionary &d)
{
	std::vector<std::pair<std::uint64_t, std::size_t>> least;
	least.reserve(p.codes.size());
	for (std::size_t j = 0; j < p.codes.size(); ++j) {
		const auto r = rotations(p.codes[j].code, d);
		least.emplace_back(*std::min_element(r.begin(), r.end()), j);
	}
	std::sort(least.begin(), least.end());
	for (std::size_t k = 1; k < least.size(); ++k) {
		if (least[k].first == least[k - 1].first)
			src.fail(p.codes[least[k].second].line,
				 "id " + std::to_string(least[k].second) + " has the code of id " +
					 std::to_string(least[k - 1].second) + " in some rotation");
	}
	if (!p.declaredHamming)
		src.fail(src.lastLine(), "over " + std::to_string(kMaxCodes) +
						 " codes: the header must give min_hamming_distance (too many to compare)");
	return *p.declaredHamming;
}

std::shared_ptr<const Dictionary> parseAny(std::string_view text, std::string_view source,
					    std::string_view fallbackName, std::string_view caller)
{
	Source src(text, source, caller);
	/* The format from the first line that is neither blank nor a comment. */
	bool xml = false, openCv = false;
	{
		Source probe(text, source, caller);
		std::string_view line;
		while (probe.next(line)) {
			if (line.empty() || line.front() == '#')
				continue;
			xml = line.front() == '<';
			openCv = !(line.starts_with("0x") || line.starts_with("0X") || line.starts_with("layout"));
			break;
		}
	}
	Parsed p = openCv ? parseOpenCv(src, xml) : parseText(src);
	auto owned = std::make_shared<OwnedDictionary>();
	if (!p.layoutRows.empty()) {
		try {
			owned->layout = MarkerLayout::fromRows(p.layoutRows);
		} catch (const std::invalid_argument &e) {
			src.fail(p.layoutLine, e.what());
		}
		if (owned->layout.size + 2 > 16)
			src.fail(p.layoutLine, "a layout of " + std::to_string(owned->layout.size) +
						       " cells a side; the detector reads at most 14");
		p.side = owned->layout.square_cells - 2;
	}
	const int cells = p.layoutRows.empty() ? p.side * p.side : owned->layout.code_bits;
	for (const CodeLine &c : p.codes) {
		if (cells < 64 && c.code >> cells)
			src.fail(c.line, p.layoutRows.empty()
						 ? "a code with bits beyond the " + std::to_string(cells) + " cells of a " +
							   std::to_string(p.side) + "x" + std::to_string(p.side) + " marker"
						 : "a code with bits beyond the layout's " + std::to_string(cells));
	}
	/* A file's stem may be any bytes: made UTF-8 and cut, not refused. */
	if (p.name.empty())
		p.name = fallbackName.empty() ? "custom" : detail::toUtf8(fallbackName, kMaxNameBytes);

	owned->name = std::move(p.name);
	owned->codes.reserve(p.codes.size());
	for (const CodeLine &c : p.codes)
		owned->codes.push_back(c.code);
	Dictionary &d = owned->dict;
	d.name = owned->name;
	d.bits = p.side;
	if (!p.layoutRows.empty())
		d.layout = &owned->layout;
	d.min_hamming = static_cast<int>(p.codes.size()) > kMaxCodes ? declaredHamming(src, p, d)
								    : minHamming(src, p.codes, d);
	d.opencv_max_correction = p.opencvMaxCorrection;
	d.codes = owned->codes;
	return std::shared_ptr<const Dictionary>(owned, &owned->dict);
}

/* Messages quote the file's name and lines: UTF-8 whatever they are. */
std::shared_ptr<const Dictionary> parse(std::string_view text, std::string_view source, std::string_view fallbackName,
					std::string_view caller)
{
	try {
		return parseAny(text, source, fallbackName, caller);
	} catch (const std::invalid_argument &e) {
		const std::string_view what = e.what();
		if (detail::invalidUtf8At(what) == std::string_view::npos)
			throw;
		throw std::invalid_argument(detail::toUtf8(what, std::string::npos));
	}
}

} // namespace

std::shared_ptr<const Dictionary> parseDictionary(std::string_view text, std::string_view name)
{
	return parse(text, name, name, "frappe::parseDictionary");
}

std::shared_ptr<const Dictionary> loadDictionary(const std::string &path)
{
	using Fault = detail::SmallFile::Fault;
	const std::string what =
		"frappe::loadDictionary: cannot read dictionary file '" + detail::toUtf8(path, std::string::npos) + "': ";
	const detail::SmallFile f = detail::readSmallFile(path, kMaxFileBytes);
	switch (f.fault) {
	case Fault::None: break;
	case Fault::NotFound: throw std::runtime_error(what + "no such file");
	case Fault::Directory: throw std::runtime_error(what + "a directory");
	case Fault::NotRegular: throw std::runtime_error(what + "not a regular file (" + f.reason + ")");
	case Fault::TooLarge:
		throw std::runtime_error(what + "over " + std::to_string(kMaxFileBytes >> 20) +
					 " MiB, too large for a dictionary");
	case Fault::Unreadable: throw std::runtime_error(what + f.reason);
	}
	return parse(f.text, path, std::filesystem::path(path).stem().string(), "frappe::loadDictionary");
}

} // namespace frappe
