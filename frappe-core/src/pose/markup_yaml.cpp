// SPDX-License-Identifier: MIT
// The YAML that ROS camera_info and OpenCV FileStorage files are written in.
#include "markup.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace frappe::detail {

const MarkupNode *MarkupNode::find(std::string_view key) const
{
	if (kind != Kind::Map)
		return nullptr;
	for (std::size_t i = 0; i < keys.size(); ++i)
		if (keys[i] == key)
			return &items[i];
	return nullptr;
}

namespace {

bool isSpace(char c)
{
	return c == ' ' || c == '\t';
}

std::string_view trim(std::string_view s)
{
	while (!s.empty() && isSpace(s.front()))
		s.remove_prefix(1);
	while (!s.empty() && (isSpace(s.back()) || s.back() == '\r'))
		s.remove_suffix(1);
	return s;
}

/* Whether a quote at `i` opens a quoted scalar: at the start of a value
 * (after nothing, a key's colon, a dash or a flow bracket), not inside a
 * plain scalar such as don't. */
bool opensQuote(std::string_view s, std::size_t i)
{
	std::size_t j = i;
	while (j > 0 && isSpace(s[j - 1]))
		--j;
	return j == 0 || s[j - 1] == ':' || s[j - 1] == '-' || s[j - 1] == '[' || s[j - 1] == '{' ||
	       s[j - 1] == ',';
}

/* The end of the quoted scalar opening at s[i], one past its closing quote,
 * or npos when it does not close on this text. */
std::size_t quoteEnd(std::string_view s, std::size_t i)
{
	const char q = s[i];
	for (std::size_t j = i + 1; j < s.size(); ++j) {
		if (q == '"' && s[j] == '\\')
			++j;
		else if (s[j] == q) {
			if (q == '\'' && j + 1 < s.size() && s[j + 1] == '\'')
				++j; /* '' is a quote inside single quotes */
			else
				return j + 1;
		}
	}
	return std::string_view::npos;
}

/* For loops that skip quoted text: when s[i] opens a quoted scalar, where
 * it closes (npos when it does not), else i. */
std::size_t pastQuote(std::string_view s, std::size_t i)
{
	if ((s[i] != '"' && s[i] != '\'') || !opensQuote(s, i))
		return i;
	const std::size_t end = quoteEnd(s, i);
	return end == std::string_view::npos ? end : end - 1;
}

/* The line without its comment: # at its start or after a space, outside
 * quotes. */
std::string_view stripComment(std::string_view s)
{
	for (std::size_t i = 0; i < s.size(); ++i) {
		i = pastQuote(s, i);
		if (i == std::string_view::npos)
			return s;
		if (s[i] == '#' && (i == 0 || isSpace(s[i - 1])))
			return s.substr(0, i);
	}
	return s;
}

/* Where the colon ending a mapping key is ("key: value", "key:"), or npos. */
std::size_t keyColon(std::string_view s)
{
	std::size_t i = 0;
	if (!s.empty() && (s[0] == '"' || s[0] == '\'')) {
		i = quoteEnd(s, 0);
		if (i == std::string_view::npos)
			return i;
		while (i < s.size() && isSpace(s[i]))
			++i;
		return i < s.size() && s[i] == ':' && (i + 1 == s.size() || isSpace(s[i + 1])) ? i
											: std::string_view::npos;
	}
	if (!s.empty() && (s[0] == '[' || s[0] == '{'))
		return std::string_view::npos;
	for (; i < s.size(); ++i)
		if (s[i] == ':' && (i + 1 == s.size() || isSpace(s[i + 1])))
			return i;
	return std::string_view::npos;
}

bool isSeqItem(std::string_view s)
{
	return !s.empty() && s[0] == '-' && (s.size() == 1 || isSpace(s[1]));
}

class YamlParser
{
public:
	YamlParser(std::string_view text, std::string_view origin) : origin_(origin) { split(text); }

