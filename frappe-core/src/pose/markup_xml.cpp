// SPDX-License-Identifier: MIT
// The XML that OpenCV FileStorage writes.
#include "markup.h"

#include <algorithm>
#include <charconv>
#include <stdexcept>
#include <string>

namespace frappe::detail {

namespace {

bool isSpace(char c)
{
	return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

bool isNameChar(char c)
{
	return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
	       c == '-' || c == '.' || c == ':';
}

class XmlParser
{
public:
	XmlParser(std::string_view text, std::string_view origin) : s_(text), origin_(origin) {}

	MarkupNode parse(std::string &root_name)
	{
		skipMisc(true);
		if (i_ == s_.size() || s_[i_] != '<')
			fail("expected an element");
		MarkupNode root = element(0, root_name);
		skipMisc(false);
		if (i_ != s_.size())
			fail("text after the root element </" + root_name + ">");
		return root;
	}

private:
	std::string_view s_;
	std::string_view origin_;
	std::size_t i_ = 0;
	int nodes_ = 0;

	std::size_t counted_ = 0; /* newlines counted up to here */
	int line_ = 1;

	/* The line of s_[i_] (i_ only moves forwards). */
	int line()
	{
		for (; counted_ < i_ && counted_ < s_.size(); ++counted_)
			line_ += s_[counted_] == '\n';
		return line_;
	}

	[[noreturn]] void fail(const std::string &what)
	{
		throw std::invalid_argument(std::string(origin_) + ": line " + std::to_string(line()) + ": " + what);
	}

	bool startsWith(std::string_view p) const { return s_.substr(i_, p.size()) == p; }

	void skipSpace()
	{
		while (i_ < s_.size() && isSpace(s_[i_]))
			++i_;
	}

	/* Past `end`, or an error saying what did not end. */
	void skipPast(std::string_view end, const char *what)
	{
		const std::size_t at = s_.find(end, i_);
		if (at == std::string_view::npos)
			fail(std::string(what) + " that does not end");
		i_ = at + end.size();
	}

	/* Spaces, comments and, before the root, the declaration. */
	void skipMisc(bool prolog)
	{
		while (true) {
			skipSpace();
			if (startsWith("<!--"))
				skipPast("-->", "a comment");
			else if (prolog && startsWith("<?"))
				skipPast("?>", "a <? declaration");
			else if (startsWith("<!DOCTYPE") || startsWith("<!ENTITY"))
				fail("DOCTYPE and entity declarations are not supported");
			else
				return;
		}
	}

	std::string name()
	{
		const std::size_t start = i_;
		while (i_ < s_.size() && isNameChar(s_[i_]))
			++i_;
		if (i_ == start)
			fail("expected a name");
		return std::string(s_.substr(start, i_ - start));
	}

	/* Text with its entities and character references replaced. */
	std::string decode(std::string_view t)
	{
		std::string out;
		for (std::size_t k = 0; k < t.size(); ++k) {
			if (t[k] != '&') {
				out += t[k];
				continue;
			}
			const std::size_t semi = t.find(';', k);
			if (semi == std::string_view::npos || semi - k > 10)
				fail("an & that starts no entity (write &amp;)");
			const std::string_view e = t.substr(k + 1, semi - k - 1);
			if (e == "lt")
				out += '<';
			else if (e == "gt")
				out += '>';
			else if (e == "amp")
				out += '&';
			else if (e == "quot")
				out += '"';
			else if (e == "apos")
				out += '\'';
			else if (e.size() > 1 && e[0] == '#') {
				const bool hex = e[1] == 'x';
				unsigned code = 0;
				const std::string_view digits = e.substr(hex ? 2 : 1);
				const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), code,
							       hex ? 16 : 10);
				if (r.ec != std::errc() || r.ptr != digits.data() + digits.size() || code == 0 ||
				    code > 127)
					fail("a character reference &" + std::string(e) + "; beyond ASCII");
				out += static_cast<char>(code);
			} else {
				fail("an unknown entity &" + std::string(e) + ";");
			}
			k = semi;
		}
		return out;
	}

	/* <name attr="v"...> children or text </name>, or <name .../>. */
	MarkupNode element(int depth, std::string &tag_name)
	{
		if (depth > kMarkupMaxDepth)
			fail("nested deeper than " + std::to_string(kMarkupMaxDepth) + " levels");
		if (++nodes_ > kMarkupMaxNodes)
			fail("more than " + std::to_string(kMarkupMaxNodes) + " elements");
		MarkupNode n;
		n.line = line();
		++i_; /* < */
		tag_name = name();
		while (true) {
			skipSpace();
			if (i_ == s_.size())
				fail("<" + tag_name + " does not end");
			if (startsWith("/>")) {
				i_ += 2;
				return n;
			}
			if (s_[i_] == '>') {
				++i_;
				break;
			}
			const std::string attr = name();
			skipSpace();
			if (i_ == s_.size() || s_[i_] != '=')
				fail("attribute " + attr + " of <" + tag_name + "> without a value");
			++i_;
			skipSpace();
			if (i_ == s_.size() || (s_[i_] != '"' && s_[i_] != '\''))
				fail("attribute " + attr + " of <" + tag_name + ">: the value is not quoted");
			const char q = s_[i_++];
			const std::size_t end = s_.find(q, i_);
			if (end == std::string_view::npos)
				fail("attribute " + attr + " of <" + tag_name + ">: the quote does not close");
			const std::string value = decode(s_.substr(i_, end - i_));
			i_ = end + 1;
			if (attr == "type_id")
				n.tag = value;
		}
		/* Content: text, or child elements (spaces between them). */
		std::string text;
		bool all_items = true;
		while (true) {
			const std::size_t lt = s_.find('<', i_);
			if (lt == std::string_view::npos)
				fail("<" + tag_name + "> does not close");
			text += decode(s_.substr(i_, lt - i_));
			i_ = lt;
			if (startsWith("<!--")) {
				skipPast("-->", "a comment");
			} else if (startsWith("<![CDATA[")) {
				i_ += 9;
				const std::size_t end = s_.find("]]>", i_);
				if (end == std::string_view::npos)
					fail("a CDATA section that does not end");
				text += s_.substr(i_, end - i_);
				i_ = end + 3;
			} else if (startsWith("</")) {
				i_ += 2;
				const std::string closing = name();
				skipSpace();
				if (closing != tag_name || i_ == s_.size() || s_[i_] != '>')
					fail("<" + tag_name + "> closed by </" + closing + ">");
				++i_;
				break;
			} else if (startsWith("<?") || startsWith("<!")) {
				fail("unexpected markup in <" + tag_name + ">");
			} else {
				std::string child_name;
				MarkupNode child = element(depth + 1, child_name);
				all_items = all_items && child_name == "_";
				n.keys.push_back(std::move(child_name));
				n.items.push_back(std::move(child));
			}
		}
		if (n.items.empty()) {
			n.kind = MarkupNode::Kind::Scalar;
			std::size_t a = 0, b = text.size();
			while (a < b && isSpace(text[a]))
				++a;
			while (b > a && isSpace(text[b - 1]))
				--b;
			n.text = text.substr(a, b - a);
			return n;
		}
		for (char c : text)
			if (!isSpace(c))
				fail("<" + tag_name + "> mixes text and elements");
		if (all_items) {
			n.kind = MarkupNode::Kind::Seq;
			n.keys.clear();
		} else {
			n.kind = MarkupNode::Kind::Map;
			std::vector<std::string_view> sorted(n.keys.begin(), n.keys.end());
			std::sort(sorted.begin(), sorted.end());
			const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
			if (twice != sorted.end())
				fail("<" + std::string(*twice) + "> given twice in <" + tag_name + ">");
		}
		return n;
	}
};

} // namespace

MarkupNode parseXmlSubset(std::string_view text, std::string_view origin, std::string &root_name)
{
	return XmlParser(text, origin).parse(root_name);
}

} // namespace frappe::detail