	MarkupNode parse()
	{
		if (pos_ == lines_.size())
			fail(1, "empty: no keys");
		MarkupNode root = parseBlock(0, 0);
		if (pos_ < lines_.size())
			fail(lines_[pos_].number, "unexpected indentation");
		return root;
	}

private:
	struct Line {
		int indent;
		std::string_view text;
		int number;
	};

	std::string_view origin_;
	std::vector<Line> lines_;
	std::size_t pos_ = 0;
	int nodes_ = 0;

	[[noreturn]] void fail(int line, const std::string &what) const
	{
		throw std::invalid_argument(std::string(origin_) + ": line " + std::to_string(line) + ": " + what);
	}

	MarkupNode node(MarkupNode::Kind kind, int line)
	{
		if (++nodes_ > kMarkupMaxNodes)
			fail(line, "more than " + std::to_string(kMarkupMaxNodes) + " values");
		MarkupNode n;
		n.kind = kind;
		n.line = line;
		return n;
	}

	/* The document's lines, without comments, blank lines, directives
	 * and document markers; the first document only. */
	void split(std::string_view text)
	{
		int number = 0;
		bool started = false;
		while (!text.empty()) {
			const std::size_t nl = text.find('\n');
			std::string_view raw = text.substr(0, nl);
			text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
			++number;
			std::size_t indent = 0;
			while (indent < raw.size() && raw[indent] == ' ')
				++indent;
			const std::string_view body = trim(stripComment(raw.substr(indent)));
			if (body.empty())
				continue;
			if (raw[indent] == '\t')
				fail(number, "a tab in the indentation (YAML indents with spaces)");
			if (indent == 0 && body[0] == '%' && !started && lines_.empty())
				continue; /* %YAML:1.0, %YAML 1.2 */
			if (indent == 0 && (body == "---" || body.substr(0, 4) == "--- ")) {
				if (started || !lines_.empty())
					break;
				started = true;
				if (body.size() > 4)
					fail(number, "content after ---");
				continue;
			}
			if (indent == 0 && body == "...")
				break;
			lines_.push_back({ static_cast<int>(indent), body, number });
		}
	}

	MarkupNode parseBlock(int depth, int min_indent)
	{
		const Line &l = lines_[pos_];
		if (depth > kMarkupMaxDepth)
			fail(l.number, "nested deeper than " + std::to_string(kMarkupMaxDepth) + " levels");
		if (l.indent < min_indent)
			fail(l.number, "unexpected indentation");
		return isSeqItem(l.text) ? parseSeq(l.indent, depth) : parseMap(l.indent, depth);
	}

	MarkupNode parseMap(int indent, int depth)
	{
		MarkupNode map = node(MarkupNode::Kind::Map, lines_[pos_].number);
		while (pos_ < lines_.size() && lines_[pos_].indent >= indent) {
			const Line l = lines_[pos_];
			if (l.indent > indent)
				fail(l.number, "unexpected indentation");
			if (isSeqItem(l.text))
				fail(l.number, "a sequence item where a key was expected");
			const std::size_t colon = keyColon(l.text);
			if (colon == std::string_view::npos)
				fail(l.number, "expected key: value, got \"" + std::string(l.text) + "\"");
			std::string key = scalar(trim(l.text.substr(0, colon)), l.number);
			++pos_;
			map.items.push_back(parseValue(trim(l.text.substr(colon + 1)), indent, l.number, depth, true));
			map.keys.push_back(std::move(key));
		}
		checkUnique(map);
		return map;
	}

	void checkUnique(const MarkupNode &map) const
	{
		std::vector<std::size_t> order(map.keys.size());
		for (std::size_t k = 0; k < order.size(); ++k)
			order[k] = k;
		std::stable_sort(order.begin(), order.end(),
				 [&](std::size_t a, std::size_t b) { return map.keys[a] < map.keys[b]; });
		for (std::size_t k = 1; k < order.size(); ++k)
			if (map.keys[order[k]] == map.keys[order[k - 1]])
				fail(map.items[order[k]].line, "key " + map.keys[order[k]] + " given twice");
	}

	MarkupNode parseSeq(int indent, int depth)
	{
		MarkupNode seq = node(MarkupNode::Kind::Seq, lines_[pos_].number);
		while (pos_ < lines_.size() && lines_[pos_].indent == indent && isSeqItem(lines_[pos_].text)) {
			Line &l = lines_[pos_];
			const std::string_view rest = trim(l.text.substr(1));
			if (!rest.empty() && (isSeqItem(rest) || keyColon(rest) != std::string_view::npos)) {
				/* "- key: value" or "- - item": the rest is a block
				 * indented to where it starts. */
				l.indent += static_cast<int>(rest.data() - l.text.data());
				l.text = rest;
				seq.items.push_back(parseBlock(depth + 1, l.indent));
				continue;
			}
			++pos_;
			seq.items.push_back(parseValue(rest, indent, l.number, depth, false));
		}
		return seq;
	}

	/* The value after "key:" or "-". In a map, a sequence may sit at the
	 * key's own indentation (key:\n- a\n- b). */
	MarkupNode parseValue(std::string_view rest, int indent, int line, int depth, bool in_map)
	{
		std::string tag;
		if (!rest.empty() && rest[0] == '!') {
			std::size_t end = 0;
			while (end < rest.size() && !isSpace(rest[end]))
				++end;
			const std::size_t skip = rest.substr(0, 2) == "!!" ? 2 : 1;
			tag = std::string(rest.substr(skip, end > skip ? end - skip : 0));
			rest = trim(rest.substr(end));
		}
		MarkupNode value;
		if (rest.empty()) {
			const bool flowBelow = pos_ < lines_.size() && lines_[pos_].indent > indent &&
					       !lines_[pos_].text.empty() &&
					       (lines_[pos_].text[0] == '[' || lines_[pos_].text[0] == '{');
			if (flowBelow) {
				/* key:\n  [ ... ] (apriltag_ros's tags.yaml writes its lists so). */
				const Line &below = lines_[pos_++];
				value = parseFlowText(below.text, below.number, depth);
			} else if (pos_ < lines_.size() && lines_[pos_].indent > indent)
				value = parseBlock(depth + 1, indent + 1);
			else if (in_map && pos_ < lines_.size() && lines_[pos_].indent == indent &&
				 isSeqItem(lines_[pos_].text))
				value = parseSeq(indent, depth + 1);
			else
				value = node(MarkupNode::Kind::Scalar, line); /* null */
		} else if (rest[0] == '[' || rest[0] == '{') {
			value = parseFlowText(rest, line, depth);
		} else if (rest[0] == '|' || rest[0] == '>') {
			fail(line, "block scalars (| and >) are not supported");
		} else if (rest[0] == '&' || rest[0] == '*') {
			fail(line, "anchors and aliases (& and *) are not supported");
		} else {
			value = node(MarkupNode::Kind::Scalar, line);
			value.text = scalar(rest, line);
		}
		value.tag = std::move(tag);
		return value;
	}

	/* A scalar: quoted (the whole of `s`) or plain. */
	std::string scalar(std::string_view s, int line) const
	{
		if (s.empty() || (s[0] != '"' && s[0] != '\''))
			return std::string(s);
		const std::size_t end = quoteEnd(s, 0);
		if (end == std::string_view::npos)
			fail(line, "a quoted string that does not end");
		if (end != s.size())
			fail(line, "text after a quoted string: \"" + std::string(s.substr(end)) + "\"");
		std::string out;
		for (std::size_t i = 1; i + 1 < end; ++i) {
			if (s[0] == '\'' && s[i] == '\'') {
				out += '\'';
				++i;
			} else if (s[0] == '"' && s[i] == '\\') {
				const char e = s[++i];
				switch (e) {
				case 'n': out += '\n'; break;
				case 't': out += '\t'; break;
				case 'r': out += '\r'; break;
				case '"':
				case '\\':
				case '/': out += e; break;
				default: fail(line, std::string("an unsupported escape \\") + e);
				}
			} else {
				out += s[i];
			}
		}
		return out;
	}

	/* A flow collection, continued over the following lines until its
	 * brackets close. */
	MarkupNode parseFlowText(std::string_view first, int line, int depth)
	{
		std::string text(first);
		for (int depth_open = open(first); depth_open > 0;) {
			if (pos_ == lines_.size())
				fail(line, "a [ or { that does not close");
			text += ' ';
			text += lines_[pos_].text;
			depth_open += open(lines_[pos_++].text);
		}
		std::size_t i = 0;
		MarkupNode value = parseFlow(text, i, line, depth + 1);
		skipSpace(text, i);
		if (i != text.size())
			fail(line, "text after the closing bracket: \"" + text.substr(i) + "\"");
		return value;
	}

	/* Brackets opened and not closed, outside quotes. */
	static int open(std::string_view s)
	{
		int n = 0;
		for (std::size_t i = 0; i < s.size(); ++i) {
			i = pastQuote(s, i);
			if (i == std::string_view::npos)
				return n;
			if (s[i] == '[' || s[i] == '{')
				++n;
			else if (s[i] == ']' || s[i] == '}')
				--n;
		}
		return n;
	}

	static void skipSpace(std::string_view s, std::size_t &i)
	{
		while (i < s.size() && isSpace(s[i]))
			++i;
	}

	/* One flow value at s[i]: [a, b], {k: v}, a quoted or a plain scalar. */
	MarkupNode parseFlow(std::string_view s, std::size_t &i, int line, int depth)
	{
		if (depth > kMarkupMaxDepth)
			fail(line, "nested deeper than " + std::to_string(kMarkupMaxDepth) + " levels");
		skipSpace(s, i);
		if (i == s.size())
			fail(line, "a value missing");
		if (s[i] == '[' || s[i] == '{') {
			const bool is_map = s[i] == '{';
			const char close = is_map ? '}' : ']';
			MarkupNode c = node(is_map ? MarkupNode::Kind::Map : MarkupNode::Kind::Seq, line);
			++i;
			while (true) {
				skipSpace(s, i);
				if (i < s.size() && s[i] == close) {
					++i;
					checkUnique(c);
					return c;
				}
				if (is_map) {
					std::string key = flowScalar(s, i, line, true);
					skipSpace(s, i);
					if (i == s.size() || s[i] != ':')
						fail(line, "expected key: value in { }");
					++i;
					c.keys.push_back(std::move(key));
				}
				c.items.push_back(parseFlow(s, i, line, depth + 1));
				skipSpace(s, i);
				if (i < s.size() && s[i] == ',')
					++i;
				else if (i == s.size() || s[i] != close)
					fail(line, std::string("expected , or ") + close);
			}
		}
		MarkupNode v = node(MarkupNode::Kind::Scalar, line);
		v.text = flowScalar(s, i, line, false);
		return v;
	}

	std::string flowScalar(std::string_view s, std::size_t &i, int line, bool key) const
	{
		skipSpace(s, i);
		if (i < s.size() && (s[i] == '"' || s[i] == '\'')) {
			const std::size_t end = quoteEnd(s, i);
			if (end == std::string_view::npos)
				fail(line, "a quoted string that does not end");
			const std::string out = scalar(s.substr(i, end - i), line);
			i = end;
			return out;
		}
		const std::size_t start = i;
		while (i < s.size() && s[i] != ',' && s[i] != ']' && s[i] != '}' && s[i] != '[' && s[i] != '{' &&
		       !(key && s[i] == ':'))
			++i;
		if (i < s.size() && (s[i] == '[' || s[i] == '{'))
			fail(line, "a bracket inside a value");
		return std::string(trim(s.substr(start, i - start)));
	}
};

} // namespace

MarkupNode parseYamlSubset(std::string_view text, std::string_view origin)
{
	return YamlParser(text, origin).parse();
}

} // namespace frappe::detail
